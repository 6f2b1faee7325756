#pragma once

#include <cstddef>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>

#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <Eigen/Geometry>

#include "mvog/CheckBoxes.h"
#include "mvog/CheckSegments.h"
#include "mvog/checks.h"
#include "mvog/planning_config.h"
#include "mvog_ros/mapper_config.h"
#include "mvog_ros/shared_map.h"

namespace mvog_ros {

/// ~check_segments (is every point within a radius of each segment free?) and ~check_boxes (what
/// the map knows of each box), exact against the map's volumes (mvog/checks.h), in any frame.
/// Bounded by ~max_query_points (segments, boxes) and ~max_query_cells (cells in all); a refused
/// request gets success false and a message saying why.
class PlanningServices {
 public:
  /// `planning`: its occupancy_threshold and max_query_cells.
  PlanningServices(ros::NodeHandle& private_nh, const QueryServicesConfig& config,
                   const mvog::PlanningConfig& planning, const std::string& frame_id,
                   const SharedMap& shared_map, const tf2_ros::Buffer& tf_buffer);

  /// Validated already (a new occupancy threshold): the next request uses it.
  void setPlanning(const mvog::PlanningConfig& planning);

 private:
  bool checkSegments(mvog::CheckSegments::Request& request,
                     mvog::CheckSegments::Response& response);
  bool checkBoxes(mvog::CheckBoxes::Request& request, mvog::CheckBoxes::Response& response);
  /// The transform of a request of `count` queries (`what`) whose two lists of points (`lists`)
  /// have `count` and `other_count` entries; nothing, with `refusal` saying why, if it is
  /// refused.
  std::optional<Eigen::Isometry3d> acceptRequest(const std::string& frame_id, std::size_t count,
                                                 std::size_t other_count, const char* what,
                                                 const char* lists, std::string& refusal) const;

  const QueryServicesConfig config_;
  mvog::PlanningConfig planning_;  // under checker_mutex_
  const std::string frame_id_;
  const SharedMap& map_;
  const tf2_ros::Buffer& tf_buffer_;
  // The segment checker keeps what it found of open space from call to call; it is not
  // thread-safe (one call at a time, under checker_mutex_, then the map's lock) and follows one
  // map: it forgets everything when the map was replaced (~load_map, ~reset).
  std::mutex checker_mutex_;
  mvog::SegmentChecker checker_;
  std::uint64_t checker_generation_ = 0;  // SharedMap::generation of the map it follows
  ros::ServiceServer check_segments_;
  ros::ServiceServer check_boxes_;
};

}  // namespace mvog_ros
