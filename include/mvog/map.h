#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "mvog/cell_index.h"
#include "mvog/config.h"
#include "mvog/grid2d.h"
#include "mvog/volume.h"

namespace mvog {

/// What a range reading saw (Sec. III-B.1): an obstacle at its end, or nothing up to its end.
enum class ReadingKind : std::uint8_t {
  kObstacle,   ///< the ray hit something at its end: free space along it, occupied at the end
  kOutOfRange  ///< no return (or beyond the range limit): free space along it only
};

/// One scan (or point cloud) taken from one origin, in the map frame, metres.
struct Scan {
  /// The sensor's position. A level laser's scan, every reading at this height exactly (a height
  /// a float holds), is inserted with one free volume for all the cells it crosses when masses
  /// count per scan (MassCounting::kPerScan, the default): fastest.
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  /// Obstacle readings: the points where a ray hit something.
  std::vector<Eigen::Vector3f> hits;
  /// Out-of-range readings (ReadingKind::kOutOfRange): where the free space seen along a ray
  /// ends, with no obstacle there.
  std::vector<Eigen::Vector3f> out_of_range;
};

/// What happened to the readings given to an insertion. Every reading is counted exactly once.
struct InsertionResult {
  std::size_t obstacle_readings = 0;       ///< inserted with a positive volume
  std::size_t out_of_range_readings = 0;   ///< inserted as free space only (incl. truncated hits)
  std::size_t truncated_to_max_range = 0;  ///< hits beyond max_range, among out_of_range_readings
  std::size_t rejected_non_finite = 0;     ///< NaN or infinite coordinates
  std::size_t rejected_out_of_bounds = 0;  ///< beyond MapConfig::max_coordinate
  std::size_t rejected_too_close = 0;      ///< hits nearer than min_range
  std::size_t ignored_out_of_range = 0;    ///< out-of-range readings with insert_out_of_range off
  /// Pixels of a depth image without a measurement (0, NaN, negative, -Inf, or +Inf when
  /// DepthImageConfig::no_return_length is infinite: REP-118), inserted straight from the image.
  std::size_t rejected_no_measurement = 0;
  /// Rays walked for free space: one per inserted reading, one per end voxel
  /// (FreeSpaceRays::kOnePerEndVoxel), or one per run of an end column
  /// (kOnePathPerEndColumn); not a count of readings.
  std::size_t rays_walked = 0;
  /// Time spent rasterising the obstacle readings and the out-of-range readings (thread time,
  /// summed over the insertion's threads): how much the readings without a return cost. With
  /// one ray per end voxel or one path per end column the rays of hits truncated to max_range,
  /// which share end voxels with the out-of-range readings, are walked and timed with theirs.
  double obstacle_seconds = 0.0;
  double out_of_range_seconds = 0.0;

  std::size_t inserted() const { return obstacle_readings + out_of_range_readings; }
  std::size_t rejected() const {
    return rejected_non_finite + rejected_out_of_bounds + rejected_too_close +
           ignored_out_of_range + rejected_no_measurement;
  }
  InsertionResult& operator+=(const InsertionResult& other);
};

/// Eq. (9) at one point, with the two densities it comes from.
struct PointOccupancy {
  double positive_density = 0.0;  ///< rho+ (0 where no positive volume contains the point)
  double negative_density = 0.0;  ///< rho- (0 where no negative volume contains the point)
  /// p = rho+ / (rho+ + rho-), or nothing where unknown (rho+ + rho- = 0).
  std::optional<float> probability;

  bool known() const { return probability.has_value(); }
  /// Occupied where p > occupancy_threshold, free where p <= it, unknown where unknown.
  OccupancyState state(double occupancy_threshold) const;
};

/// A cell's two volume lists, heights in grid units and masses as of now.
struct CellVolumes {
  std::vector<Volume> positive;
  std::vector<Volume> negative;
};

/// A cell's two lists as the map stores them, without a copy: valid until the map next changes.
/// Masses are in the unit of the cell's tile, which eq. (9) and every ratio of densities do not
/// see (cellVolumes gives real masses).
struct ColumnView {
  const Volume* positive = nullptr;
  std::uint32_t num_positive = 0;
  const Volume* negative = nullptr;
  std::uint32_t num_negative = 0;
  bool empty() const { return num_positive + num_negative == 0; }
};

/// Memory held by the map.
struct MemoryUsage {
  /// Bytes the map holds: its tiles, the index of tiles and every cell's volume storage with
  /// its spare capacity, and its record of removed tiles (allocator bookkeeping not included).
  std::size_t bytes_held = 0;
  /// The paper's Table I accounting: 12 bytes per volume plus an 8-byte reference per cell of
  /// the minimal 2D grid that holds every cell with a volume.
  std::size_t table_one_bytes = 0;
  std::size_t minimal_grid_cells = 0;
  std::size_t cells_with_volumes = 0;
  std::size_t positive_volumes = 0;
  std::size_t negative_volumes = 0;
  std::size_t tiles = 0;
};

/// Square block of cells the map is stored in (Sec. V.A: the map grows by adding tiles, no cell
/// is ever copied). Tiles are also the unit of change tracking for incremental publication.
struct TileIndex {
  std::int32_t x = 0;
  std::int32_t y = 0;
  friend bool operator==(const TileIndex& a, const TileIndex& b) {
    return a.x == b.x && a.y == b.y;
  }
};

/// What Map::forget removed.
struct ForgetResult {
  std::size_t volumes_removed = 0;  ///< positive volumes and negative volumes (each piece counted)
  std::size_t cells_emptied = 0;    ///< cells left without a volume, now unknown
  std::size_t tiles_freed = 0;      ///< tiles left without a cell, their memory released
};

/// A transform between two maps of one resolution that keeps the grid, so that merging moves
/// volumes from cell to cell without resampling them (Map::merge): a rotation about z by
/// quarter_turns x 90 degrees (counter-clockwise), then a translation by whole cells in x and y
/// and by dz metres in z. A quarter turn takes cell (i, j), the square [i, i + 1) x [j, j + 1),
/// to the square [-j - 1, -j) x [i, i + 1): cell (-j - 1, i).
struct GridTransform {
  int quarter_turns = 0;  ///< any integer; taken modulo 4
  std::int64_t dx_cells = 0;
  std::int64_t dy_cells = 0;
  double dz = 0.0;  ///< metres

  /// The transform `this_from_other` (a homogeneous 4 x 4 matrix, metres) as a GridTransform for
  /// maps of `resolution`. Throws ConfigError saying why if it is not finite, not rigid, has a
  /// roll or pitch, a yaw that is no multiple of 90 degrees, or an x or y translation that is no
  /// whole number of cells (each to within 1e-6 of a cell, or of 1 in the rotation's entries):
  /// any of those would need the volumes resampled.
  static GridTransform fromMatrix(const Eigen::Matrix4d& this_from_other, double resolution);
  /// Where a cell of the other map goes: (x, y), in 64 bits (it may lie beyond any map).
  std::array<std::int64_t, 2> target(const CellIndex& cell) const;
};

class ScanUpdate;
struct DepthFrame;
namespace detail {
class TileBlock;
struct MapUpdateCodec;
}  // namespace detail

/// A Multi-Volume Occupancy Grid (Dryanovski, Morris, Xiao, IROS 2010).
///
/// Not thread-safe: callers serialise writers against readers (const methods may run
/// concurrently with each other).
class Map {
 public:
  static constexpr int kTileSizeLog2 = 4;
  static constexpr int kTileSize = 1 << kTileSizeLog2;  ///< cells per tile edge

  /// Throws ConfigError if `config` is invalid.
  explicit Map(const MapConfig& config = MapConfig{});
  ~Map();
  Map(Map&&) noexcept;
  Map& operator=(Map&&) noexcept;
  Map(const Map&) = delete;
  Map& operator=(const Map&) = delete;

  const MapConfig& config() const { return config_; }
  double resolution() const { return config_.resolution; }

  // ---- Insertion (Sec. III-B, Fig. 2) -----------------------------------------------------

  /// Inserts a whole scan as Fig. 2 draws it: every reading rasterised and its new volumes
  /// created (ScanUpdate::prepare), then the constraints applied once to every list the scan
  /// modified (apply). The map depends on the set of the scan's new volumes only: not on the
  /// order of its readings, nor on config.insertion_threads.
  InsertionResult insertScan(const Scan& scan, const InsertionConfig& config = {});
  /// Inserts a depth image straight from its pixels: the map insertScan makes of the image's
  /// readings (backProjectDepthImage), without a Scan of them in between when one ray per end
  /// voxel is walked (ScanUpdate::prepare of a DepthFrame).
  InsertionResult insertDepthImage(const DepthFrame& frame, const InsertionConfig& config = {});
  /// The scan of one reading ending at `end`: an obstacle reading, or an out-of-range reading.
  InsertionResult insertReading(const Eigen::Vector3d& origin, const Eigen::Vector3d& end,
                                ReadingKind kind, const InsertionConfig& config = {});
  /// The second half of insertScan: applies the constraints (eqs. 6-8, the model's rules) to
  /// every list `update` reaches, with its new volumes. Throws ConfigError if the update was
  /// prepared for another configuration (resolution, max_coordinate, rules).
  InsertionResult apply(ScanUpdate& update);

  // ---- Queries (Sec. III-C) ---------------------------------------------------------------

  /// Densities and probability at a world point (m). NaN or infinite coordinates: unknown.
  PointOccupancy occupancy(const Eigen::Vector3d& point) const;
  /// The volume lists of one cell (empty lists for a cell never observed).
  CellVolumes cellVolumes(const CellIndex& cell) const;
  /// The same without a copy, masses as stored (see ColumnView): for queries over many cells.
  ColumnView column(const CellIndex& cell) const;
  /// Cell holding the world point (x, y).
  CellIndex cellAtPoint(double x, double y) const;
  /// Eq. (9) at height z (m) over `cells` (Fig. 5).
  CrossSection crossSection(double z, const CellRange& cells) const;
  /// Over the height band [z_min, z_max] (m; infinite bounds allowed): occupied where some point
  /// of the band has p > occupancy_threshold, free where some point of the band is known and none
  /// is occupied, unknown where nothing in the band was observed.
  Projection projection(double z_min, double z_max, double occupancy_threshold,
                        const CellRange& cells) const;
  /// The smallest rectangle holding every cell with a volume (empty for an empty map).
  CellRange bounds() const { return bounds_; }
  /// Cells of the world rectangle [min_x, max_x] x [min_y, max_y] (m).
  CellRange cellsInRectangle(double min_x, double min_y, double max_x, double max_y) const;

  /// Calls visit(CellIndex, VolumeSign, const Volume&) for every volume (masses as of now), tile
  /// rows from the lowest, each tile's cells row by row.
  void forEachVolume(
      const std::function<void(const CellIndex&, VolumeSign, const Volume&)>& visit) const;
  /// Same, restricted to the cells of `cells`.
  void forEachVolumeIn(
      const CellRange& cells,
      const std::function<void(const CellIndex&, VolumeSign, const Volume&)>& visit) const;

  // ---- Decay (Sec. III-E) -----------------------------------------------------------------

  /// Multiplies every mass by k_d in (0, 1], in O(1): masses are stored in a unit that a single
  /// factor converts, so no tile is touched. A tile's stored masses are rescaled, exactly by a
  /// power of two, only when the tile is next written. Hence the probabilities of a tile that
  /// receives no new reading stay bit for bit the same after any number of steps; in a tile
  /// that does, masses decayed below float range relative to the new ones become 0. Masses and
  /// densities read back (cellVolumes, occupancy) underflow to 0 after extreme decay.
  /// Increases revision() (unless k_d = 1) but marks no tile: no probability changes.
  void decay(double k_d);

  // ---- Bookkeeping ------------------------------------------------------------------------

  MemoryUsage memoryUsage() const;
  bool empty() const { return bounds_.empty(); }
  void clear();
  /// Increases with every change; tilesModifiedSince() lists the tiles whose volumes changed
  /// after a revision (decay, which scales every mass alike, lists none).
  std::uint64_t revision() const { return revision_; }
  std::vector<TileIndex> tilesModifiedSince(std::uint64_t revision) const;
  /// Cells covered by a tile (whether or not they hold volumes).
  static CellRange tileCells(const TileIndex& tile);
  static TileIndex tileOf(const CellIndex& cell) {
    return {cell.x >> kTileSizeLog2, cell.y >> kTileSizeLog2};  // arithmetic shift floors
  }

  // ---- Direct access (serialisation, merging) ----------------------------------------------

  /// A cell's new lists (masses as cellVolumes returns them).
  struct CellAssignment {
    CellIndex cell;
    CellVolumes volumes;
  };
  /// Replaces the lists of the cells given (each tile is rewritten once, whatever the number of
  /// its cells given). Throws ConfigError, changing nothing, unless every list satisfies the
  /// Sec. III-A constraints (checkColumn under the map's rules; finite non-negative masses
  /// representable in the map's decayed mass unit), every cell lies within max_coordinate (|i|,
  /// |j| <= max_coordinate / resolution + 1, the cells readings can reach) and appears once.
  /// Emptying a cell removes it from bounds(). Under ModelRules::split_free_space_at_obstacles,
  /// a negative list is stored as ListMerger cuts it (a volume reaching into an obstacle cut at
  /// its bottom and top, each piece with the mass within its heights), as insertion leaves it.
  void setCellVolumes(const std::vector<CellAssignment>& cells);
  void setCellVolumes(const CellIndex& cell, const CellVolumes& volumes);

  // ---- A map's lifetime: forgetting, a local window, clearing, merging ----------------------

  /// Forgetting (after a decay step): removes every positive volume whose real mass is below
  /// `min_mass`, and every run of touching negative volumes (the pieces of one free volume split
  /// at obstacles, ModelRules::split_free_space_at_obstacles) whose mass together is below it;
  /// their space becomes unknown. Negative pieces that touched at a removed positive volume's
  /// bottom or top are merged again (ListMerger), so every column stays valid. A cell left empty
  /// is removed, a tile left empty freed. `min_mass` 0 forgets nothing; it must be finite and
  /// >= 0 (ConfigError). A tile that nothing could have made lighter since the last call costs
  /// a look at its header: cheap enough for every decay step.
  ForgetResult forget(double min_mass);
  /// Removes the tiles wholly farther than `radius` (m) in xy from `centre` and returns them as a
  /// map of this configuration and mass unit (masses exact), for the caller to save or merge
  /// elsewhere. Throws ConfigError for a non-finite centre or a NaN or negative radius.
  Map dropTilesFartherThan(const Eigen::Vector2d& centre, double radius);
  /// Makes the box [min_corner, max_corner] (m) unknown: in the cells whose squares meet its
  /// footprint ([floor(s min), ceil(s max)) in x and y), volumes are cut at its bottom and top,
  /// the parts outside keeping their mass in proportion to their height (parts lower than 1
  /// go too: Sec. III-A); a column wholly inside is removed. A box one cell high (1 / s) or lower
  /// is cleared a little over one cell high around its centre: a column cannot hold a
  /// gap of 1 or less. Infinite corners are allowed. Returns the number of cells changed.
  /// Throws ConfigError, changing nothing, for a NaN corner or a box empty or inverted on an axis.
  std::size_t clearBox(const Eigen::Vector3d& min_corner, const Eigen::Vector3d& max_corner);
  /// Adds `other` into this map by the constraint application of Sec. III-B.3 (ListMerger, with
  /// this map's rules, as insertion does): every cell of `other`, moved by `this_from_other`,
  /// has its lists merged with this map's, overlapping volumes' masses summed (eq. 7), gaps of
  /// at most 1 closed at density 1 (eq. 8). Masses are brought to this map's unit (exact unless
  /// this map has decayed: then within a float rounding). Throws ConfigError, changing nothing,
  /// if the resolutions differ, if the maps count mass differently (ModelRules::mass_counting:
  /// their masses mean different things), or if a cell would land beyond max_coordinate. Other
  /// rules may differ: this map's rules shape the merged lists. `other` may be this map.
  void merge(const Map& other, const GridTransform& this_from_other = {});
  /// The tiles removed after `revision` (by forget, dropTilesFartherThan, clearBox,
  /// setCellVolumes, a map update) that do not exist now, rows from the lowest; nothing if the map
  /// no longer knows (clear() since, or more removals since than it remembers, a bounded number):
  /// then treat every tile as changed.
  std::optional<std::vector<TileIndex>> tilesRemovedSince(std::uint64_t revision) const;

 private:
  struct Storage;
  friend struct detail::MapUpdateCodec;  // map_update.cpp: tiles as stored, for exact mirrors

  const detail::TileBlock* findTile(std::uint64_t key) const;
  template <class T, class CellValue>
  Grid2D<T> fillGrid(const CellRange& cells, T unobserved, CellValue&& value_of) const;
  /// Real mass of a stored mass of a tile written with mass exponent `tile_exponent`.
  double realMass(std::int32_t tile_exponent, float stored_mass) const;
  /// Scale from a tile's stored masses to the map's current unit (a power of two).
  double rescaleOf(std::int32_t tile_exponent) const;
  std::vector<std::uint64_t> sortedTileKeys() const;
  void recomputeBounds();

  MapConfig config_;
  double scale_inverse_;  // 1 / resolution
  /// Stored masses of a tile are in units of mass_unit_ * 2^(unit_exponent_ - the tile's
  /// exponent) real mass, mass_unit_ in (0.5, 1]. Decay changes these two only (Sec. III-E in
  /// O(1)); a tile takes the map's unit exponent when it is written.
  double mass_unit_ = 1.0;
  std::int64_t unit_exponent_ = 0;
  std::unique_ptr<Storage> storage_;
  std::unique_ptr<ScanUpdate> own_update_;  // insertScan's buffers, kept from scan to scan
  std::uint64_t revision_ = 1;
  CellRange bounds_ = kNoCells;
};

}  // namespace mvog
