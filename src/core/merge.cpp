// Merging another map into this one (the constraint application of Sec. III-B.3 on its lists),
// under transforms that keep the grid.
#include <cmath>
#include <string>

#include "map_storage.h"
#include "mvog/constraints.h"

namespace mvog {
namespace {

/// How close to exact a grid transform's numbers must be: in cells for translations, and in
/// the rotation's entries (1e-6 rad moves a point 100 m away by 0.1 mm).
constexpr double kGridTolerance = 1e-6;
constexpr double kPi = 3.14159265358979323846;
/// Translations beyond this many cells are refused before they are converted to integers.
constexpr double kMaxShiftCells = 4503599627370496.0;  // 2^52

std::string degrees(double radians) { return std::to_string(radians * 180.0 / kPi) + " degrees"; }

/// A translation of `metres` as a whole number of cells of `resolution`.
std::int64_t wholeCells(double metres, double resolution, const char* axis) {
  const double cells = metres / resolution;
  const double nearest = std::round(cells);
  if (std::fabs(nearest) > kMaxShiftCells) {
    throw ConfigError(std::string("transform: the ") + axis + " translation is too large");
  }
  if (std::fabs(cells - nearest) > kGridTolerance) {
    throw ConfigError(std::string("transform: the ") + axis + " translation is " +
                      std::to_string(metres) + " m, " + std::to_string(cells) + " cells of " +
                      std::to_string(resolution) +
                      " m: not a whole number of cells (the volumes would need resampling)");
  }
  return static_cast<std::int64_t>(nearest);
}

}  // namespace

GridTransform GridTransform::fromMatrix(const Eigen::Matrix4d& this_from_other, double resolution) {
  if (!(std::isfinite(resolution) && resolution > 0.0)) {
    throw ConfigError("resolution: must be finite and > 0");
  }
  if (!this_from_other.allFinite()) throw ConfigError("transform: not finite (NaN or infinite)");
  const Eigen::Matrix4d& m = this_from_other;
  if ((m.row(3) - Eigen::RowVector4d(0.0, 0.0, 0.0, 1.0)).cwiseAbs().maxCoeff() > kGridTolerance) {
    throw ConfigError("transform: not rigid (its last row is not 0 0 0 1)");
  }
  const double tilt = std::acos(std::max(-1.0, std::min(1.0, m(2, 2))));
  if (std::fabs(m(2, 0)) > kGridTolerance || std::fabs(m(2, 1)) > kGridTolerance ||
      std::fabs(m(0, 2)) > kGridTolerance || std::fabs(m(1, 2)) > kGridTolerance ||
      std::fabs(m(2, 2) - 1.0) > kGridTolerance) {
    throw ConfigError("transform: roll or pitch is not zero (the z axis tilts by " + degrees(tilt) +
                      "): the volumes would need resampling");
  }
  const double yaw = std::atan2(m(1, 0), m(0, 0));
  GridTransform transform;
  transform.quarter_turns = static_cast<int>(std::lround(yaw / (0.5 * kPi)) & 3);
  static const double kCos[4] = {1.0, 0.0, -1.0, 0.0};
  static const double kSin[4] = {0.0, 1.0, 0.0, -1.0};
  const double c = kCos[transform.quarter_turns];
  const double s = kSin[transform.quarter_turns];
  if (std::fabs(m(0, 0) - c) > kGridTolerance || std::fabs(m(0, 1) + s) > kGridTolerance ||
      std::fabs(m(1, 0) - s) > kGridTolerance || std::fabs(m(1, 1) - c) > kGridTolerance) {
    throw ConfigError("transform: the yaw is " + degrees(yaw) +
                      ", not a multiple of 90 degrees (or the rotation is not a rotation): the "
                      "volumes would need resampling");
  }
  transform.dx_cells = wholeCells(m(0, 3), resolution, "x");
  transform.dy_cells = wholeCells(m(1, 3), resolution, "y");
  transform.dz = m(2, 3);
  return transform;
}

std::array<std::int64_t, 2> GridTransform::target(const CellIndex& cell) const {
  std::int64_t i = cell.x;
  std::int64_t j = cell.y;
  for (int turn = 0; turn < (quarter_turns % 4 + 4) % 4; ++turn) {
    const std::int64_t turned_i = -j - 1;  // the square [i, i + 1) x [j, j + 1) turned
    j = i;
    i = turned_i;
  }
  return {i + dx_cells, j + dy_cells};
}

void Map::merge(const Map& other, const GridTransform& this_from_other) {
  if (other.config_.resolution != config_.resolution) {
    throw ConfigError("merge: the other map's resolution (" +
                      std::to_string(other.config_.resolution) + " m) is not this map's (" +
                      std::to_string(config_.resolution) + " m)");
  }
  if (other.config_.rules.mass_counting != config_.rules.mass_counting) {
    throw ConfigError(
        "merge: the maps count mass differently (mass_counting per scan in one, per reading in "
        "the other): their masses mean different things");
  }
  if (!(std::fabs(this_from_other.dz) <= config_.max_coordinate)) {
    throw ConfigError("merge: dz must be finite and within max_coordinate");
  }
  const auto dz = static_cast<float>(this_from_other.dz * scale_inverse_);
  const double max_cell = config_.max_coordinate * scale_inverse_ + 1.0;  // as setCellVolumes
  const FreeSpaceRules free_space_rules = detail::freeSpaceRulesOf(config_.rules);
  ListMerger merger;
  CellVolumes added;
  std::vector<CellAssignment> merged;
  for (const auto& entry : other.storage_->tiles) {
    const detail::TileBlock& tile = entry.second;
    const CellIndex origin = detail::tileOrigin(entry.first);
    for (unsigned local = 0; local < detail::kCellsPerTile; ++local) {
      if (!tile.holds(local)) continue;
      const CellIndex cell = detail::cellInTile(origin, local);
      const auto [x, y] = this_from_other.target(cell);
      if (std::fabs(static_cast<double>(x)) > max_cell ||
          std::fabs(static_cast<double>(y)) > max_cell) {
        throw ConfigError("merge: cell (" + std::to_string(cell.x) + ", " + std::to_string(cell.y) +
                          ") of the other map lands at (" + std::to_string(x) + ", " +
                          std::to_string(y) + "), beyond max_coordinate");
      }
      const detail::ColumnRef column = tile.column(local);
      auto move = [&](const Volume* list, std::uint32_t count, std::vector<Volume>& out) {
        out.clear();
        for (const Volume* v = list; v != list + count; ++v) {
          // A shifted volume whose float height rounds below 1 is lifted back to it (eq. 6).
          Volume moved = dz == 0.0f ? *v : makeVolume(v->bottom + dz, v->top + dz);
          moved.mass = static_cast<float>(other.realMass(tile.exponent(), v->mass));
          out.push_back(moved);
        }
      };
      move(column.positive, column.num_positive, added.positive);
      move(column.negative, column.num_negative, added.negative);
      const CellIndex target{static_cast<std::int32_t>(x), static_cast<std::int32_t>(y)};
      const CellVolumes existing = cellVolumes(target);
      CellAssignment& assignment = merged.emplace_back();
      assignment.cell = target;
      // As insertion does (real masses here: density 1 is a unit mass per unit height).
      merger.merge(existing.positive, added.positive, {}, {}, 1.0f, assignment.volumes.positive);
      merger.merge(existing.negative, added.negative, assignment.volumes.positive, free_space_rules,
                   1.0f, assignment.volumes.negative);
    }
  }
  setCellVolumes(merged);  // checks every list again; changes nothing if it throws
}

}  // namespace mvog
