#pragma once

#include <cstdint>
#include <vector>

#include "mvog/grid2d.h"
#include "mvog/map.h"
#include "mvog/planning_config.h"
#include "mvog/tile_changes.h"

namespace mvog {

/// A top of occupied space in a column: a multi-level surface map holds every one of them (a
/// floor under a table gives two surfaces: the floor and the table top).
struct Surface {
  float x = 0.0f;  ///< the cell's centre (m)
  float y = 0.0f;
  float z = 0.0f;  ///< the height of the top (m)
  /// The height (m) of the known-free space right above the top, up to the next occupied or
  /// unknown space (0 where unknown space lies right above).
  float clearance = 0.0f;
  /// Whether occupied space ends the clearance (else unknown space does).
  bool capped = false;
  float probability = 0.0f;  ///< eq. (9) just below the top

  friend bool operator==(const Surface& a, const Surface& b) {
    return a.x == b.x && a.y == b.y && a.z == b.z && a.clearance == b.clearance &&
           a.capped == b.capped && a.probability == b.probability;
  }
};

/// The surfaces of every column of a map, kept tile by tile: an update recomputes only the tiles
/// that changed (TileChanges).
class Surfaces {
 public:
  /// Throws ConfigError if `config` is invalid (occupancy_threshold is the one used).
  explicit Surfaces(const PlanningConfig& config = {});

  /// Brings the surfaces up to date with `map`.
  void update(const Map& map);
  /// Forgets everything: the next update computes every tile (for a map replaced by another).
  void clear();

  /// By rows of tiles from the lowest, then cells, then heights from the lowest.
  const std::vector<Surface>& surfaces() const { return surfaces_; }
  /// The tiles the last update recomputed.
  std::size_t tilesRecomputed() const { return tiles_recomputed_; }

 private:
  PlanningConfig config_;
  TileResults<Surface> by_tile_;
  std::vector<Surface> surfaces_;
  std::size_t tiles_recomputed_ = 0;
};

/// Where a ground robot can go, as nav_msgs/OccupancyGrid values.
enum class Traversability : std::int8_t {
  kUnknown = -1,
  kTraversable = 0,
  kBlocked = 100,
};
using TraversableMap = Grid2D<Traversability>;

/// The map of a ground robot of height robot_height that climbs steps up to max_step, over
/// `cells`, from the surfaces whose tops lie within [traversable_min_z, traversable_max_z]:
///  - kTraversable where a surface has a clearance of at least robot_height and every one of the
///    four neighbouring cells that holds a surface in the band holds one within max_step of it;
///  - kBlocked where the robot cannot stand or pass although the map knows enough: such a
///    surface fails the step, or a surface's clearance below robot_height ends at occupied space,
///    or no surface lies in the band and the band is occupied somewhere (a wall) or known free
///    throughout (a drop);
///  - kUnknown elsewhere (nothing known, or a clearance ended by unknown space).
/// A cell's value depends on its four neighbours: after a change of a tile, the tile and its
/// neighbours (withNeighbourTiles) are those to compute again. Throws ConfigError if `config` is
/// invalid, or `cells` is empty or holds more than 2^28 cells.
TraversableMap traversableMap(const Map& map, const CellRange& cells,
                              const PlanningConfig& config = {});

}  // namespace mvog
