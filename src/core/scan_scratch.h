// What a scan's rasterisation collects per column before the constraints are applied (internal
// to the core): ScanUpdate fills it, Map::apply reads it.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <unordered_map>
#include <utility>
#include <vector>

#include "mvog/constraints.h"
#include "mvog/depth_image.h"
#include "mvog/scan_update.h"
#include "thread_pool.h"
#include "tile_block.h"

namespace mvog {
namespace detail {

/// New volumes of one list of one column joined where they overlap or touch (eq. 7), or, with
/// MassCounting::kPerScan, where they are at most kMaxMergeGap apart (one scan sees a column at
/// the model's vertical resolution: a gap it leaves of 1 or less is not resolved, and eq. 8
/// would close it anyway). Each carries the summed mass of what it joined: density-1 masses
/// (heights) summed in double. Every height is a float of at least 1, a multiple of 2^-23, so the
/// sums are exact (whatever their order) while a column's total stays below 2^30 cells of height
/// in one scan.
struct ScanInterval {
  float bottom;
  float top;
  double mass;
};

/// A column's free space so far in one scan: the interval its last ray reached inline, so that
/// the next ray, which mostly reaches the same interval, grows it inline, whether or not the
/// column holds other intervals (OtherIntervals): the inline interval may grow over some of
/// them, which join it when it next goes among them (ScanScratch::addFreeSlow) or is read
/// (ScanScratch::appendFree). 16 bytes: a scan's slots are most of what its rasterisation reads
/// and writes.
struct FreeSlot {
  float bottom;
  float top;
  /// The stamp of the scan the slot holds (so that no slot needs clearing between scans), and
  /// the index of the column's other intervals (OtherIntervals) or kNoOthers: one word (slotTag).
  /// A visit tests its stamp; singleFree, whether it is this scan's without others.
  std::uint64_t tag;
  std::uint32_t stamp() const { return static_cast<std::uint32_t>(tag); }
  std::uint32_t others() const { return static_cast<std::uint32_t>(tag >> 32); }
  /// Grows the inline interval to hold `volume`.
  void grow(const Volume& volume) {
    bottom = std::min(bottom, volume.bottom);
    top = std::max(top, volume.top);
  }
};
static_assert(sizeof(FreeSlot) == 16, "four slots a cache line");
constexpr std::uint32_t kNoOthers = 0xffffffffu;
inline std::uint64_t slotTag(std::uint32_t stamp, std::uint32_t others) {
  return stamp | std::uint64_t{others} << 32;
}

/// The intervals of a column with several, but for the one inline in its slot (sorted, more than
/// the join gap apart): a run of the scan's arena of intervals, with room for `capacity`
/// (ScanScratch::heights_ and masses_).
struct OtherIntervals {
  std::size_t offset;
  std::uint32_t size;
  std::uint32_t capacity;
};

/// A hit's positive volume (eq. 5) in a cell of a tile.
struct TileHit {
  std::uint16_t local;
  float bottom;
  float top;
};

struct ScratchTile {
  FreeSlot slots[kCellsPerTile];
  /// With MassCounting::kPerReading: the mass of the volumes each slot's inline interval took
  /// (the other intervals it grew over keep theirs until they join it).
  double masses[kCellsPerTile];
  std::vector<TileHit> hits;
  /// Bit k: cell k got a hit, or (but in a level scan) free space in this scan (so that applying
  /// visits only those).
  std::uint64_t reached[kCellsPerTile / 64];
  /// In a level scan (ScanScratch::begin): bit k, cell k got the scan's one free volume.
  std::uint64_t level_free[kCellsPerTile / 64];

  void markReached(unsigned local) { reached[local >> 6] |= std::uint64_t{1} << (local & 63); }
  void markLevelFree(unsigned local) { level_free[local >> 6] |= std::uint64_t{1} << (local & 63); }
  bool levelFree(unsigned local) const {
    return ((level_free[local >> 6] >> (local & 63)) & 1u) != 0;
  }
  /// Whether no cell got anything: a tile a ray's walk stepped into without crossing any of its
  /// cells (Writer::enterTile). A cell with a hit is reached.
  bool reachedNone() const {
    std::uint64_t any = 0;
    for (std::size_t w = 0; w < kCellsPerTile / 64; ++w) any |= reached[w] | level_free[w];
    return any == 0;
  }
};

/// Whether two intervals, one not below the other, join: the upper one's bottom is at most
/// `join_gap` above the lower one's top.
inline bool joins(float lower_top, float upper_bottom, float join_gap) {
  return upper_bottom - lower_top <= join_gap;
}

/// Whether two intervals, in either order, join: they overlap, or lie at most `join_gap` apart.
inline bool intervalsJoin(float bottom, float top, float other_bottom, float other_top,
                          float join_gap) {
  return std::max(bottom - other_top, other_bottom - top) <= join_gap;
}

/// The cache line: each thread's working memory (ScanScratch, ColumnWork) starts on one of its
/// own. Side by side in a vector, the end of one thread's struct and the start of the next one's
/// could share a line, wherever the vector lay (an arena's fill beside the list of tiles entered,
/// a tile's rewrite beside the merge's buffers): each thread's writes then evicted what the other
/// used (false sharing).
constexpr std::size_t kCacheLine = 64;

/// One thread's part of a scan: the tiles its readings' walks entered.
class alignas(kCacheLine) ScanScratch {
 public:
  /// Forgets the previous scan (its memory is kept for the next). Intervals less than
  /// `join_gap` apart will join (0: only overlapping or touching ones); masses are summed only
  /// if `count_masses`. The readings will stay within the tiles of `tiles` if it is not empty.
  /// A level scan (`level` not null, masses not counted) gives every cell it frees the one free
  /// volume `*level`: the scratch keeps one bit a cell (Writer<false, true>).
  void begin(float join_gap, bool count_masses, const CellRange& tiles,
             const Volume* level = nullptr);

  /// Adds one scan's volumes to the scratch at the cell where it is: the cursor of a ray's walk
  /// (walkRayWith), copied into each walk so that what every cell visit needs stays in
  /// registers. It keeps the cell as its tile and the cell's place there, moved one step at a
  /// time. kLevel: the writer of a level scan (see begin).
  template <bool kCountMasses, bool kLevel = false>
  class Writer {
   public:
    explicit Writer(ScanScratch& scratch)
        : scratch_(scratch),
          stamp_(scratch.stamp_),
          inline_only_(slotTag(scratch.stamp_, kNoOthers)),
          join_gap_(scratch.join_gap_) {}

    void moveTo(const CellIndex& cell) {
      tile_x_ = cell.x >> kTileSizeLog2;
      tile_y_ = cell.y >> kTileSizeLog2;
      local_x_ = cell.x & (kTileSize - 1);
      local_y_ = cell.y & (kTileSize - 1);
      enterTile();
    }
    void stepX(int step) {
      local_x_ += step;
      if (static_cast<unsigned>(local_x_) >= kTileSize) {  // into the next tile along x
        local_x_ -= step * kTileSize;
        tile_x_ += step;
        enterTile();
      }
    }
    void stepY(int step) {
      local_y_ += step;
      if (static_cast<unsigned>(local_y_) >= kTileSize) {
        local_y_ -= step * kTileSize;
        tile_y_ += step;
        enterTile();
      }
    }

    /// Called for every cell a ray crosses: the commonest case (the interval inline grows)
    /// stays inline in the ray walk (forced: see walkReading in scan_update.cpp).
    [[gnu::always_inline]] void addFree(const Volume& volume) {
      ScratchTile& tile = *tile_;
      const unsigned local = currentLocal();
      if constexpr (kLevel) {  // every free volume of the scan is the level one
        static_assert(!kCountMasses, "a level scan's cells hold no masses");
        tile.markLevelFree(local);
        return;
      }
      FreeSlot& slot = tile.slots[local];
      if (slot.stamp() == stamp_) {
        if (intervalsJoin(volume.bottom, volume.top, slot.bottom, slot.top, join_gap_)) {
          slot.grow(volume);
          if (kCountMasses) tile.masses[local] += volume.mass;
          return;
        }
      } else {  // the cell's first interval of this scan
        slot = {volume.bottom, volume.top, inline_only_};
        if (kCountMasses) tile.masses[local] = volume.mass;
        tile.markReached(local);
        return;
      }
      scratch_.addFreeSlow(tile, local, volume);
    }
    void addHit(const Volume& volume) { scratch_.addHit(*tile_, currentLocal(), volume); }

   private:
    /// Finds (or adds) the tile the walk has just entered, on entering it rather than at each
    /// visit: the test of a step into another tile is there anyway. A tile whose cells the walk
    /// does not cross (it passes a grid corner, or starts on the wall it leaves through:
    /// walkRayWith) is added too, with no cell reached (ScratchTile::reachedNone), and the update
    /// passes it by.
    void enterTile() {
      ScratchTile* known = scratch_.denseTile(tile_x_, tile_y_);
      tile_ = known != nullptr ? known : &scratch_.findOrAddTile(tile_x_, tile_y_);
    }
    unsigned currentLocal() const { return static_cast<unsigned>(local_y_ * kTileSize + local_x_); }

    ScanScratch& scratch_;
    const std::uint32_t stamp_;
    const std::uint64_t inline_only_;  ///< the tag of a slot of this scan without others
    const float join_gap_;
    ScratchTile* tile_ = nullptr;
    std::int32_t tile_x_ = 0;
    std::int32_t tile_y_ = 0;
    std::int32_t local_x_ = 0;  ///< 0 to kTileSize - 1 between steps
    std::int32_t local_y_ = 0;
  };

  /// The tile `key` of this scan, or nullptr.
  const ScratchTile* find(std::uint64_t key) const;
  /// Every tile this scan's walks entered, by key, some perhaps with no cell reached
  /// (ScratchTile::reachedNone).
  const std::vector<std::pair<std::uint64_t, ScratchTile*>>& tiles() const { return entered_; }
  /// Whether cell `local` of `tile` holds exactly one free interval; if so, sets it.
  bool singleFree(const ScratchTile& tile, unsigned local, ScanInterval& interval) const {
    if (level_) {
      if (!tile.levelFree(local)) return false;
      interval = {level_volume_.bottom, level_volume_.top, 0.0};
      return true;
    }
    const FreeSlot& slot = tile.slots[local];
    if (slot.tag != slotTag(stamp_, kNoOthers)) return false;
    interval = {slot.bottom, slot.top, count_masses_ ? tile.masses[local] : 0.0};
    return true;
  }
  /// Appends the free intervals of cell `local` of `tile` (sorted, disjoint) to `out`; their
  /// masses are 0 unless counted.
  void appendFree(const ScratchTile& tile, unsigned local, std::vector<ScanInterval>& out) const;

 private:
  /// Where the dense index holds tile (tile_x, tile_y), or kNotDense outside it.
  static constexpr std::size_t kNotDense = ~std::size_t{0};
  std::size_t denseIndex(std::int32_t tile_x, std::int32_t tile_y) const {
    const auto column = static_cast<std::uint32_t>(tile_x - dense_min_x_);
    const auto row = static_cast<std::uint32_t>(tile_y - dense_min_y_);
    if (column >= dense_width_ || row >= dense_height_) return kNotDense;
    return std::size_t{row} * dense_width_ + column;
  }
  /// The tile (tile_x, tile_y) if this scan entered it already and the dense index holds it,
  /// else null. Inline: a ray's walk enters a tile every few cells.
  ScratchTile* denseTile(std::int32_t tile_x, std::int32_t tile_y) const {
    const std::size_t index = denseIndex(tile_x, tile_y);
    return index == kNotDense ? nullptr : dense_[index];
  }
  ScratchTile& findOrAddTile(std::int32_t tile_x, std::int32_t tile_y);
  /// A hit's volume in cell `local` of `tile` (out of line: once a ray, not in its walk's loop).
  void addHit(ScratchTile& tile, unsigned local, const Volume& volume);
  /// An interval that does not reach the inline interval of a slot of this scan: the inline
  /// one goes among the others and the new one comes inline, each joined with those it reaches.
  void addFreeSlow(ScratchTile& tile, unsigned local, const Volume& volume);
  /// The heights of an interval in the arena (its mass, if counted, at the same place in
  /// masses_): 8 bytes, half a ScanInterval, since a rotating lidar's columns hold many.
  struct Heights {
    float bottom;
    float top;
  };
  /// A column's first other intervals get 64 bytes of room (most hold a few).
  static constexpr std::uint32_t kFirstCapacity = 64 / sizeof(Heights);
  /// Room in the arena for `capacity` intervals (kFirstCapacity times a power of two): its
  /// offset.
  std::size_t allocate(std::uint32_t capacity);
  /// k for a capacity of kFirstCapacity << k: the list of free_runs_ its room goes to.
  static std::size_t sizeClass(std::uint32_t capacity);
  /// Moves `others`, which is full, to room twice as large; the room it leaves goes to the next
  /// run needing room of that size (allocate).
  void moveToLargerRoom(OtherIntervals& others);
  ScanInterval intervalAt(std::size_t index) const {
    return {heights_[index].bottom, heights_[index].top, count_masses_ ? masses_[index] : 0.0};
  }
  void setInterval(std::size_t index, const ScanInterval& interval) {
    heights_[index] = {interval.bottom, interval.top};
    if (count_masses_) masses_[index] = interval.mass;
  }
  /// Moves the arena's intervals [from, from + count) to `to` (the two may overlap).
  void moveIntervals(std::size_t from, std::size_t count, std::size_t to) {
    std::memmove(heights_.get() + to, heights_.get() + from, count * sizeof(Heights));
    if (count_masses_) {
      std::memmove(masses_.get() + to, masses_.get() + from, count * sizeof(double));
    }
  }
  /// Replaces the intervals [first, last) of `others`, which has room for one more, by
  /// `interval`.
  void replaceRange(OtherIntervals& others, std::size_t first, std::size_t last,
                    const ScanInterval& interval) {
    moveIntervals(last, others.offset + others.size - last, first + 1);
    setInterval(first, interval);
    others.size = static_cast<std::uint32_t>(others.size + 1 - (last - first));
  }
  /// The run [first, last) of the arena's intervals in [begin, end) (sorted, more than the join
  /// gap apart) that `interval` reaches, joined into it: their union reaches no other. The run is
  /// empty, at the first interval above, if it reaches none.
  std::pair<std::size_t, std::size_t> joinReached(std::size_t begin, std::size_t end,
                                                  ScanInterval& interval) const {
    std::size_t first = begin;
    while (first != end && !joins(heights_[first].top, interval.bottom, join_gap_)) ++first;
    std::size_t last = first;
    for (; last != end && joins(interval.top, heights_[last].bottom, join_gap_); ++last) {
      interval.bottom = std::min(interval.bottom, heights_[last].bottom);
      interval.top = std::max(interval.top, heights_[last].top);
      if (count_masses_) interval.mass += masses_[last];
    }
    return {first, last};
  }

  /// The tiles entered, by key, and the index from tile to scratch: dense over the scan's tiles
  /// when they are few enough, else hashed.
  std::vector<std::pair<std::uint64_t, ScratchTile*>> entered_;
  /// The dense index: tiles [min, min + width) x [min, min + height), rows of width entries.
  std::int32_t dense_min_x_ = 0;
  std::int32_t dense_min_y_ = 0;
  std::uint32_t dense_width_ = 0;
  std::uint32_t dense_height_ = 0;
  std::vector<ScratchTile*> dense_;
  std::unordered_map<std::uint64_t, ScratchTile*> hashed_;
  std::vector<std::unique_ptr<ScratchTile>> pool_;
  /// The other intervals of columns with several (FreeSlot::others indexes this scan's), runs of
  /// one arena: the first arena_used_ intervals are this scan's.
  std::vector<OtherIntervals> others_;
  /// Left uninitialised: pages not yet written (masses_ when masses are not counted) take no
  /// memory.
  std::unique_ptr<Heights[]> heights_;
  std::unique_ptr<double[]> masses_;
  std::size_t arena_capacity_ = 0;
  std::size_t arena_used_ = 0;
  /// The room runs left when they moved (moveToLargerRoom), by capacity: kFirstCapacity <<
  /// index.
  std::vector<std::vector<std::size_t>> free_runs_;
  std::uint32_t stamp_ = 0;
  float join_gap_ = 0.0f;
  bool count_masses_ = false;
  /// A level scan, and its one free volume (see begin).
  bool level_ = false;
  Volume level_volume_{};
};

/// The voxel a reading's ray ends in (grid units: its cell, and the floor of its height), and
/// whether it ends in an obstacle (FreeSpaceRays::kOnePerEndVoxel).
struct EndVoxel {
  std::int32_t x;
  std::int32_t y;
  std::int32_t z;
  bool obstacle;
};

/// The voxel `end` (grid units) lies in.
inline EndVoxel endVoxelOf(const Eigen::Vector3d& end, bool obstacle) {
  const CellIndex cell = cellAt(end.x(), end.y());
  return {cell.x, cell.y, floorToIndex(end.z()), obstacle};
}

/// The fewest readings of a scan ending in one voxel for which one ray is walked
/// (FreeSpaceRays::kOnePerEndVoxel): n readings spread over a voxel lie about 1 / sqrt(n) cells
/// apart, from 4 on half a cell or less, closer than the one cell of height eq. (6) gives each
/// crossing, so that their rays free nearly the same cells at nearly the same heights. A sparse
/// sensor's few readings in a voxel are walked each: their rays part by up to a cell, and no
/// neighbour's ray frees what one of them alone does.
constexpr std::uint32_t kReadingsForOneRay = 4;

/// Eq. (5): a hit's positive volume, one cell high around its height `end_z` (grid units).
inline Volume hitVolume(float end_z) { return makeVolume(end_z - 0.5f, end_z + 0.5f); }

/// The readings of a scan ending in one voxel: their ends while fewer than kReadingsForOneRay
/// (each walked), the end nearest the voxel's centre (the one walked for all from then on), and
/// in an obstacle's voxel the lowest and highest of their heights: the union of their hits'
/// volumes (eq. 5: each is a cell high and their heights are less than one apart, so that they
/// overlap) spans from the lowest's bottom to the highest's top (EndVoxelRays::hitsOf).
struct VoxelReadings {
  std::array<Eigen::Vector3d, kReadingsForOneRay - 1> ends;  ///< the first ones, grid units
  Eigen::Vector3d nearest;
  double nearest_distance;  ///< squared, from `nearest` to the voxel's centre
  CellIndex cell;
  float lowest_hit;  ///< heights as hitVolume takes them (masses are not counted per scan)
  float highest_hit;
  std::uint32_t count;
  bool obstacle;
};

/// A scan's end voxels (or columns: z = 0), each with the index it was added at (0, 1, ...): an
/// open-addressing hash set kept from scan to scan, its slots stamped with their scan so that
/// none needs clearing.
class EndVoxelIndex {
 public:
  /// Forgets the previous scan's voxels (the memory is kept).
  void begin();
  /// The index of `voxel`, and whether it is new (then it gets the next index).
  std::pair<std::uint32_t, bool> findOrAdd(const EndVoxel& voxel);

 private:
  struct Slot {
    std::int32_t x;
    std::int32_t y;
    std::int32_t z;
    /// The scan's stamp << 1 | obstacle; a slot of another scan is empty.
    std::uint32_t tag;
    std::uint32_t index;
  };
  /// Puts `slot` (not in the set) in its place.
  void place(const Slot& slot);
  /// Doubles the slots, keeping this scan's.
  void grow();

  std::vector<Slot> slots_;  ///< a power of two of them, at most half this scan's
  std::uint32_t stamp_ = 0;  ///< 1 to 2^31 - 1
  std::uint32_t size_ = 0;   ///< this scan's voxels
};

/// One thread's end voxels in a scan and their readings (FreeSpaceRays::kOnePerEndVoxel). The ray
/// walked for a voxel of kReadingsForOneRay readings or more is that of the reading ending
/// nearest its centre, ties to the lowest end in x, then y, then z, so that the choice does not
/// depend on the readings' order. Kept from scan to scan with its memory.
class alignas(kCacheLine) EndVoxelRays {
 public:
  /// Forgets the previous scan's voxels (their memory is kept).
  void begin();
  /// A reading of the scan ending at `end` (grid units), in an obstacle or not. Inline where it
  /// ends in the voxel of the reading before.
  void offer(const Eigen::Vector3d& end, bool obstacle) {
    // floor(g) == k exactly where k <= g < k + 1: the test needs no conversion to integers.
    if (obstacle == last_obstacle_ && (end.array() >= last_corner_.array()).all() &&
        (end.array() < last_corner_.array() + 1.0).all()) {
      join(voxels_[last_index_], obstacle, end, (end - last_centre_).squaredNorm());
      return;
    }
    offerElsewhere(endVoxelOf(end, obstacle), end);
  }
  /// The voxels offered, in the order first offered.
  const std::vector<VoxelReadings>& voxels() const { return voxels_; }
  /// Adds the readings of `other`'s voxels (another part of the scan's readings): the voxels of
  /// offering both parts' readings to one set, the same rays to walk, whatever the split.
  void merge(const EndVoxelRays& other);
  /// The union of the hits' volumes of an obstacle's voxel. A hit's volume (hitVolume) is
  /// exactly [z - 0.5, z + 0.5]: both sums are exact for a float of magnitude up to 2^22
  /// (MapConfig's bound in cells), so its bottom and top grow with z.
  static Volume hitsOf(const VoxelReadings& voxel) {
    return volumeOfMinimumHeight(hitVolume(voxel.lowest_hit).bottom,
                                 hitVolume(voxel.highest_hit).top);
  }
  /// Calls walk(end) for the ray of each of the voxel's readings to walk.
  template <class Walk>
  static void forEachRayOf(const VoxelReadings& voxel, Walk&& walk) {
    if (voxel.count >= kReadingsForOneRay) {
      walk(voxel.nearest);
      return;
    }
    for (std::uint32_t k = 0; k < voxel.count; ++k) walk(voxel.ends[k]);
  }

 private:
  /// offer() for a reading ending in another voxel than the reading before.
  void offerElsewhere(const EndVoxel& voxel, const Eigen::Vector3d& end);
  /// Adds a reading of the voxel of `readings`, ending at `end`, at squared distance `distance`
  /// from its centre.
  static void join(VoxelReadings& readings, bool obstacle, const Eigen::Vector3d& end,
                   double distance) {
    if (readings.count < readings.ends.size()) readings.ends[readings.count] = end;
    ++readings.count;
    if (obstacle) {
      const auto z = static_cast<float>(end.z());
      readings.lowest_hit = std::min(readings.lowest_hit, z);
      readings.highest_hit = std::max(readings.highest_hit, z);
    }
    keepNearer(readings, end, distance);
  }
  /// Makes `end`, `distance` from the voxel's centre, the readings' nearest if it is nearer, or
  /// as near and lower in x, then y, then z: an order in which no two ends tie.
  static void keepNearer(VoxelReadings& readings, const Eigen::Vector3d& end, double distance) {
    if (distance < readings.nearest_distance ||
        (distance == readings.nearest_distance &&
         std::lexicographical_compare(end.data(), end.data() + 3, readings.nearest.data(),
                                      readings.nearest.data() + 3))) {
      readings.nearest = end;
      readings.nearest_distance = distance;
    }
  }
  /// The corner of `voxel` with the lowest coordinates (grid units).
  static Eigen::Vector3d cornerOf(const EndVoxel& voxel) {
    return Eigen::Vector3d(voxel.x, voxel.y, voxel.z);
  }
  EndVoxelIndex index_;  ///< of voxels_
  std::vector<VoxelReadings> voxels_;
  /// The voxel last offered: its readings' kind, its index, its corner (cornerOf; NaN, in which
  /// no end lies, before a scan's first reading) and its centre. A depth image's neighbouring
  /// pixels mostly end in one.
  bool last_obstacle_ = false;
  std::uint32_t last_index_ = 0;
  Eigen::Vector3d last_corner_ =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector3d last_centre_ = Eigen::Vector3d::Zero();
};

/// Joins the intervals of a list sorted by bottom that come within `join_gap`, in place.
void joinSorted(std::vector<ScanInterval>& intervals, float join_gap);
/// Which thread's scratch each reading of a scan goes to, and what decided it: kept from scan
/// to scan.
struct ReadingSplit {
  /// By reading (hits, then out-of-range ones), or by end voxel (splitEndVoxelsBySector).
  std::vector<std::uint8_t> chunk_of_reading;
  std::vector<std::uint16_t> sector_of_reading;  ///< the direction of its ray
  std::vector<double> cells_in_sector;           ///< the cell visits of the sector's readings
  std::vector<double> cells_in_part;  ///< the same by run of readings (a thread's), then sector
};
/// How far from the sensor a reading of `kind` may free space (m): a hit up to max_range, a
/// reading without a return up to out_of_range_free_length too (ModelRules).
inline double freeLengthOf(ReadingKind kind, const MapConfig& map_config,
                           const InsertionConfig& config) {
  return kind == ReadingKind::kObstacle
             ? config.max_range
             : std::min(config.max_range, map_config.rules.out_of_range_free_length);
}

/// Where a reading's ray from `origin` to `end`, `length` long, stops freeing space: its end, or
/// `free_length` along it.
inline Eigen::Vector3d freeEnd(const Eigen::Vector3d& origin, const Eigen::Vector3d& end,
                               double length, double free_length) {
  return length > free_length ? Eigen::Vector3d(origin + (end - origin) * (free_length / length))
                              : end;
}

/// Checks one reading and counts it in `result`; on acceptance sets the ray's end (truncated to
/// max_range) and whether it ends in an obstacle. `origin_accepted`: the scan's origin is within
/// the map's bounds (checked once a scan).
[[gnu::always_inline]] inline bool acceptReading(const Eigen::Vector3d& origin,
                                                 bool origin_accepted, const Eigen::Vector3d& end,
                                                 ReadingKind kind, const MapConfig& map_config,
                                                 const InsertionConfig& config,
                                                 Eigen::Vector3d& ray_end, bool& obstacle,
                                                 InsertionResult& result) {
  const bool is_obstacle = kind == ReadingKind::kObstacle;
  if (!origin_accepted || !map_config.withinBounds(end)) {
    if (!origin.allFinite() || !end.allFinite()) {
      ++result.rejected_non_finite;
    } else {
      ++result.rejected_out_of_bounds;
    }
    return false;
  }
  const Eigen::Vector3d ray = end - origin;
  const double length = ray.norm();
  // A zero-length out-of-range reading carries no free space; a zero-length hit is below any
  // min_range but the sensor itself (decision: both are dropped as too close).
  if (length == 0.0 || (is_obstacle && length < config.min_range)) {
    ++result.rejected_too_close;
    return false;
  }
  obstacle = is_obstacle && length <= config.max_range;
  if (!obstacle && !config.insert_out_of_range) {
    ++result.ignored_out_of_range;
    return false;
  }
  ray_end = freeEnd(origin, end, length, freeLengthOf(kind, map_config, config));
  if (obstacle) {
    ++result.obstacle_readings;
  } else {
    ++result.out_of_range_readings;
    if (is_obstacle) ++result.truncated_to_max_range;
  }
  return true;
}

/// The most the end heights of two neighbouring rays of an end column's run may differ (grid
/// units, FreeSpaceRays::kOnePathPerEndColumn). Rays from one origin whose end heights differ by
/// d differ by at most d wherever they cross a cell, and each crossing is a cell high or more
/// (eq. 6): their volumes there lie at most d - 1 apart, so that up to d = 1 + kMaxMergeGap a
/// scan's intervals join (joinGapOf) and a run's crossings of a cell fill one interval.
constexpr double kColumnRunHeightGap = 1.0 + kMaxMergeGap;

/// The rays of one thread's end voxels of kReadingsForOneRay readings or more (each walks the
/// ray of its reading nearest its centre) by the column they end in and whether they end in an
/// obstacle, each column's in runs of neighbouring end heights
/// (FreeSpaceRays::kOnePathPerEndColumn). Kept from scan to scan with its memory.
class EndColumnRuns {
 public:
  /// The rays of the voxels k of `voxels` for which mine(k), of kReadingsForOneRay readings or
  /// more, in runs.
  template <class Mine>
  void gather(const std::vector<VoxelReadings>& voxels, const Mine& mine) {
    columns_.begin();
    column_rays_.clear();
    ends_.clear();
    for (std::size_t k = 0; k < voxels.size(); ++k) {
      const VoxelReadings& voxel = voxels[k];
      if (voxel.count < kReadingsForOneRay || !mine(k)) continue;
      const std::uint32_t column =
          columns_.findOrAdd({voxel.cell.x, voxel.cell.y, 0, voxel.obstacle}).first;
      if (column == column_rays_.size()) column_rays_.push_back(0);
      ends_.push_back({voxel.nearest, static_cast<std::uint32_t>(k), column});
      ++column_rays_[column];
    }
    formRuns(voxels.size());
  }
  /// Calls walk(ends, count, path) for the run whose first voxel (of those gathered) is voxel
  /// `k`, if it is one's: ends[0, count) sorted by height, ends[path] the one ending nearest
  /// the column's axis (ties to the lowest end in x, then y, then z). A run is walked where its
  /// first voxel's ray would be: a scan's neighbouring readings' walks then mostly grow one
  /// interval of a cell, as each voxel's own walk would.
  template <class Walk>
  void walkRunFrom(std::size_t k, Walk&& walk) const {
    const std::uint32_t index = run_of_first_voxel_[k];
    if (index == kNoRun) return;
    const Run& run = runs_[index];
    walk(by_column_.data() + run.first, run.count, run.path);
  }

 private:
  /// A ray's end, its voxel's index and its column's.
  struct RayEnd {
    Eigen::Vector3d end;
    std::uint32_t voxel;
    std::uint32_t column;
  };
  struct Run {
    std::uint32_t first;  ///< in by_column_
    std::uint32_t count;
    std::uint32_t path;  ///< the ray whose path the run follows, from first
  };
  static constexpr std::uint32_t kNoRun = ~std::uint32_t{0};
  /// Sorts ends_ by column and end height into by_column_, and finds the runs and their first
  /// of the `voxels` voxels.
  void formRuns(std::size_t voxels);

  EndVoxelIndex columns_;  ///< the columns of the rays' ends (z = 0), and whether they end in a hit
  std::vector<std::uint32_t> column_rays_;  ///< by column: how many rays end there, then where
  std::vector<RayEnd> ends_;                ///< in the voxels' order
  std::vector<RayEnd> sorted_;              ///< by column, then height
  std::vector<Eigen::Vector3d> by_column_;  ///< the ends of sorted_
  std::vector<Run> runs_;
  std::vector<std::uint32_t> run_of_first_voxel_;  ///< by voxel: the run it is the first of
};

/// What grouping a scan's readings by end voxel learnt of them all (groupByEndVoxel).
struct GroupedScan {
  /// The cells of the origin and of every accepted reading's end: every walk stays within them.
  CellRange cells = kNoCells;
  /// Every accepted reading at the origin's height: a level scan (addReading's level ray).
  bool level = true;
};

/// Checks and counts (in `result`) every reading of `scan`, and groups the accepted ones by end
/// voxel into voxels[0], in one pass over them (FreeSpaceRays::kOnePerEndVoxel); with `pool`,
/// each of its threads a run of the readings into voxels[k], then merged into voxels[0] (the
/// same voxels). Nothing is walked yet: the walks follow the voxels.
GroupedScan groupByEndVoxel(const Scan& scan, const MapConfig& map_config,
                            const InsertionConfig& insertion, ThreadPool* pool,
                            std::vector<EndVoxelRays>& voxels, InsertionResult& result);
/// The same straight from the pixels of a depth image (validated), each thread a run of its
/// rows, the pixels without a measurement counted in result.rejected_no_measurement.
GroupedScan groupByEndVoxel(const DepthFrame& frame, const MapConfig& map_config,
                            const InsertionConfig& insertion, ThreadPool* pool,
                            std::vector<EndVoxelRays>& voxels, InsertionResult& result);

/// Whether every reading of `scan` lies in one plane through its origin, as a line scanner's do
/// (a 2D laser's scan, one line of a tilting laser): InsertionConfig::hit_memory_scans groups
/// such scans (Sec. V.B). Within a thousandth of a cell (`resolution`, m), and the single
/// precision's rounding of the readings. A scan of one reading, or of readings in line, is one.
bool isLineScan(const Scan& scan, double resolution);

/// Whether a scan joins the map's scan groups (InsertionConfig::hit_memory_scope): every scan
/// does with HitMemoryScope::kEveryScan; with kLineScans a line scan (isLineScan) does, tested
/// only where the map remembers hits at all. `scan` is null for a depth image, never a line.
bool joinsHitMemory(const MapConfig& map_config, const InsertionConfig& insertion,
                    const Scan* scan);

/// Whether a scan's free space is walked one ray per end voxel (FreeSpaceRays).
inline bool walksOneRayPerEndVoxel(const MapConfig& map_config, const InsertionConfig& insertion) {
  return map_config.rules.mass_counting == MassCounting::kPerScan &&
         insertion.free_space_rays != FreeSpaceRays::kEveryReading &&
         insertion.model_negative_space;
}
/// Splits a scan's readings among `chunks` threads (see scan_update.cpp), reading them on
/// `pool`'s threads if not null.
void splitReadingsBySector(const Scan& scan, const MapConfig& map_config,
                           const InsertionConfig& insertion, std::size_t chunks, ThreadPool* pool,
                           ReadingSplit& split);
/// Splits a scan's end voxels (FreeSpaceRays::kOnePerEndVoxel) among `chunks` threads, the rays
/// from `start` (grid units).
void splitEndVoxelsBySector(const EndVoxelRays& voxels, const Eigen::Vector3d& start,
                            std::size_t chunks, ReadingSplit& split);
/// The gap under which one scan's intervals join (see ScanInterval).
inline float joinGapOf(const ModelRules& rules) {
  return rules.mass_counting == MassCounting::kPerScan ? kMaxMergeGap : 0.0f;
}

class RecentHits;
struct RecentTileHits;

/// One thread's working memory while Map::apply applies a scan (ScanUpdate::Impl keeps it from
/// scan to scan).
struct alignas(kCacheLine) ColumnWork {
  /// The map's recent hits that clip the scan's free space (InsertionConfig::hit_memory_scans),
  /// or null, those of how many scans, those of the tile being updated (RecentHits::tile, or
  /// null), and whether the column being updated may hold some.
  const RecentHits* recent_hits = nullptr;
  int hit_memory_scans = 0;
  const RecentTileHits* remembered_tile = nullptr;
  bool column_remembered = false;
  ListMerger merger;
  /// The scratches that reached the tile being updated, and their part of it.
  std::vector<std::pair<const ScanScratch*, const ScratchTile*>> parts;
  std::vector<TileHit> hits;                  // the tile's, by cell (gatherTile)
  std::vector<TileHit> sorted_hits;           // gatherTile's counting sort's output
  std::uint64_t reached[kCellsPerTile / 64];  // the cells the scan reached
  std::vector<ScanInterval> free;
  std::vector<ScanInterval> positive;
  /// The scan's hits and the recent ones, by bottom: where its free space is clipped.
  std::vector<ScanInterval> clip_at;
  CellVolumes added;
  std::vector<double> evidence_factors;  // boundEvidence's
  CellVolumes merged;
  /// The new lists of the tile's cells whose lists changed length.
  TileBlock::Rewrite rewrite;
  CellRange grown = kNoCells;  // cells that received their first volume
};

}  // namespace detail

struct ScanUpdate::Impl {
  MapConfig map_config;
  /// Of the scan prepared (Map::apply bounds the columns with its evidence limit).
  InsertionConfig insertion;
  InsertionResult result;
  /// Whether the scan prepared joins the map's scan groups (detail::joinsHitMemory): Map::apply
  /// clips it around the hits kept and keeps its own, or else forgets them.
  bool joins_hit_memory = false;
  /// One per chunk of readings (one per thread).
  std::vector<detail::ScanScratch> scratches;
  /// Those of threads the last scan did not use, kept with their memory.
  std::vector<detail::ScanScratch> idle_scratches;
  /// The scan's end voxels and their rays (FreeSpaceRays::kOnePerEndVoxel): the first holds them
  /// all once grouped (each thread groups a part of the readings into one), before the chunks
  /// walk them.
  std::vector<detail::EndVoxelRays> end_voxels;
  /// One per chunk: its end voxels' rays by end column (FreeSpaceRays::kOnePathPerEndColumn).
  std::vector<detail::EndColumnRuns> end_columns;
  /// With several threads: the scratch of each reading of the scan (splitReadingsBySector).
  detail::ReadingSplit split;
  std::unique_ptr<detail::ThreadPool> pool;
  /// Map::apply's working memory, one per thread: its buffers keep their capacity from scan to
  /// scan instead of growing anew at each.
  std::vector<detail::ColumnWork> column_work;

  /// Threads for `insertion_threads`, started once.
  detail::ThreadPool* threads(std::size_t count);
};

}  // namespace mvog
