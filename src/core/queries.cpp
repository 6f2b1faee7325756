// Queries (Sec. III-C): eq. (9) at points, over planes and height bands, and the volumes.
#include <algorithm>
#include <cmath>
#include <limits>

#include "map_storage.h"
#include "mvog/map.h"

namespace mvog {
namespace {

/// Eq. (9) from the stored masses of the volumes containing a height: the stored unit cancels,
/// so decay (which changes only the unit) leaves it exactly unchanged (Sec. III-E).
float probabilityAt(const detail::ColumnRef& column, float z) {
  const Volume* positive = findVolume(column.positive, column.num_positive, z);
  const Volume* negative = findVolume(column.negative, column.num_negative, z);
  return occupancyProbability(positive != nullptr ? positive->density() : 0.0f,
                              negative != nullptr ? negative->density() : 0.0f);
}

/// Occupancy of a column over the band [low, high] (grid units), see Map::projection.
OccupancyState bandState(const detail::ColumnRef& column, float low, float high,
                         double occupancy_threshold) {
  auto in_band = [&](const Volume& v) { return v.top >= low && v.bottom <= high && v.mass > 0; };
  const Volume* negative_end = column.negative + column.num_negative;
  bool known = std::any_of(column.negative, negative_end, in_band);
  for (const Volume* p = column.positive; p != column.positive + column.num_positive; ++p) {
    if (!in_band(*p)) continue;
    known = true;
    // The highest p over this volume's part of the band: 1 where no negative volume covers it
    // (rho- = 0), else the largest over the negative volumes covering it.
    const float part_low = std::max(p->bottom, low);
    const float part_high = std::min(p->top, high);
    float covered_to = part_low;
    float rho_minus = std::numeric_limits<float>::infinity();
    bool covered = false;  // every point of the part lies in a negative volume
    for (const Volume* n = column.negative; n != negative_end; ++n) {
      if (n->top < part_low) continue;
      if (n->bottom > covered_to) break;
      rho_minus = std::min(rho_minus, n->density());
      covered_to = std::max(covered_to, n->top);
      if (covered_to >= part_high) {
        covered = true;
        break;
      }
    }
    if (!covered) rho_minus = 0.0f;
    if (occupancyProbability(p->density(), rho_minus) > occupancy_threshold) {
      return OccupancyState::kOccupied;
    }
  }
  return known ? OccupancyState::kFree : OccupancyState::kUnknown;
}

}  // namespace

PointOccupancy Map::occupancy(const Eigen::Vector3d& point) const {
  PointOccupancy result;
  if (!config_.withinBounds(point)) return result;
  const CellIndex cell = cellAtPoint(point.x(), point.y());
  const detail::TileBlock* tile = findTile(detail::tileKeyOf(cell));
  if (tile == nullptr) return result;
  const detail::ColumnRef column = tile->column(detail::localIndex(cell));
  if (column.empty()) return result;
  const auto z = static_cast<float>(point.z() * scale_inverse_);
  const Volume* positive = findVolume(column.positive, column.num_positive, z);
  const Volume* negative = findVolume(column.negative, column.num_negative, z);
  if (positive != nullptr)
    result.positive_density = realMass(tile->exponent(), positive->density());
  if (negative != nullptr)
    result.negative_density = realMass(tile->exponent(), negative->density());
  const float p = occupancyProbability(positive != nullptr ? positive->density() : 0.0f,
                                       negative != nullptr ? negative->density() : 0.0f);
  if (!std::isnan(p)) result.probability = p;
  return result;
}

ColumnView Map::column(const CellIndex& cell) const {
  const detail::TileBlock* tile = findTile(detail::tileKeyOf(cell));
  if (tile == nullptr) return {};
  const detail::ColumnRef c = tile->column(detail::localIndex(cell));
  return {c.positive, c.num_positive, c.negative, c.num_negative};
}

CellVolumes Map::cellVolumes(const CellIndex& cell) const {
  CellVolumes result;
  const detail::TileBlock* tile = findTile(detail::tileKeyOf(cell));
  if (tile == nullptr) return result;
  const detail::ColumnRef column = tile->column(detail::localIndex(cell));
  auto copy = [&](const Volume* list, std::uint32_t count, std::vector<Volume>& out) {
    for (std::uint32_t k = 0; k < count; ++k) {
      out.push_back({list[k].bottom, list[k].top,
                     static_cast<float>(realMass(tile->exponent(), list[k].mass))});
    }
  };
  copy(column.positive, column.num_positive, result.positive);
  copy(column.negative, column.num_negative, result.negative);
  return result;
}

template <class T, class CellValue>
Grid2D<T> Map::fillGrid(const CellRange& cells, T unobserved, CellValue&& value_of) const {
  if (cells.empty()) throw ConfigError("cells: the range is empty");
  if (cells.width() * cells.height() > (std::int64_t{1} << 28)) {
    throw ConfigError("cells: the range exceeds 2^28 cells");
  }
  Grid2D<T> grid;
  grid.resolution = config_.resolution;
  grid.cells = cells;
  grid.values.assign(grid.width() * grid.height(), unobserved);
  // Walk tile by tile: one lookup per tile, and unobserved tiles are skipped whole.
  const TileIndex first = tileOf(cells.min);
  const TileIndex last = tileOf(cells.max);
  for (std::int32_t ty = first.y; ty <= last.y; ++ty) {
    for (std::int32_t tx = first.x; tx <= last.x; ++tx) {
      const detail::TileBlock* tile = findTile(detail::tileKey(tx, ty));
      if (tile == nullptr) continue;
      const CellRange in_tile = tileCells({tx, ty});
      const std::int32_t x0 = std::max(in_tile.min.x, cells.min.x);
      const std::int32_t x1 = std::min(in_tile.max.x, cells.max.x);
      const std::int32_t y0 = std::max(in_tile.min.y, cells.min.y);
      const std::int32_t y1 = std::min(in_tile.max.y, cells.max.y);
      for (std::int32_t y = y0; y <= y1; ++y) {
        for (std::int32_t x = x0; x <= x1; ++x) {
          const detail::ColumnRef column = tile->column(detail::localIndex({x, y}));
          if (column.empty()) continue;
          grid.values[static_cast<std::size_t>(y - cells.min.y) * grid.width() +
                      static_cast<std::size_t>(x - cells.min.x)] = value_of(column);
        }
      }
    }
  }
  return grid;
}

CrossSection Map::crossSection(double z, const CellRange& cells) const {
  if (!std::isfinite(z)) throw ConfigError("z: must be finite");
  const auto height = static_cast<float>(z * scale_inverse_);
  return fillGrid<float>(
      cells, std::numeric_limits<float>::quiet_NaN(),
      [&](const detail::ColumnRef& column) { return probabilityAt(column, height); });
}

Projection Map::projection(double z_min, double z_max, double occupancy_threshold,
                           const CellRange& cells) const {
  if (std::isnan(z_min) || std::isnan(z_max) || z_min > z_max) {
    throw ConfigError("z_min: must not be NaN nor above z_max");
  }
  if (!(occupancy_threshold >= 0.0 && occupancy_threshold < 1.0)) {
    throw ConfigError("occupancy_threshold: must be in [0, 1)");
  }
  const auto low = static_cast<float>(z_min * scale_inverse_);
  const auto high = static_cast<float>(z_max * scale_inverse_);
  return fillGrid<OccupancyState>(cells, OccupancyState::kUnknown,
                                  [&](const detail::ColumnRef& column) {
                                    return bandState(column, low, high, occupancy_threshold);
                                  });
}

void Map::forEachVolumeIn(
    const CellRange& cells,
    const std::function<void(const CellIndex&, VolumeSign, const Volume&)>& visit) const {
  for (std::uint64_t key : sortedTileKeys()) {
    const CellRange tile_cells = tileCells({detail::tileKeyX(key), detail::tileKeyY(key)});
    if (!tile_cells.intersects(cells)) continue;
    const detail::TileBlock& tile = storage_->tiles.at(key);
    for (unsigned local = 0; local < detail::kCellsPerTile; ++local) {
      const CellIndex index = detail::cellInTile(tile_cells.min, local);
      if (!tile.holds(local) || !cells.contains(index)) continue;
      const detail::ColumnRef column = tile.column(local);
      auto visit_list = [&](VolumeSign sign, const Volume* list, std::uint32_t count) {
        for (std::uint32_t k = 0; k < count; ++k) {
          const auto mass = static_cast<float>(realMass(tile.exponent(), list[k].mass));
          visit(index, sign, Volume{list[k].bottom, list[k].top, mass});
        }
      };
      visit_list(VolumeSign::kPositive, column.positive, column.num_positive);
      visit_list(VolumeSign::kNegative, column.negative, column.num_negative);
    }
  }
}

void Map::forEachVolume(
    const std::function<void(const CellIndex&, VolumeSign, const Volume&)>& visit) const {
  forEachVolumeIn(bounds_, visit);
}

}  // namespace mvog
