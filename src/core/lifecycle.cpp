// A map's lifetime: forgetting what decayed, dropping far tiles, clearing a box, and the record
// of removed tiles that incremental publication and map updates need.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <iterator>
#include <limits>
#include <string>

#include <unistd.h>

#include "map_storage.h"
#include "mvog/constraints.h"

namespace mvog {
namespace detail {

void TileRemovalLog::record(std::uint64_t key, std::uint64_t revision) {
  if (entries_.size() >= kMaxEntries) {
    // Forget the oldest half: from now on, only revisions from the last one forgotten are told.
    const auto half = entries_.begin() + static_cast<std::ptrdiff_t>(kMaxEntries / 2);
    complete_from_ = std::prev(half)->first;
    entries_.erase(entries_.begin(), half);
  }
  entries_.emplace_back(revision, key);
}

void TileRemovalLog::restartAt(std::uint64_t revision) {
  entries_.clear();
  entries_.shrink_to_fit();
  complete_from_ = revision;
}

std::vector<std::uint64_t> TileRemovalLog::keysRemovedAfter(std::uint64_t revision) const {
  const auto first =
      std::upper_bound(entries_.begin(), entries_.end(), revision,
                       [](std::uint64_t r, const Entry& entry) { return r < entry.first; });
  std::vector<std::uint64_t> keys;
  for (auto it = first; it != entries_.end(); ++it) keys.push_back(it->second);
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  return keys;
}

std::uint64_t newMapId() {
  // splitmix64 over a per-process seed (time and process id) and a counter: distinct for every
  // map of a process, and between processes but for a negligible chance.
  static const std::uint64_t seed =
      static_cast<std::uint64_t>(std::chrono::system_clock::now().time_since_epoch().count()) ^
      (static_cast<std::uint64_t>(::getpid()) << 40);
  static std::atomic<std::uint64_t> counter{0};
  std::uint64_t z = seed + 0x9e3779b97f4a7c15ull * (counter.fetch_add(1) + 1);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

}  // namespace detail

namespace {

/// Working memory of the column edits.
struct ColumnEdit {
  std::vector<Volume> positive;  // the edited cell's new lists
  std::vector<Volume> negative;
  std::vector<Volume> kept_negative;
  ListMerger merger;
  detail::TileBlock::Rewrite rewrite;
};

struct EditCount {
  std::size_t cells_changed = 0;
  std::size_t cells_emptied = 0;
};

/// Rewrites the cells of `tile` that `edit(local, column, work)` changes: it returns true with
/// the cell's new lists in work.positive and work.negative (both empty: the cell goes), false
/// for a cell it leaves as it is. Masses stay in the tile's unit and the tile keeps its
/// exponent, so what is not edited stays bit for bit; a changed tile takes `revision`, and is
/// left empty if every cell went.
template <class Edit>
EditCount editColumns(detail::TileBlock& tile, std::uint64_t revision, ColumnEdit& work,
                      Edit&& edit) {
  EditCount count;
  work.rewrite.clear();
  for (unsigned local = 0; local < detail::kCellsPerTile; ++local) {
    if (!tile.holds(local) || !edit(local, tile.column(local), work)) continue;
    ++count.cells_changed;
    if (work.positive.empty() && work.negative.empty()) ++count.cells_emptied;
    work.rewrite.set(local, work.positive, work.negative);
  }
  if (!work.rewrite.empty()) tile = work.rewrite.apply(tile, tile.exponent(), revision);
  return count;
}

/// The mass of negative volumes [first, first + count) together, in float as one volume.
float runMass(const Volume* first, std::uint32_t count) {
  double mass = 0.0;
  for (std::uint32_t k = 0; k < count; ++k) mass += first[k].mass;
  return static_cast<float>(mass);
}

/// Calls visit(sign, first, count, mass) for what forgetting weighs in a column: each positive
/// volume, and each run of touching negative volumes (count of them from first).
template <class Visit>
void forEachForgettable(const detail::ColumnRef& column, Visit&& visit) {
  for (std::uint32_t k = 0; k < column.num_positive; ++k) {
    visit(VolumeSign::kPositive, column.positive + k, 1u, column.positive[k].mass);
  }
  const Volume* negative = column.negative;
  for (std::uint32_t first = 0; first < column.num_negative;) {
    std::uint32_t end = first + 1;
    while (end < column.num_negative && negative[end].bottom == negative[end - 1].top) ++end;
    visit(VolumeSign::kNegative, negative + first, end - first,
          runMass(negative + first, end - first));
    first = end;
  }
}

float lightestMass(const detail::TileBlock& tile) {
  float lightest = std::numeric_limits<float>::infinity();
  for (std::uint32_t rank = 0; rank < tile.numCells(); ++rank) {
    forEachForgettable(tile.columnAtRank(rank),
                       [&](VolumeSign, const Volume*, std::uint32_t, float mass) {
                         lightest = std::min(lightest, mass);
                       });
  }
  return lightest;
}

/// A float height from metres times s, infinite beyond the float range.
float heightOf(double grid_units) {
  constexpr float kInfinity = std::numeric_limits<float>::infinity();
  if (std::fabs(grid_units) > std::numeric_limits<float>::max()) {
    return grid_units > 0.0 ? kInfinity : -kInfinity;
  }
  return static_cast<float>(grid_units);
}

/// The lists of `column` without their parts within [low, high], the rest of each volume
/// keeping the mass in proportion to its height, parts lower than kMinVolumeHeight dropped.
/// Returns whether anything lay within.
bool cutColumn(const detail::ColumnRef& column, float low, float high, ColumnEdit& work) {
  bool changed = false;
  auto cut = [&](const Volume* list, std::uint32_t count, std::vector<Volume>& out) {
    out.clear();
    for (const Volume* v = list; v != list + count; ++v) {
      if (!(v->top > low && v->bottom < high)) {
        out.push_back(*v);
        continue;
      }
      changed = true;
      const double height = static_cast<double>(v->top) - v->bottom;
      auto keep = [&](float bottom, float top) {
        if (top - bottom < kMinVolumeHeight) return;
        out.push_back(
            {bottom, top,
             static_cast<float>(v->mass * ((static_cast<double>(top) - bottom) / height))});
      };
      if (v->bottom < low) keep(v->bottom, low);
      if (v->top > high) keep(high, v->top);
    }
  };
  cut(column.positive, column.num_positive, work.positive);
  cut(column.negative, column.num_negative, work.negative);
  return changed;
}

}  // namespace

std::optional<std::vector<TileIndex>> Map::tilesRemovedSince(std::uint64_t revision) const {
  if (!storage_->removals.covers(revision)) return std::nullopt;
  std::vector<std::uint64_t> keys = storage_->removals.keysRemovedAfter(revision);
  keys.erase(std::remove_if(keys.begin(), keys.end(),
                            [&](std::uint64_t key) { return storage_->tiles.count(key) != 0; }),
             keys.end());
  std::sort(keys.begin(), keys.end(), detail::rowMajorBefore);
  std::vector<TileIndex> removed;
  removed.reserve(keys.size());
  for (std::uint64_t key : keys) removed.push_back({detail::tileKeyX(key), detail::tileKeyY(key)});
  return removed;
}

ForgetResult Map::forget(double min_mass) {
  if (!(std::isfinite(min_mass) && min_mass >= 0.0)) {
    throw ConfigError("min_mass: must be finite and >= 0");
  }
  ForgetResult result;
  if (min_mass == 0.0) return result;
  // A tile whose lightest mass is not light holds nothing to forget; most tiles are not written
  // between two decay steps, and keep their lightest mass from the last call.
  std::vector<Storage::Tiles::iterator> candidates;
  for (auto it = storage_->tiles.begin(); it != storage_->tiles.end(); ++it) {
    detail::TileBlock& tile = it->second;
    float lightest = tile.cachedLightestMass();
    if (std::isnan(lightest)) {
      lightest = lightestMass(tile);
      tile.cacheLightestMass(lightest);
    }
    if (realMass(tile.exponent(), lightest) < min_mass) candidates.push_back(it);
  }
  if (candidates.empty()) return result;

  ++revision_;
  const FreeSpaceRules free_space_rules = detail::freeSpaceRulesOf(config_.rules);
  ColumnEdit work;
  for (const auto it : candidates) {
    detail::TileBlock& tile = it->second;
    const std::int32_t exponent = tile.exponent();
    const EditCount count = editColumns(
        tile, revision_, work, [&](unsigned, const detail::ColumnRef& column, ColumnEdit& edit) {
          std::size_t removed = 0;
          bool removed_positive = false;
          edit.positive.clear();
          edit.kept_negative.clear();
          forEachForgettable(
              column, [&](VolumeSign sign, const Volume* first, std::uint32_t num, float mass) {
                const bool light = realMass(exponent, mass) < min_mass;
                if (light) {
                  removed += num;
                  removed_positive |= sign == VolumeSign::kPositive;
                  return;
                }
                std::vector<Volume>& kept =
                    sign == VolumeSign::kPositive ? edit.positive : edit.kept_negative;
                kept.insert(kept.end(), first, first + num);
              });
          if (removed == 0) return false;
          result.volumes_removed += removed;
          if (removed_positive && free_space_rules.split_at_obstacles &&
              !edit.kept_negative.empty()) {
            // Pieces that touched at a removed positive volume merge again.
            edit.merger.cutAsTheMergeDoes(edit.kept_negative, edit.positive, free_space_rules);
          }
          edit.negative.swap(edit.kept_negative);
          return true;
        });
    result.cells_emptied += count.cells_emptied;
    if (tile.empty()) {
      storage_->removeTile(it, revision_);
      ++result.tiles_freed;
    } else {
      tile.cacheLightestMass(lightestMass(tile));
    }
  }
  if (result.cells_emptied > 0) recomputeBounds();
  storage_->shrinkIndex();
  return result;
}

Map Map::dropTilesFartherThan(const Eigen::Vector2d& centre, double radius) {
  if (!centre.allFinite()) throw ConfigError("centre: must be finite");
  if (!(radius >= 0.0)) throw ConfigError("radius: must be >= 0");
  Map dropped(config_);
  dropped.mass_unit_ = mass_unit_;
  dropped.unit_exponent_ = unit_exponent_;
  ++dropped.revision_;
  const double tile_edge = kTileSize * config_.resolution;
  const std::uint64_t revision = revision_ + 1;
  for (auto it = storage_->tiles.begin(); it != storage_->tiles.end();) {
    // The distance from the centre to the nearest point of the tile's square.
    const double x0 = detail::tileKeyX(it->first) * tile_edge;
    const double y0 = detail::tileKeyY(it->first) * tile_edge;
    const double dx = std::max({x0 - centre.x(), 0.0, centre.x() - (x0 + tile_edge)});
    const double dy = std::max({y0 - centre.y(), 0.0, centre.y() - (y0 + tile_edge)});
    if (dx * dx + dy * dy <= radius * radius) {
      ++it;
      continue;
    }
    it->second.setModifiedRevision(dropped.revision_);
    dropped.storage_->tiles.emplace(it->first, std::move(it->second));
    it = storage_->removeTile(it, revision);
  }
  if (!dropped.storage_->tiles.empty()) {
    revision_ = revision;
    recomputeBounds();
    dropped.recomputeBounds();
    storage_->shrinkIndex();
  }
  return dropped;
}

std::size_t Map::clearBox(const Eigen::Vector3d& min_corner, const Eigen::Vector3d& max_corner) {
  static const char* const kAxes[] = {"x", "y", "z"};
  for (int axis = 0; axis < 3; ++axis) {
    const std::string which = std::string(" in ") + kAxes[axis];
    if (std::isnan(min_corner[axis]) || std::isnan(max_corner[axis])) {
      throw ConfigError("box: a corner is NaN" + which);
    }
    if (min_corner[axis] > max_corner[axis]) {
      throw ConfigError("box: inverted, min_corner is above max_corner" + which);
    }
    if (min_corner[axis] == max_corner[axis]) throw ConfigError("box: empty" + which);
  }
  // The cells whose squares meet [min, max) in x and y, within reach of max_coordinate.
  const double reach = config_.max_coordinate * scale_inverse_ + 2.0;
  auto cell_bound = [&](double grid_units) {
    return static_cast<std::int32_t>(std::clamp(grid_units, -reach, reach));
  };
  const CellRange cells{{cell_bound(std::floor(min_corner.x() * scale_inverse_)),
                         cell_bound(std::floor(min_corner.y() * scale_inverse_))},
                        {cell_bound(std::ceil(max_corner.x() * scale_inverse_) - 1.0),
                         cell_bound(std::ceil(max_corner.y() * scale_inverse_) - 1.0)}};
  float low = heightOf(min_corner.z() * scale_inverse_);
  float high = heightOf(max_corner.z() * scale_inverse_);
  if (std::isinf(low) && low == high) return 0;  // beyond every volume's height
  if (!(high - low > kMaxMergeGap)) {
    // Cut a volume there and the two parts would lie 1 or less apart (Sec. III-A forbids it).
    low = static_cast<float>(0.5 * (static_cast<double>(low) + high) - 0.5 * kMaxMergeGap);
    high = low + kMaxMergeGap;
    while (!(high - low > kMaxMergeGap)) high = std::nextafter(high, INFINITY);
  }

  const std::uint64_t revision = revision_ + 1;
  std::size_t cells_changed = 0;
  bool emptied = false;
  ColumnEdit work;
  for (auto it = storage_->tiles.begin(); it != storage_->tiles.end();) {
    const CellRange tile_cells =
        tileCells({detail::tileKeyX(it->first), detail::tileKeyY(it->first)});
    if (!tile_cells.intersects(cells)) {
      ++it;
      continue;
    }
    const EditCount count =
        editColumns(it->second, revision, work,
                    [&](unsigned local, const detail::ColumnRef& column, ColumnEdit& edit) {
                      return cells.contains(detail::cellInTile(tile_cells.min, local)) &&
                             cutColumn(column, low, high, edit);
                    });
    cells_changed += count.cells_changed;
    emptied |= count.cells_emptied > 0;
    it = it->second.empty() ? storage_->removeTile(it, revision) : std::next(it);
  }
  if (cells_changed == 0) return 0;
  revision_ = revision;
  if (emptied) recomputeBounds();
  storage_->shrinkIndex();
  return cells_changed;
}

}  // namespace mvog
