#pragma once

#include <cstdint>
#include <vector>

#include "mvog/map.h"
#include "mvog/planning_config.h"
#include "mvog/tile_changes.h"

namespace mvog {

/// Frontier voxels of one cell: the heights [bottom, top + 1) in grid units (voxel k spans
/// heights [k, k + 1)), both voxels included.
struct FrontierRun {
  CellIndex cell;
  std::int32_t bottom = 0;
  std::int32_t top = 0;
};

/// One frontier voxel: its centre (m, map frame) and the connected piece it belongs to.
struct FrontierPoint {
  float x = 0.0f;
  float y = 0.0f;
  float z = 0.0f;
  std::uint32_t cluster = 0;

  friend bool operator==(const FrontierPoint& a, const FrontierPoint& b) {
    return a.x == b.x && a.y == b.y && a.z == b.z && a.cluster == b.cluster;
  }
};

/// The frontiers of a map: known-free space that touches unknown space, within the band
/// [frontier_min_z, frontier_max_z], in voxels one cell wide and one cell high. A voxel is a
/// frontier where a free interval of its column meets, with a height of positive length within
/// the voxel, unknown space of a column beside it (4-neighbourhood); and where the top (bottom)
/// of a free interval lies in the band with unknown space directly above (below) it: the voxel
/// just below that top (above that bottom). Frontier voxels are clustered into connected pieces
/// (26-neighbourhood); pieces of fewer than frontier_min_cells voxels are dropped.
///
/// Kept tile by tile: an update recomputes the tiles that changed (TileChanges) and their four
/// neighbours, then clusters every frontier voxel again.
class Frontiers {
 public:
  /// Throws ConfigError if `config` is invalid.
  explicit Frontiers(const PlanningConfig& config = {});

  /// Brings the frontiers up to date with `map`.
  void update(const Map& map);
  /// Forgets everything: the next update computes every tile (for a map replaced by another).
  void clear();

  /// The voxels of the pieces kept, by rows of tiles from the lowest, then cells, then heights.
  /// Clusters are numbered from 0 in the order of their first voxel here.
  const std::vector<FrontierPoint>& points() const { return points_; }
  std::uint32_t numClusters() const { return num_clusters_; }
  /// The tiles the last update recomputed.
  std::size_t tilesRecomputed() const { return tiles_recomputed_; }

 private:
  void cluster(double resolution);

  PlanningConfig config_;
  TileResults<FrontierRun> runs_;
  std::vector<FrontierPoint> points_;
  std::uint32_t num_clusters_ = 0;
  std::size_t tiles_recomputed_ = 0;
};

}  // namespace mvog
