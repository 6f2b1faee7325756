#pragma once

#include <limits>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "mvog/grid2d.h"
#include "mvog/map.h"
#include "mvog/planning_config.h"

namespace mvog {

/// A straight segment between two points (m, map frame).
struct Segment {
  Eigen::Vector3d start = Eigen::Vector3d::Zero();
  Eigen::Vector3d end = Eigen::Vector3d::Zero();
};

/// What a segment check found about the points within a radius of a segment.
struct SegmentCheck {
  /// kOccupied if some point is occupied (p > occupancy_threshold), kFree if every point is known
  /// and free, else kUnknown.
  OccupancyState state = OccupancyState::kUnknown;
  /// Distance (m) from the start along the segment to the first point that is occupied or
  /// unknown (radius 0), or at which the sphere of the radius swept along the segment first meets
  /// such a point (radius > 0); NaN where kFree.
  double blocked_at = std::numeric_limits<double>::quiet_NaN();
};

/// An axis-aligned box (m, map frame), corners included.
struct Box {
  Eigen::Vector3d min = Eigen::Vector3d::Zero();
  Eigen::Vector3d max = Eigen::Vector3d::Zero();
};

/// What a box check found about the points of a box.
struct BoxCheck {
  /// As SegmentCheck::state, over the box's points.
  OccupancyState state = OccupancyState::kUnknown;
  /// The share of the box's volume that some volume of the map covers (NaN for a flat box).
  double known_fraction = 0.0;
  /// The highest p in the box, NaN if nothing in it is known.
  double max_probability = std::numeric_limits<double>::quiet_NaN();
};

/// Checks segments against the map's volumes exactly, not by sampling points. Radius 0: in each
/// cell that the segment's xy-projection crosses (walkRay), the column's stretches of one state
/// are intersected with the heights the segment spans there. Radius > 0 (m): in each cell that a
/// point within the radius may lie over, each occupied or unknown stretch of the column within
/// the heights the sphere spans near it is the box it fills over the cell, and where the sphere
/// swept along the segment first meets that box is solved exactly (touching a face counts).
/// Decision where the paper is silent: a height where two known stretches of different states
/// meet counts as both (eq. 9 at that one height comes from one of the two touching volumes), so
/// a segment grazing an obstacle's face is occupied.
///
/// Throws ConfigError, naming the field, if `config` or `radius` is invalid (a radius must be
/// finite, >= 0 and at most the map's max_coordinate), if a segment has a
/// point that is not finite or lies beyond the map's max_coordinate, or if the segments cover more
/// than config.max_query_cells cells in all (then before any work).
std::vector<SegmentCheck> checkSegments(const Map& map, const std::vector<Segment>& segments,
                                        double radius, const PlanningConfig& config = {});

namespace detail {
class BlockSummaries;
}

/// Checks segments as checkSegments does, keeping from call to call what it found about blocks of
/// 4 x 4 cells (the heights at which all are known free, those at which some is occupied),
/// forgotten for the tiles that change: repeated checks on a map pass open and unknown space
/// without looking at each of its columns.
/// Not thread-safe: one call at a time. After the map is replaced by another one (loaded, reset),
/// call clear(): revisions of two maps say nothing about each other.
class SegmentChecker {
 public:
  /// Throws ConfigError if `config` is invalid.
  explicit SegmentChecker(const PlanningConfig& config = {});
  ~SegmentChecker();
  SegmentChecker(SegmentChecker&&) noexcept;
  SegmentChecker& operator=(SegmentChecker&&) noexcept;

  /// See checkSegments.
  std::vector<SegmentCheck> check(const Map& map, const std::vector<Segment>& segments,
                                  double radius);
  void clear();

 private:
  PlanningConfig config_;
  std::unique_ptr<detail::BlockSummaries> blocks_;
};

/// Checks axis-aligned boxes against the map's volumes exactly: each cell the box lies over,
/// weighted by the area the box covers of it, with the column's lists over the box's heights.
/// Throws ConfigError, naming the field, if `config` is invalid, if a box has a corner that is not
/// finite or lies beyond max_coordinate, or min above max along an axis, or if the boxes lie over
/// more than config.max_query_cells cells in all.
std::vector<BoxCheck> checkBoxes(const Map& map, const std::vector<Box>& boxes,
                                 const PlanningConfig& config = {});

}  // namespace mvog
