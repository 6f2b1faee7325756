#pragma once

#include <cstdint>
#include <limits>

#include "mvog/config.h"

namespace mvog {

/// What planners and explorers ask the map (mvog/checks.h, mvog/frontiers.h, mvog/surfaces.h):
/// one set of parameters, named as the server's. Heights in metres, map frame.
struct PlanningConfig {
  /// Occupied where eq. (9) gives p above it (Sec. III-C). In [0, 1).
  double occupancy_threshold = kDefaultOccupancyThreshold;
  /// Segment and box checks: the most cells one call may visit, over all its segments or boxes
  /// (the cells a segment's swept sphere covers, counted by rows of its footprint). A larger call
  /// is refused before any work. 10,000 segments of 5 m with a radius of 0.3 m at 0.05 m visit
  /// some 10 million. At least 1.
  std::int64_t max_query_cells = 50000000;

  /// Frontiers: the band of heights searched, bounds included (min <= max, not NaN, infinite
  /// bounds allowed).
  double frontier_min_z = -std::numeric_limits<double>::infinity();
  double frontier_max_z = std::numeric_limits<double>::infinity();
  /// Frontiers: connected pieces of fewer frontier voxels (cells one cell high) are dropped. At
  /// least 1.
  int frontier_min_cells = 10;

  /// Traversable map: the height of the robot (m): the free space it needs above a surface.
  /// Finite, > 0.
  double robot_height = 0.5;
  /// Traversable map: the largest step (m) between the surfaces of neighbouring cells it passes.
  /// Finite, >= 0.
  double max_step = 0.1;
  /// Traversable map: the band of heights (m) where the ground it drives on may lie (by default
  /// around z = 0, the ground of a map frame by REP-105); bounds included, min <= max, not NaN.
  double traversable_min_z = -0.5;
  double traversable_max_z = 0.5;

  /// Throws ConfigError naming the first invalid field.
  void validate() const;
};

}  // namespace mvog
