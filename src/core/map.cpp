// The map's storage and bookkeeping: tiles, bounds, revisions, decay, memory, direct access.
#include "mvog/map.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <unordered_set>
#include <utility>

#include "map_storage.h"
#include "mvog/scan_update.h"

namespace mvog {
namespace {

/// Splits x > 0 into f * 2^e with f in (0.5, 1] (exactly, subnormal x included).
double splitPowerOfTwo(double x, int& e) {
  double f = std::frexp(x, &e);
  if (f == 0.5) {
    f = 1.0;
    --e;
  }
  return f;
}

}  // namespace

InsertionResult& InsertionResult::operator+=(const InsertionResult& other) {
  obstacle_readings += other.obstacle_readings;
  out_of_range_readings += other.out_of_range_readings;
  truncated_to_max_range += other.truncated_to_max_range;
  rejected_non_finite += other.rejected_non_finite;
  rejected_out_of_bounds += other.rejected_out_of_bounds;
  rejected_too_close += other.rejected_too_close;
  rejected_no_measurement += other.rejected_no_measurement;
  ignored_out_of_range += other.ignored_out_of_range;
  rays_walked += other.rays_walked;
  obstacle_seconds += other.obstacle_seconds;
  out_of_range_seconds += other.out_of_range_seconds;
  return *this;
}

OccupancyState PointOccupancy::state(double occupancy_threshold) const {
  if (!probability) return OccupancyState::kUnknown;
  return *probability > occupancy_threshold ? OccupancyState::kOccupied : OccupancyState::kFree;
}

Map::Map(const MapConfig& config)
    : config_(config), storage_(std::make_unique<Storage>()), own_update_(nullptr) {
  config_.validate();
  scale_inverse_ = 1.0 / config_.resolution;
}

Map::~Map() = default;
Map::Map(Map&&) noexcept = default;
Map& Map::operator=(Map&&) noexcept = default;

CellRange Map::tileCells(const TileIndex& tile) {
  const CellIndex min{tile.x * kTileSize, tile.y * kTileSize};
  return {min, {min.x + kTileSize - 1, min.y + kTileSize - 1}};
}

const detail::TileBlock* Map::findTile(std::uint64_t key) const {
  const auto it = storage_->tiles.find(key);
  return it == storage_->tiles.end() ? nullptr : &it->second;
}

CellIndex Map::cellAtPoint(double x, double y) const {
  return cellAt(x * scale_inverse_, y * scale_inverse_);
}

CellRange Map::cellsInRectangle(double min_x, double min_y, double max_x, double max_y) const {
  return {cellAtPoint(min_x, min_y), cellAtPoint(max_x, max_y)};
}

double Map::rescaleOf(std::int32_t tile_exponent) const {
  return std::ldexp(1.0, static_cast<int>(unit_exponent_ - tile_exponent));
}

double Map::realMass(std::int32_t tile_exponent, float stored_mass) const {
  return std::ldexp(stored_mass * mass_unit_, static_cast<int>(unit_exponent_ - tile_exponent));
}

std::vector<std::uint64_t> Map::sortedTileKeys() const {
  std::vector<std::uint64_t> keys;
  keys.reserve(storage_->tiles.size());
  for (const auto& entry : storage_->tiles) keys.push_back(entry.first);
  std::sort(keys.begin(), keys.end(), detail::rowMajorBefore);
  return keys;
}

void Map::recomputeBounds() {
  bounds_ = kNoCells;
  for (const auto& [key, tile] : storage_->tiles) {
    const CellIndex origin = detail::tileOrigin(key);
    const CellRange held = tile.heldCells();
    bounds_.extend(CellRange{{origin.x + held.min.x, origin.y + held.min.y},
                             {origin.x + held.max.x, origin.y + held.max.y}});
  }
}

void Map::decay(double k_d) {
  if (!(k_d > 0.0 && k_d <= 1.0)) throw ConfigError("k_d: must be in (0, 1]");
  if (k_d == 1.0) return;
  ++revision_;  // every mass changes; no probability does, so no tile is marked
  // mass_unit_ * 2^unit_exponent_ *= k_d, with mass_unit_ kept in (0.5, 1]: no tile is touched,
  // and the unit exponent never rises (k_d <= 1).
  int k_exponent = 0;
  const double k_fraction = splitPowerOfTwo(k_d, k_exponent);
  int unit_exponent = 0;
  mass_unit_ = splitPowerOfTwo(mass_unit_ * k_fraction, unit_exponent);
  unit_exponent_ += k_exponent + unit_exponent;
  // After some 2^24 binary orders of decay, move the exponents back near zero so that they stay
  // within 32 bits. No real mass changes that a double can show, and no stored mass changes.
  if (unit_exponent_ < detail::kMinUnitExponent) {
    for (auto& entry : storage_->tiles) {
      entry.second.rebaseExponent(unit_exponent_, detail::kMaxExponentLag);
    }
    unit_exponent_ = 0;
    storage_->exponents_rebased_revision = revision_;
  }
}

MemoryUsage Map::memoryUsage() const {
  MemoryUsage usage;
  const auto& tiles = storage_->tiles;
  usage.tiles = tiles.size();
  std::size_t tile_bytes = 0;
  for (const auto& entry : tiles) {
    const detail::TileBlock& tile = entry.second;
    tile_bytes += tile.bytes();
    usage.cells_with_volumes += tile.numCells();
    const std::uint32_t positive = tile.numPositive();
    usage.positive_volumes += positive;
    usage.negative_volumes += tile.numVolumes() - positive;
  }
  // A node of the tile index holds its next pointer, the key and the tile's block pointer.
  const std::size_t tile_index_bytes =
      tiles.bucket_count() * sizeof(void*) +
      tiles.size() * (sizeof(void*) + sizeof(std::uint64_t) + sizeof(detail::TileBlock));
  usage.bytes_held = sizeof(Map) + sizeof(Storage) + tile_index_bytes + tile_bytes +
                     storage_->removals.bytes() +
                     (storage_->recent_hits != nullptr ? storage_->recent_hits->bytes() : 0);
  usage.minimal_grid_cells = static_cast<std::size_t>(bounds_.width() * bounds_.height());
  usage.table_one_bytes = usage.minimal_grid_cells * 8 +
                          (usage.positive_volumes + usage.negative_volumes) * sizeof(Volume);
  return usage;
}

void Map::clear() {
  storage_->tiles.clear();
  storage_->recent_hits.reset();
  bounds_ = kNoCells;
  mass_unit_ = 1.0;
  unit_exponent_ = 0;
  ++revision_;
  storage_->removals.restartAt(revision_);  // the tiles cleared are not listed one by one
}

std::vector<TileIndex> Map::tilesModifiedSince(std::uint64_t revision) const {
  std::vector<TileIndex> modified;
  for (std::uint64_t key : sortedTileKeys()) {
    if (storage_->tiles.at(key).modifiedRevision() > revision) {
      modified.push_back({detail::tileKeyX(key), detail::tileKeyY(key)});
    }
  }
  return modified;
}

void Map::setCellVolumes(const CellIndex& cell, const CellVolumes& volumes) {
  setCellVolumes(std::vector<CellAssignment>{{cell, volumes}});
}

void Map::setCellVolumes(const std::vector<CellAssignment>& cells) {
  // Check everything first: a refused call changes nothing.
  const double max_cell = config_.max_coordinate * scale_inverse_ + 1.0;
  std::vector<std::pair<std::uint64_t, const CellAssignment*>> by_tile;  // (key, assignment)
  std::unordered_set<std::uint64_t> seen;
  for (const CellAssignment& assignment : cells) {
    const CellIndex& c = assignment.cell;
    // The cell's name is made only for a message: this loop checks every cell assigned.
    auto refuse = [&](const std::string& problem) {
      throw ConfigError(detail::cellName(c).append(problem));
    };
    // Readings within max_coordinate fall in cells |i|, |j| <= max_coordinate * s + 1.
    if (std::fabs(static_cast<double>(c.x)) > max_cell ||
        std::fabs(static_cast<double>(c.y)) > max_cell) {
      refuse(" lies beyond max_coordinate");
    }
    if (!seen.insert(detail::cellKey(c)).second) {
      refuse(" is given twice");
    }
    const CellVolumes& v = assignment.volumes;
    const std::string problem =
        checkColumn(v.positive.data(), v.positive.size(), v.negative.data(), v.negative.size(),
                    config_.rules.split_free_space_at_obstacles);
    if (!problem.empty()) refuse(": " + problem);
    for (const std::vector<Volume>* list : {&v.positive, &v.negative}) {
      for (const Volume& volume : *list) {
        if (!std::isfinite(static_cast<float>(volume.mass / mass_unit_))) {
          refuse(": a mass is too large for the map's decayed unit");
        }
      }
    }
    by_tile.emplace_back(detail::tileKeyOf(c), &assignment);
  }
  const bool changes_nothing =
      std::all_of(cells.begin(), cells.end(), [&](const CellAssignment& a) {
        const detail::TileBlock* tile = findTile(detail::tileKeyOf(a.cell));
        return a.volumes.positive.empty() && a.volumes.negative.empty() &&
               (tile == nullptr || !tile->holds(detail::localIndex(a.cell)));
      });
  if (changes_nothing) return;
  std::sort(by_tile.begin(), by_tile.end(), [](const auto& a, const auto& b) {
    return a.first != b.first
               ? a.first < b.first
               : detail::localIndex(a.second->cell) < detail::localIndex(b.second->cell);
  });

  ++revision_;
  bool emptied_a_cell = false;
  detail::TileBlock::Builder builder;
  std::vector<Volume> positive;
  std::vector<Volume> negative;
  const FreeSpaceRules free_space_rules = detail::freeSpaceRulesOf(config_.rules);
  ListMerger merger;
  for (std::size_t first = 0; first < by_tile.size();) {
    const std::uint64_t key = by_tile[first].first;
    std::size_t last = first;
    while (last < by_tile.size() && by_tile[last].first == key) ++last;
    auto existing = storage_->tiles.find(key);
    const detail::TileBlock* old = existing == storage_->tiles.end() ? nullptr : &existing->second;
    const double rescale = old == nullptr ? 1.0 : rescaleOf(old->exponent());
    const CellIndex origin = detail::tileOrigin(key);
    std::size_t next = first;
    for (unsigned local = 0; local < detail::kCellsPerTile; ++local) {
      if (next < last && detail::localIndex(by_tile[next].second->cell) == local) {
        const CellVolumes& v = by_tile[next++].second->volumes;
        if (v.positive.empty() && v.negative.empty()) {
          emptied_a_cell |= old != nullptr && old->holds(local);
          continue;
        }
        auto stored = [&](const std::vector<Volume>& list, std::vector<Volume>& out) {
          out = list;
          for (Volume& volume : out) volume.mass = static_cast<float>(volume.mass / mass_unit_);
        };
        stored(v.positive, positive);
        stored(v.negative, negative);
        merger.cutAsTheMergeDoes(negative, positive, free_space_rules);
        builder.add(local, positive, negative);
        bounds_.extend(detail::cellInTile(origin, local));
      } else if (old != nullptr && old->holds(local)) {
        builder.add(local, old->column(local), rescale);
      }
    }
    detail::TileBlock tile = builder.finish(static_cast<std::int32_t>(unit_exponent_), revision_);
    if (!tile.empty()) {
      storage_->tiles[key] = std::move(tile);
    } else if (old != nullptr) {
      storage_->removeTile(existing, revision_);
    }
    first = last;
  }
  if (emptied_a_cell) recomputeBounds();
}

}  // namespace mvog
