// The first half of the scan update of Fig. 2: rasterisation (Sec. III-B.1) and the creation of
// new volumes (Sec. III-B.2), collected per column.
#include "mvog/scan_update.h"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <cstring>
#include <iterator>
#include <limits>
#include <utility>

#include "mvog/depth_image.h"
#include "mvog/raster.h"
#include "scan_scratch.h"

namespace mvog {
namespace detail {

void joinSorted(std::vector<ScanInterval>& intervals, float join_gap) {
  std::size_t out = 0;
  for (std::size_t k = 0; k < intervals.size(); ++k) {
    if (out > 0 && joins(intervals[out - 1].top, intervals[k].bottom, join_gap)) {
      intervals[out - 1].top = std::max(intervals[out - 1].top, intervals[k].top);
      intervals[out - 1].mass += intervals[k].mass;
    } else {
      intervals[out++] = intervals[k];
    }
  }
  intervals.resize(out);
}

/// The most tiles a scan's dense tile index spans (512 KB of pointers); a scan reaching wider
/// (a far reading) indexes its tiles in a hash map.
constexpr std::int64_t kMaxDenseTiles = std::int64_t{1} << 16;

void ScanScratch::begin(float join_gap, bool count_masses, const CellRange& tiles,
                        const Volume* level) {
  join_gap_ = join_gap;
  count_masses_ = count_masses;
  level_ = level != nullptr && !count_masses;
  level_volume_ = level_ ? *level : Volume{};
  entered_.clear();
  hashed_.clear();
  others_.clear();
  arena_used_ = 0;
  for (auto& runs : free_runs_) runs.clear();
  const bool dense = !tiles.empty() && tiles.width() * tiles.height() <= kMaxDenseTiles;
  dense_min_x_ = dense ? tiles.min.x : 0;
  dense_min_y_ = dense ? tiles.min.y : 0;
  dense_width_ = dense ? static_cast<std::uint32_t>(tiles.width()) : 0;
  dense_height_ = dense ? static_cast<std::uint32_t>(tiles.height()) : 0;
  dense_.assign(std::size_t{dense_width_} * dense_height_, nullptr);
  if (++stamp_ == 0) {  // after 2^32 scans: no slot may keep the new stamp from long ago
    for (auto& tile : pool_) {
      for (FreeSlot& slot : tile->slots) slot.tag = 0;
    }
    stamp_ = 1;
  }
}

ScratchTile& ScanScratch::findOrAddTile(std::int32_t tile_x, std::int32_t tile_y) {
  const std::size_t index = denseIndex(tile_x, tile_y);
  ScratchTile** slot = index != kNotDense ? &dense_[index] : &hashed_[tileKey(tile_x, tile_y)];
  if (*slot == nullptr) {
    if (entered_.size() == pool_.size()) {
      pool_.push_back(std::make_unique<ScratchTile>());
      for (FreeSlot& s : pool_.back()->slots) s.tag = 0;
    }
    *slot = pool_[entered_.size()].get();
    (*slot)->hits.clear();
    std::fill(std::begin((*slot)->reached), std::end((*slot)->reached), std::uint64_t{0});
    std::fill(std::begin((*slot)->level_free), std::end((*slot)->level_free), std::uint64_t{0});
    entered_.emplace_back(tileKey(tile_x, tile_y), *slot);
  }
  return **slot;
}

std::size_t ScanScratch::sizeClass(std::uint32_t capacity) {
  const std::uint32_t rooms = capacity / kFirstCapacity;
  assert(rooms != 0 && capacity % kFirstCapacity == 0 && (rooms & (rooms - 1)) == 0);
  return lowestBit(rooms);
}

std::size_t ScanScratch::allocate(std::uint32_t capacity) {
  // Room that a run left when it moved (moveToLargerRoom) is reused first.
  const std::size_t size_class = sizeClass(capacity);
  if (size_class < free_runs_.size() && !free_runs_[size_class].empty()) {
    const std::size_t offset = free_runs_[size_class].back();
    free_runs_[size_class].pop_back();
    return offset;
  }
  const std::size_t offset = arena_used_;
  const std::size_t used = arena_used_ + capacity;
  if (used > arena_capacity_) {
    const std::size_t grown = std::max(used, 2 * arena_capacity_);
    std::unique_ptr<Heights[]> heights(new Heights[grown]);
    std::unique_ptr<double[]> masses(new double[grown]);
    // The whole used part is copied, the room of runs beyond their size and the room runs left
    // included (never read before it is written again).
    if (offset > 0) std::memcpy(heights.get(), heights_.get(), offset * sizeof(Heights));
    if (offset > 0 && count_masses_)
      std::memcpy(masses.get(), masses_.get(), offset * sizeof(double));
    heights_ = std::move(heights);
    masses_ = std::move(masses);
    arena_capacity_ = grown;
  }
  arena_used_ = used;  // only once the room exists: an allocation that throws leaves it as it was
  return offset;
}

void ScanScratch::moveToLargerRoom(OtherIntervals& others) {
  // A column holds at most one interval a reading: a run's capacity reaches 2^31 only in a scan
  // of over 2^30 readings (12 GB of points), where doubling it would wrap.
  assert(others.capacity <= std::numeric_limits<std::uint32_t>::max() / 2);
  const std::size_t offset = allocate(2 * others.capacity);
  moveIntervals(others.offset, others.size, offset);
  const std::size_t size_class = sizeClass(others.capacity);
  if (size_class >= free_runs_.size()) free_runs_.resize(size_class + 1);
  free_runs_[size_class].push_back(others.offset);
  others.offset = offset;
  others.capacity *= 2;
}

void ScanScratch::addFreeSlow(ScratchTile& tile, unsigned local, const Volume& volume) {
  FreeSlot& slot = tile.slots[local];
  if (slot.others() == kNoOthers) {
    slot.tag = slotTag(stamp_, static_cast<std::uint32_t>(others_.size()));
    others_.push_back({allocate(kFirstCapacity), 0, kFirstCapacity});
  }
  // The inline interval, which may have grown over some of the others (Writer::addFree grows it
  // without looking at them), goes among them; the volume comes inline with what it reaches.
  OtherIntervals& others = others_[slot.others()];
  if (others.size == others.capacity) moveToLargerRoom(others);
  const std::size_t first = others.offset;
  const std::size_t end = first + others.size;
  ScanInterval current{slot.bottom, slot.top, count_masses_ ? tile.masses[local] : 0.0};
  const ScanInterval added{volume.bottom, volume.top,
                           count_masses_ ? static_cast<double>(volume.mass) : 0.0};
  ScanInterval joined = added;
  const auto [current_first, current_last] = joinReached(first, end, current);
  const auto [taken, taken_last] = joinReached(first, end, joined);
  if (current_first == current_last && taken_last - taken <= 1) {
    // The commonest case (a lidar's next beam): the inline interval reaches none of the others
    // and the volume reaches one at most. The inline interval is inserted among them, or
    // replaces the one reached, those between the two places shifted by one to keep their order
    // (the volume never reaches the inline interval here).
    const std::size_t place = current_first;  // where the inline interval belongs
    if (taken == taken_last) {
      replaceRange(others, place, place, current);
    } else if (place <= taken) {
      moveIntervals(place, taken - place, place + 1);
      setInterval(place, current);
    } else {
      moveIntervals(taken + 1, place - taken - 1, taken);
      setInterval(place - 1, current);
    }
  } else {
    replaceRange(others, current_first, current_last, current);
    joined = added;
    const std::size_t new_end = first + others.size;
    const auto [reached, reached_last] = joinReached(first, new_end, joined);
    moveIntervals(reached_last, new_end - reached_last, reached);
    others.size -= static_cast<std::uint32_t>(reached_last - reached);
  }
  slot.bottom = joined.bottom;
  slot.top = joined.top;
  if (count_masses_) tile.masses[local] = joined.mass;
}

void ScanScratch::addHit(ScratchTile& tile, unsigned local, const Volume& volume) {
  // Counted per scan, a column's hits count by the heights they cover: one joining the tile's
  // last hit (a depth camera's neighbouring pixels mostly hit one cell at one height) grows it,
  // which applying the scan, joining the cell's hits, would do anyway.
  if (!count_masses_ && !tile.hits.empty() && tile.hits.back().local == local &&
      intervalsJoin(volume.bottom, volume.top, tile.hits.back().bottom, tile.hits.back().top,
                    join_gap_)) {
    TileHit& last = tile.hits.back();
    last.bottom = std::min(last.bottom, volume.bottom);
    last.top = std::max(last.top, volume.top);
    return;
  }
  tile.hits.push_back({static_cast<std::uint16_t>(local), volume.bottom, volume.top});
  tile.markReached(local);
}

const ScratchTile* ScanScratch::find(std::uint64_t key) const {
  const std::int32_t x = tileKeyX(key);
  const std::int32_t y = tileKeyY(key);
  const std::size_t index = denseIndex(x, y);
  if (index != kNotDense) return dense_[index];
  const auto it = hashed_.find(key);
  return it == hashed_.end() ? nullptr : it->second;
}

void ScanScratch::appendFree(const ScratchTile& tile, unsigned local,
                             std::vector<ScanInterval>& out) const {
  if (level_) {
    if (tile.levelFree(local)) out.push_back({level_volume_.bottom, level_volume_.top, 0.0});
    return;
  }
  const FreeSlot& slot = tile.slots[local];
  if (slot.stamp() != stamp_) return;
  const ScanInterval current{slot.bottom, slot.top, count_masses_ ? tile.masses[local] : 0.0};
  if (slot.others() == kNoOthers) {
    out.push_back(current);
    return;
  }
  // The inline interval joined with the others it grew over (see addFreeSlow), in their order.
  const OtherIntervals& others = others_[slot.others()];
  const std::size_t end = others.offset + others.size;
  ScanInterval joined = current;
  const auto [first, last] = joinReached(others.offset, end, joined);
  for (std::size_t k = others.offset; k < first; ++k) out.push_back(intervalAt(k));
  out.push_back(joined);
  for (std::size_t k = last; k < end; ++k) out.push_back(intervalAt(k));
}

namespace {

/// The heights (grid units) below which a float is within 1/32 of the double it rounds: two
/// heights half a cell apart stay less than a cell apart as floats.
constexpr double kShallowRayMaxHeight = 1 << 20;

/// Eq. (6) for a level ray at `height` (grid units): it enters and leaves every cell at that
/// height, so every cell it crosses gets this one free volume.
Volume levelRayVolume(float height) { return makeVolume(height, height); }

/// Eq. (6): the free volume of a crossing from height `z_enter` to `z_exit` (grid units).
[[gnu::always_inline]] inline Volume crossingVolume(double z_enter, double z_exit) {
  return makeVolume(static_cast<float>(z_enter), static_cast<float>(z_exit));
}

/// The last cell of an obstacle reading's walk, entered at height `z_enter`, ending at `end_z`
/// (grid units): its positive volume (eq. 5) only if `add_hit`, and the free space up to it
/// (Fig. 3, left).
template <class Writer>
[[gnu::always_inline]] inline void addObstacleEnd(double z_enter, double end_z, bool add_hit,
                                                  Writer& scratch) {
  const Volume positive = hitVolume(static_cast<float>(end_z));
  if (add_hit) scratch.addHit(positive);
  if (std::fabs(z_enter - end_z) > 1.0) {  // pad up to the obstacle
    scratch.addFree(
        makeVolume(static_cast<float>(z_enter), z_enter < end_z ? positive.bottom : positive.top));
  }
}

/// Sec. III-B.2: the volumes of one reading from `start` to `end` (grid units), into `scratch`,
/// each cell's free volume from `free_volume(z_enter, z_exit)`; an obstacle's own positive
/// volume only if `add_hit` (FreeSpaceRays::kOnePerEndVoxel adds each hit's apart).
/// Forced inline, with its visit and ScanScratch::Writer::addFree: GCC's inliner left them out of
/// the walk's loop once this file held the walks of both insertions (every reading's, each end
/// voxel's), the writer then lived in memory instead of registers, and the TUM bag's insertion
/// took 25 % longer.
template <class Writer, class FreeVolume>
[[gnu::always_inline]] inline void walkReading(const Eigen::Vector3d& start,
                                               const Eigen::Vector3d& end, bool obstacle,
                                               bool add_hit, Writer& scratch,
                                               const FreeVolume& free_volume) {
  auto visit = [&](double z_enter, double z_exit, bool is_last) __attribute__((always_inline)) {
    if (!is_last || !obstacle) {  // eqs. (3) and (4)
      scratch.addFree(free_volume(z_enter, z_exit));
      return;
    }
    addObstacleEnd(z_enter, end.z(), add_hit, scratch);
  };
  walkRayWith(scratch, start.x(), start.y(), start.z(), end.x(), end.y(), end.z(), visit);
}

/// The rays of a run of one end column (FreeSpaceRays::kOnePathPerEndColumn): ends[0, count)
/// (grid units) sorted by height, walked from `start` along the xy-path of ends[path]. Each
/// cell before the column gets the hull of the lowest and the highest ray's crossings (eq. 6
/// each), which holds those of the rays between them (kColumnRunHeightGap); in the column, each
/// ray its own last crossing (eq. 4, or addObstacleEnd).
template <class Writer>
void walkColumnRun(const Eigen::Vector3d& start, const Eigen::Vector3d* ends, std::size_t count,
                   std::size_t path, bool obstacle, Writer scratch) {
  const double lowest_rise = ends[0].z() - start.z();
  const double highest_rise = ends[count - 1].z() - start.z();
  // The path's heights go from 0 to 1: walkRayWith gives each crossing's parameters t, from
  // which a ray's heights are start.z() + t * rise, as its own walk computes them.
  auto visit = [&](double t_enter, double t_exit, bool is_last) __attribute__((always_inline)) {
    if (!is_last) {
      const Volume lowest =
          crossingVolume(start.z() + t_enter * lowest_rise, start.z() + t_exit * lowest_rise);
      const Volume highest =
          crossingVolume(start.z() + t_enter * highest_rise, start.z() + t_exit * highest_rise);
      scratch.addFree(volumeOfMinimumHeight(std::min(lowest.bottom, highest.bottom),
                                            std::max(lowest.top, highest.top)));
      return;
    }
    for (std::size_t k = 0; k < count; ++k) {
      const double z_enter = start.z() + t_enter * (ends[k].z() - start.z());
      if (obstacle) {
        addObstacleEnd(z_enter, ends[k].z(), false, scratch);
      } else {  // eq. (4)
        scratch.addFree(crossingVolume(z_enter, ends[k].z()));
      }
    }
  };
  walkRayWith(scratch, start.x(), start.y(), 0.0, ends[path].x(), ends[path].y(), 1.0, visit);
}

/// A hit's positive volume alone (eq. 5), in the cell a walk to `end` (grid units) would end in
/// (see walkRay), into `scratch` (a copy of the chunk's writer).
template <class Writer>
void addHitAt(const Eigen::Vector3d& end, Writer scratch) {
  scratch.moveTo(cellAt(end.x(), end.y()));
  scratch.addHit(hitVolume(static_cast<float>(end.z())));
}

/// The volumes of one reading (see walkReading), into `scratch` (a copy of the chunk's writer,
/// local to the ray so that the walk keeps it in registers).
template <class Writer>
void addReading(const Eigen::Vector3d& start, const Eigen::Vector3d& end, bool obstacle,
                bool add_hit, Writer scratch) {
  const auto end_z = static_cast<float>(end.z());
  if (start.z() == end.z()) {
    // A level ray (a 2D laser's): its one free volume made once instead of in each cell.
    const Volume level = levelRayVolume(end_z);
    walkReading(start, end, obstacle, add_hit, scratch, [&](double, double) { return level; });
    return;
  }
  // Eq. (6) lifts a crossing lower than one cell around its centre. A ray that rises at most half
  // a cell per cell along its main axis crosses every cell lower than that (it spends at most
  // 1 / max(|dx|, |dy|) of its length in a cell), even after rounding its heights to floats
  // below kShallowRayMaxHeight: then every crossing is lifted, with no test in each cell.
  const Eigen::Vector3d ray = end - start;
  if (std::fabs(ray.z()) <= 0.5 * std::max(std::fabs(ray.x()), std::fabs(ray.y())) &&
      std::max(std::fabs(start.z()), std::fabs(end.z())) < kShallowRayMaxHeight) {
    walkReading(start, end, obstacle, add_hit, scratch, [](double z_enter, double z_exit) {
      return makeVolumeAround(0.5f * (static_cast<float>(z_enter) + static_cast<float>(z_exit)));
    });
    return;
  }
  walkReading(start, end, obstacle, add_hit, scratch,
              [](double z_enter, double z_exit) { return crossingVolume(z_enter, z_exit); });
}

/// The readings of `scan` (its hits, then its out-of-range readings) that `mine(k)` gives to
/// this chunk, checked, counted and rasterised into `writer`, every reading's ray walked.
template <class Writer, class Mine>
void rasterizeReadings(const Scan& scan, const Mine& mine, const MapConfig& map_config,
                       const InsertionConfig& insertion, Writer& writer, InsertionResult& result) {
  const double s = 1.0 / map_config.resolution;
  const Eigen::Vector3d start = scan.origin * s;
  const bool origin_accepted = map_config.withinBounds(scan.origin);
  const std::size_t num_hits = scan.hits.size();
  auto add = [&](const Eigen::Vector3f& end, ReadingKind kind) {
    Eigen::Vector3d ray_end;
    bool obstacle = false;
    if (!acceptReading(scan.origin, origin_accepted, end.cast<double>(), kind, map_config,
                       insertion, ray_end, obstacle, result)) {
      return;
    }
    const Eigen::Vector3d end_cells = ray_end * s;
    if (!insertion.model_negative_space) {  // only the obstacle's own volume: no walk
      if (obstacle) addHitAt(end_cells, writer);
      return;
    }
    addReading(start, end_cells, obstacle, true, writer);
    ++result.rays_walked;
  };
  const auto began = std::chrono::steady_clock::now();
  for (std::size_t k = 0; k < num_hits; ++k) {
    if (mine(k)) add(scan.hits[k], ReadingKind::kObstacle);
  }
  const auto hits_done = std::chrono::steady_clock::now();
  for (std::size_t k = 0; k < scan.out_of_range.size(); ++k) {
    if (mine(num_hits + k)) add(scan.out_of_range[k], ReadingKind::kOutOfRange);
  }
  result.obstacle_seconds = std::chrono::duration<double>(hits_done - began).count();
  result.out_of_range_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - hits_done).count();
}

/// The tiles of `cells`.
CellRange tilesOf(const CellRange& cells) {
  if (cells.empty()) return kNoCells;
  return {{cells.min.x >> kTileSizeLog2, cells.min.y >> kTileSizeLog2},
          {cells.max.x >> kTileSizeLog2, cells.max.y >> kTileSizeLog2}};
}

/// The hits and rays of the end voxels of `voxels` that `mine(k)` gives to this chunk (voxel k),
/// rasterised into `writer`: the hits, then the rays of the voxels of obstacle readings, then
/// the others'.
template <class Writer, class Mine>
void rasterizeEndVoxels(const EndVoxelRays& voxels, const Mine& mine, const Eigen::Vector3d& start,
                        EndColumnRuns* columns, Writer& writer, InsertionResult& result) {
  const std::vector<VoxelReadings>& all = voxels.voxels();
  const auto began = std::chrono::steady_clock::now();
  for (std::size_t k = 0; k < all.size(); ++k) {
    if (!all[k].obstacle || !mine(k)) continue;
    auto hit_writer = writer;
    hit_writer.moveTo(all[k].cell);
    hit_writer.addHit(EndVoxelRays::hitsOf(all[k]));
  }
  if (columns != nullptr) columns->gather(all, mine);
  auto walk = [&](bool obstacle) {
    for (std::size_t k = 0; k < all.size(); ++k) {
      if (all[k].obstacle != obstacle || !mine(k)) continue;
      if (columns != nullptr && all[k].count >= kReadingsForOneRay) {
        columns->walkRunFrom(k,
                             [&](const Eigen::Vector3d* ends, std::size_t count, std::size_t path) {
                               if (count == 1) {
                                 addReading(start, ends[0], obstacle, false, writer);
                               } else {
                                 walkColumnRun(start, ends, count, path, obstacle, writer);
                               }
                               ++result.rays_walked;
                             });
        continue;
      }
      EndVoxelRays::forEachRayOf(all[k], [&](const Eigen::Vector3d& end) {
        addReading(start, end, obstacle, false, writer);
        ++result.rays_walked;
      });
    }
  };
  walk(true);
  const auto hits_done = std::chrono::steady_clock::now();
  walk(false);
  result.obstacle_seconds += std::chrono::duration<double>(hits_done - began).count();
  result.out_of_range_seconds +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - hits_done).count();
}

/// Sectors of directions around a scan's origin, for splitting its readings among threads.
constexpr std::size_t kSectors = 1024;

/// The direction of (dx, dy) as a number in [0, 4) that grows with the angle (a "diamond
/// angle": atan2's order without its cost).
float pseudoAngle(double dx, double dy) {
  const double p = dx / (std::fabs(dx) + std::fabs(dy));
  return static_cast<float>(dy >= 0.0 ? 1.0 - p : 3.0 + p);
}

/// The sector of a ray's direction (dx, dy) in xy; a vertical ray has none: sector 0.
std::uint16_t sectorOf(const Eigen::Vector2d& direction) {
  if (direction.x() == 0.0 && direction.y() == 0.0) return 0;
  return static_cast<std::uint16_t>(
      std::min<double>(kSectors - 1, pseudoAngle(direction.x(), direction.y()) * (kSectors / 4.0)));
}

/// Gives each sector to one of `chunks` threads: around the circle from the sector with the
/// fewest cells (outside a camera's field of view, or a 360-degree sensor's emptiest direction),
/// each chunk takes consecutive sectors until it holds its share of `cells_in` (cell visits by
/// sector).
void chunksOfSectors(const std::vector<double>& cells_in, std::size_t chunks,
                     std::uint8_t (&chunk_of_sector)[kSectors]) {
  const std::size_t first = static_cast<std::size_t>(
      std::min_element(cells_in.begin(), cells_in.end()) - cells_in.begin());
  double total = 0.0;
  for (double cells : cells_in) total += cells;
  double so_far = 0.0;
  std::size_t chunk = 0;
  for (std::size_t n = 0; n < kSectors; ++n) {
    const std::size_t sector = (first + n) % kSectors;
    while (chunk + 1 < chunks &&
           so_far >= total * static_cast<double>(chunk + 1) / static_cast<double>(chunks)) {
      ++chunk;
    }
    chunk_of_sector[sector] = static_cast<std::uint8_t>(chunk);
    so_far += cells_in[sector];
  }
}

}  // namespace

/// Gives each reading of `scan` to one of `chunks` threads (chunk_of[k] for reading k: hits, then
/// out-of-range readings) by the direction of its ray around the scan's origin, each chunk a run
/// of neighbouring sectors holding about the same number of cell visits. The readings of a
/// chunk then reach columns that the other chunks mostly do not, so few columns need their
/// parts joined when the scan is applied (which the map's result does not depend on: it is the
/// same for any split, ScanInterval).
void splitReadingsBySector(const Scan& scan, const MapConfig& map_config,
                           const InsertionConfig& insertion, std::size_t chunks, ThreadPool* pool,
                           ReadingSplit& split) {
  const std::size_t num_hits = scan.hits.size();
  const std::size_t num_readings = num_hits + scan.out_of_range.size();
  const double s = 1.0 / map_config.resolution;
  std::vector<std::uint16_t>& sector_of = split.sector_of_reading;
  sector_of.resize(num_readings);
  // The readings are read in `parts` runs of consecutive readings, one a thread, each counting
  // the cells of its sectors in its own row of split.cells_in_part.
  const std::size_t parts = pool != nullptr ? pool->threads() : 1;
  split.cells_in_part.assign(parts * kSectors, 0.0);
  const bool origin_accepted = map_config.withinBounds(scan.origin);
  auto sectors_of_part = [&](std::size_t, std::size_t part) {
    double* cells_in = split.cells_in_part.data() + part * kSectors;
    for (std::size_t k = num_readings * part / parts; k < num_readings * (part + 1) / parts; ++k) {
      const bool is_hit = k < num_hits;
      const Eigen::Vector3d end =
          (is_hit ? scan.hits[k] : scan.out_of_range[k - num_hits]).cast<double>();
      const Eigen::Vector3d ray = end - scan.origin;
      const double length = ray.norm();
      // A reading that will be refused (acceptReading: not finite, beyond max_coordinate, at the
      // origin) costs about one cell.
      if (!origin_accepted || !map_config.withinBounds(end) || length == 0.0) {
        cells_in[0] += 1.0;
        sector_of[k] = 0;
        continue;
      }
      const double free_length = freeLengthOf(
          is_hit ? ReadingKind::kObstacle : ReadingKind::kOutOfRange, map_config, insertion);
      // The walk takes |di| + |dj| steps over the part of the ray it frees: the cells it costs.
      sector_of[k] = sectorOf(ray.head<2>());
      cells_in[sector_of[k]] +=
          (std::fabs(ray.x()) + std::fabs(ray.y())) * std::min(1.0, free_length / length) * s + 1.0;
    }
  };
  if (pool != nullptr) {
    pool->run(parts, sectors_of_part);
  } else {
    sectors_of_part(0, 0);
  }
  std::vector<double>& cells_in = split.cells_in_sector;
  cells_in.assign(split.cells_in_part.begin(), split.cells_in_part.begin() + kSectors);
  for (std::size_t part = 1; part < parts; ++part) {
    for (std::size_t sector = 0; sector < kSectors; ++sector) {
      cells_in[sector] += split.cells_in_part[part * kSectors + sector];
    }
  }
  std::uint8_t chunk_of_sector[kSectors];
  chunksOfSectors(cells_in, chunks, chunk_of_sector);
  split.chunk_of_reading.resize(num_readings);
  for (std::size_t k = 0; k < num_readings; ++k) {
    split.chunk_of_reading[k] = chunk_of_sector[sector_of[k]];
  }
}

/// Gives each end voxel of `voxels` to one of `chunks` threads (split.chunk_of_reading[k] for
/// voxel k) as splitReadingsBySector gives readings: by the direction of the voxel's centre from
/// `start` (the origin, grid units), weighed by the cells its rays walk. A voxel's readings are
/// grouped before the split, so the rays walked do not depend on the number of threads.
void splitEndVoxelsBySector(const EndVoxelRays& voxels, const Eigen::Vector3d& start,
                            std::size_t chunks, ReadingSplit& split) {
  const std::vector<VoxelReadings>& all = voxels.voxels();
  std::vector<std::uint16_t>& sector_of = split.sector_of_reading;
  sector_of.resize(all.size());
  std::vector<double>& cells_in = split.cells_in_sector;
  cells_in.assign(kSectors, 0.0);
  for (std::size_t k = 0; k < all.size(); ++k) {
    const VoxelReadings& voxel = all[k];
    sector_of[k] =
        sectorOf(Eigen::Vector2d(voxel.cell.x + 0.5, voxel.cell.y + 0.5) - start.head<2>());
    EndVoxelRays::forEachRayOf(voxel, [&](const Eigen::Vector3d& end) {
      cells_in[sector_of[k]] +=
          std::fabs(end.x() - start.x()) + std::fabs(end.y() - start.y()) + 1.0;
    });
  }
  std::uint8_t chunk_of_sector[kSectors];
  chunksOfSectors(cells_in, chunks, chunk_of_sector);
  split.chunk_of_reading.resize(all.size());
  for (std::size_t k = 0; k < all.size(); ++k) {
    split.chunk_of_reading[k] = chunk_of_sector[sector_of[k]];
  }
}

bool isLineScan(const Scan& scan, double resolution) {
  // visit(p) for each finite reading (the others are rejected) from the origin, while it returns
  // true; whether it did for all.
  auto every_finite = [&](auto&& visit) {
    for (const auto* points : {&scan.hits, &scan.out_of_range}) {
      for (const Eigen::Vector3f& p : *points) {
        if (p.allFinite() && !visit(Eigen::Vector3d(p.cast<double>() - scan.origin))) return false;
      }
    }
    return true;
  };
  // A reading's distance from the plane may be a thousandth of a cell, and the float's rounding
  // of the reading and the normal's error (some 1e-7 of its magnitude each) in room to spare.
  const double tolerance = 1e-3 * resolution + 1e-6 * scan.origin.cwiseAbs().maxCoeff();
  auto all_within = [&](const Eigen::Vector3d& normal) {
    return every_finite([&](const Eigen::Vector3d& p) {
      return std::fabs(normal.dot(p)) <= tolerance + 1e-6 * p.cwiseAbs().maxCoeff();
    });
  };
  Eigen::Vector3d along = Eigen::Vector3d::Zero();
  every_finite([&](const Eigen::Vector3d& p) {
    if (p.squaredNorm() > 0.0) along = p.normalized();
    return p.squaredNorm() == 0.0;
  });
  if (along.squaredNorm() == 0.0) return true;
  // The plane's normal from the first reading and the first one at least ~6 degrees off its
  // line (sin 0.1): its direction is then known to within a few roundings of a float, at any
  // range. Where every reading is within 6 degrees of that line, the plane through the one
  // farthest from it, which holds them all if they lie in one.
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  every_finite([&](const Eigen::Vector3d& p) {
    const Eigen::Vector3d cross = along.cross(p);
    if (cross.norm() >= 0.1 * p.norm()) {
      normal = cross;
      return false;
    }
    if (cross.squaredNorm() > normal.squaredNorm()) normal = cross;
    return true;
  });
  return normal.squaredNorm() == 0.0 || all_within(normal.normalized());
}

bool joinsHitMemory(const MapConfig& map_config, const InsertionConfig& insertion,
                    const Scan* scan) {
  if (insertion.hit_memory_scope == HitMemoryScope::kEveryScan) return true;
  return scan != nullptr && insertion.appliedHitMemoryScans(map_config.rules) > 0 &&
         isLineScan(*scan, map_config.resolution);
}

}  // namespace detail

detail::ThreadPool* ScanUpdate::Impl::threads(std::size_t count) {
  if (count <= 1) return nullptr;
  if (pool == nullptr || pool->threads() != count)
    pool = std::make_unique<detail::ThreadPool>(count);
  return pool.get();
}

ScanUpdate::ScanUpdate() : impl_(std::make_unique<Impl>()) {}
ScanUpdate::~ScanUpdate() = default;
ScanUpdate::ScanUpdate(ScanUpdate&&) noexcept = default;
ScanUpdate& ScanUpdate::operator=(ScanUpdate&&) noexcept = default;

const InsertionResult& ScanUpdate::result() const { return impl_->result; }

bool ScanUpdate::preparedFor(const MapConfig& map_config) const {
  const MapConfig& prepared = impl_->map_config;
  return prepared.resolution == map_config.resolution &&
         prepared.max_coordinate == map_config.max_coordinate && prepared.rules == map_config.rules;
}

void ScanUpdate::begin(const MapConfig& map_config, const InsertionConfig& insertion) {
  map_config.validate();
  insertion.validate();
  Impl& impl = *impl_;
  impl.map_config = map_config;
  impl.insertion = insertion;
  impl.result = InsertionResult{};
  // As a depth image's (prepare(const Scan&) tests whether a scan is a line).
  impl.joins_hit_memory = detail::joinsHitMemory(map_config, insertion, nullptr);
  const auto num_threads = static_cast<std::size_t>(insertion.insertion_threads);
  // A server switches between one thread and several as its queue backs up: the scratches of the
  // threads a scan does not use wait with their memory instead of being freed.
  while (impl.scratches.size() > num_threads) {
    impl.idle_scratches.push_back(std::move(impl.scratches.back()));
    impl.scratches.pop_back();
  }
  while (impl.scratches.size() < num_threads && !impl.idle_scratches.empty()) {
    impl.scratches.push_back(std::move(impl.idle_scratches.back()));
    impl.idle_scratches.pop_back();
  }
  impl.scratches.resize(num_threads);
}

void ScanUpdate::prepare(const Scan& scan, const MapConfig& map_config,
                         const InsertionConfig& insertion) {
  begin(map_config, insertion);
  impl_->joins_hit_memory = detail::joinsHitMemory(map_config, insertion, &scan);
  if (!detail::walksOneRayPerEndVoxel(map_config, insertion)) {
    prepareEveryReading(scan);
    return;
  }
  Impl& impl = *impl_;
  const auto began = std::chrono::steady_clock::now();
  const detail::GroupedScan grouped =
      detail::groupByEndVoxel(scan, map_config, insertion, impl.threads(impl.scratches.size()),
                              impl.end_voxels, impl.result);
  walkEndVoxels(scan.origin, grouped.cells, grouped.level, began);
}

void ScanUpdate::prepare(const DepthFrame& frame, const MapConfig& map_config,
                         const InsertionConfig& insertion) {
  map_config.validate();
  insertion.validate();
  frame.validate();
  if (!detail::walksOneRayPerEndVoxel(map_config, insertion)) {
    // Every reading's ray walked (FreeSpaceRays::kEveryReading, or masses counted per reading):
    // the readings are split among threads before they are walked, from a Scan of them.
    std::size_t skipped = 0;
    const Scan scan = backProjectDepthImage(frame, skipped);
    prepare(scan, map_config, insertion);
    impl_->result.rejected_no_measurement = skipped;
    // An image's pixels, whatever plane its readings happen to lie in.
    impl_->joins_hit_memory = detail::joinsHitMemory(map_config, insertion, nullptr);
    return;
  }
  begin(map_config, insertion);
  Impl& impl = *impl_;
  const auto began = std::chrono::steady_clock::now();
  const detail::GroupedScan grouped =
      detail::groupByEndVoxel(frame, map_config, insertion, impl.threads(impl.scratches.size()),
                              impl.end_voxels, impl.result);
  walkEndVoxels(frame.map_from_camera.translation(), grouped.cells, grouped.level, began);
}

void ScanUpdate::walkEndVoxels(const Eigen::Vector3d& origin, const CellRange& cells, bool level,
                               std::chrono::steady_clock::time_point grouping_began) {
  Impl& impl = *impl_;
  const MapConfig& map_config = impl.map_config;
  // Grouping is timed with the obstacle readings (a depth image's pixels are read once for both
  // kinds).
  impl.result.obstacle_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - grouping_began).count();
  const std::size_t num_threads = impl.scratches.size();
  const Eigen::Vector3d start = origin * (1.0 / map_config.resolution);
  if (num_threads > 1) {
    detail::splitEndVoxelsBySector(impl.end_voxels[0], start, num_threads, impl.split);
  }
  const CellRange tiles = detail::tilesOf(cells);
  const Volume level_volume = detail::levelRayVolume(static_cast<float>(start.z()));
  const float join_gap = detail::joinGapOf(map_config.rules);
  const bool by_column = impl.insertion.free_space_rays == FreeSpaceRays::kOnePathPerEndColumn;
  if (impl.end_columns.size() < num_threads) impl.end_columns.resize(num_threads);
  std::vector<InsertionResult> results(num_threads);
  // The end voxels of chunk k (split.chunk_of_reading) go to scratch k.
  auto rasterize = [&](std::size_t, std::size_t chunk) {
    detail::ScanScratch& scratch = impl.scratches[chunk];
    auto mine = [&](std::size_t k) {
      return num_threads == 1 || impl.split.chunk_of_reading[k] == chunk;
    };
    scratch.begin(join_gap, false, tiles, level ? &level_volume : nullptr);
    detail::EndColumnRuns* columns = by_column ? &impl.end_columns[chunk] : nullptr;
    if (level) {
      detail::ScanScratch::Writer<false, true> writer(scratch);
      detail::rasterizeEndVoxels(impl.end_voxels[0], mine, start, columns, writer, results[chunk]);
    } else {
      detail::ScanScratch::Writer<false> writer(scratch);
      detail::rasterizeEndVoxels(impl.end_voxels[0], mine, start, columns, writer, results[chunk]);
    }
  };
  if (detail::ThreadPool* pool = impl.threads(num_threads)) {
    pool->run(num_threads, rasterize);
  } else {
    rasterize(0, 0);
  }
  for (const InsertionResult& r : results) impl.result += r;
}

void ScanUpdate::prepareEveryReading(const Scan& scan) {
  Impl& impl = *impl_;
  const MapConfig& map_config = impl.map_config;
  const InsertionConfig& insertion = impl.insertion;
  const std::size_t num_threads = impl.scratches.size();
  const bool count_masses = map_config.rules.mass_counting == MassCounting::kPerReading;
  const std::size_t num_hits = scan.hits.size();
  const std::size_t num_readings = num_hits + scan.out_of_range.size();
  const double s = 1.0 / map_config.resolution;
  std::vector<InsertionResult> results(num_threads);
  if (num_threads > 1) {
    detail::splitReadingsBySector(scan, map_config, insertion, num_threads,
                                  impl.threads(num_threads), impl.split);
  }
  // The readings of chunk k (split.chunk_of_reading) go to scratch k.
  auto rasterize = [&](std::size_t, std::size_t chunk) {
    detail::ScanScratch& scratch = impl.scratches[chunk];
    auto mine = [&](std::size_t k) {
      return num_threads == 1 || impl.split.chunk_of_reading[k] == chunk;
    };
    // The tiles of the chunk's rays (those it may accept) for the scratch's dense index: those
    // of the corners of their points' bounding box (a cell's index grows with its coordinates).
    Eigen::Vector2d low = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector2d high = -low;
    auto reach = [&](const Eigen::Vector3d& p) {
      if (!map_config.withinBounds(p)) return;
      low = low.cwiseMin(p.head<2>());
      high = high.cwiseMax(p.head<2>());
    };
    // A level scan: every reading at the origin's height (a level 2D laser's), each of whose
    // rays then frees the same volume in every cell it crosses (addReading's level ray).
    bool level = true;
    reach(scan.origin);
    for (std::size_t k = 0; k < num_readings; ++k) {
      if (mine(k)) {
        const Eigen::Vector3d p =
            (k < num_hits ? scan.hits[k] : scan.out_of_range[k - num_hits]).cast<double>();
        reach(p);
        level = level && p.z() == scan.origin.z();
      }
    }
    CellRange tiles = kNoCells;
    if (low.x() <= high.x()) {
      tiles =
          detail::tilesOf({cellAt(low.x() * s, low.y() * s), cellAt(high.x() * s, high.y() * s)});
    }
    const Volume level_volume = detail::levelRayVolume(static_cast<float>(scan.origin.z() * s));
    scratch.begin(detail::joinGapOf(map_config.rules), count_masses, tiles,
                  level ? &level_volume : nullptr);
    if (count_masses) {
      detail::ScanScratch::Writer<true> writer(scratch);
      detail::rasterizeReadings(scan, mine, map_config, insertion, writer, results[chunk]);
    } else if (level) {
      detail::ScanScratch::Writer<false, true> writer(scratch);
      detail::rasterizeReadings(scan, mine, map_config, insertion, writer, results[chunk]);
    } else {
      detail::ScanScratch::Writer<false> writer(scratch);
      detail::rasterizeReadings(scan, mine, map_config, insertion, writer, results[chunk]);
    }
  };
  if (detail::ThreadPool* pool = impl.threads(num_threads)) {
    pool->run(num_threads, rasterize);
  } else {
    rasterize(0, 0);
  }
  for (const InsertionResult& r : results) impl.result += r;
}

}  // namespace mvog
