#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <unordered_map>
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
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  /// Obstacle readings: the points where a ray hit something.
  std::vector<Eigen::Vector3f> hits;
  /// Out-of-range readings (ReadingKind::kOutOfRange): where the free space seen along a ray
  /// ends, with no obstacle there.
  std::vector<Eigen::Vector3f> out_of_range;
};

/// Splits `scan` into consecutive pieces of at most `max_readings` readings each (its hits, then
/// its free endpoints, in order), all from its origin. Inserting the pieces in order builds the
/// same map as inserting `scan`, since the readings go in in the same order; not so with
/// InsertionConfig::clear_conflicting_free_space, whose conflicts are those within one scan.
/// A server inserts a large cloud piece by piece so that queries get the map in between.
/// An empty scan has no piece. Throws ConfigError if `max_readings` is 0.
std::vector<Scan> splitScan(const Scan& scan, std::size_t max_readings);

/// What happened to the readings given to an insertion. Every reading is counted exactly once.
struct InsertionResult {
  std::size_t obstacle_readings = 0;       ///< inserted with a positive volume
  std::size_t out_of_range_readings = 0;   ///< inserted as free space only (incl. truncated hits)
  std::size_t truncated_to_max_range = 0;  ///< hits beyond max_range, among out_of_range_readings
  std::size_t rejected_non_finite = 0;     ///< NaN or infinite coordinates
  std::size_t rejected_out_of_bounds = 0;  ///< beyond MapConfig::max_coordinate
  std::size_t rejected_too_close = 0;      ///< hits nearer than min_range
  std::size_t ignored_out_of_range = 0;    ///< out-of-range readings with insert_out_of_range off

  std::size_t inserted() const { return obstacle_readings + out_of_range_readings; }
  std::size_t rejected() const {
    return rejected_non_finite + rejected_out_of_bounds + rejected_too_close + ignored_out_of_range;
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

/// Memory held by the map.
struct MemoryUsage {
  /// Bytes the map holds: its tiles, the index of tiles and every cell's volume storage with
  /// its spare capacity (allocator bookkeeping not included).
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

  // ---- Insertion (Sec. III-B) ------------------------------------------------------------

  /// Inserts one reading ending at `end`: an obstacle reading, or an out-of-range reading.
  InsertionResult insertReading(const Eigen::Vector3d& origin, const Eigen::Vector3d& end,
                                ReadingKind kind, const InsertionConfig& config = {});
  /// Inserts a whole scan: the same map as inserting its hits, then its free endpoints, one by
  /// one in order (unless config.clear_conflicting_free_space), with any number of threads.
  InsertionResult insertScan(const Scan& scan, const InsertionConfig& config = {});

  // ---- Queries (Sec. III-C) ---------------------------------------------------------------

  /// Densities and probability at a world point (m). NaN or infinite coordinates: unknown.
  PointOccupancy occupancy(const Eigen::Vector3d& point) const;
  /// The volume lists of one cell (empty lists for a cell never observed).
  CellVolumes cellVolumes(const CellIndex& cell) const;
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

  /// Calls visit(CellIndex, VolumeSign, const Volume&) for every volume (masses as of now).
  void forEachVolume(
      const std::function<void(const CellIndex&, VolumeSign, const Volume&)>& visit) const;
  /// Same, restricted to the cells of `cells`.
  void forEachVolumeIn(
      const CellRange& cells,
      const std::function<void(const CellIndex&, VolumeSign, const Volume&)>& visit) const;

  // ---- Decay (Sec. III-E) -----------------------------------------------------------------

  /// Multiplies every mass by k_d in (0, 1], in O(1): masses are stored in a unit that a single
  /// factor converts, so no cell is touched. A cell's stored masses are rescaled, exactly by a
  /// power of two, only when the cell next receives a volume. Hence the probabilities of a cell
  /// that receives no new reading stay bit for bit the same after any number of steps; in a
  /// cell that does, masses decayed below float range relative to the new ones become 0. Masses
  /// and densities read back (cellVolumes, occupancy) underflow to 0 after extreme decay.
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

  // ---- Direct access for serialisation ------------------------------------------------------

  /// Replaces a cell's lists (masses as cellVolumes returns them). Throws ConfigError unless both
  /// lists satisfy the Sec. III-A constraints (sorted, heights >= 1, gaps > 1, finite
  /// non-negative masses, representable in the map's decayed mass unit) and the cell lies within
  /// max_coordinate (|i|, |j| <= max_coordinate / resolution + 1, the cells readings can reach).
  /// Emptying a cell removes it from bounds().
  void setCellVolumes(const CellIndex& cell, const CellVolumes& volumes);

 private:
  struct Tile;
  class Cell;
  class TileWriter;
  friend struct MapFileAccess;

  const Cell* findCell(const CellIndex& cell) const;
  const Tile* findTile(const TileIndex& index) const;
  std::vector<std::uint64_t> sortedTileKeys() const;
  bool acceptReading(const Eigen::Vector3d& origin, const Eigen::Vector3d& end, ReadingKind kind,
                     const InsertionConfig& config, Eigen::Vector3d& ray_end, bool& obstacle,
                     InsertionResult& result) const;
  template <class T, class CellValue>
  Grid2D<T> fillGrid(const CellRange& cells, T unobserved, CellValue&& value_of) const;
  double realMass(const Cell& cell, float stored_mass) const;
  void growBounds(const CellRange& cells);
  void recomputeBounds();

  MapConfig config_;
  double scale_inverse_;  // 1 / resolution
  /// Stored masses of a cell are in units of mass_unit_ * 2^(unit_exponent_ - the cell's
  /// exponent) real mass, mass_unit_ in (0.5, 1]. Decay changes these two only (Sec. III-E in
  /// O(1)); a cell takes the map's unit exponent when it is written.
  double mass_unit_ = 1.0;
  std::int64_t unit_exponent_ = 0;
  std::unordered_map<std::uint64_t, std::unique_ptr<Tile>> tiles_;
  std::uint64_t revision_ = 1;
  CellRange bounds_{{0, 0}, {-1, -1}};
  std::size_t bytes_in_cells_ = 0;
};

}  // namespace mvog
