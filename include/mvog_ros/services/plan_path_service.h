#pragma once

#include <mutex>
#include <string>

#include <ros/ros.h>
#include <tf2_ros/buffer.h>

#include "mvog/PlanPath.h"
#include "mvog/planning_config.h"
#include "mvog_ros/mapper_config.h"
#include "mvog_ros/shared_map.h"

namespace mvog_ros {

/// ~plan_path (mvog/PlanPath): a path for a sphere, planned in the live map under its read lock
/// (mvog_ompl::planPath: RRT-Connect, every state and motion checked exactly, simplified, every
/// edge checked once more), answered with a status, and published on ~planned_path
/// (nav_msgs/Path, latched) for rviz. Built when OMPL is found.
class PlanPathService {
 public:
  /// `planning`: its occupancy_threshold and max_query_cells.
  PlanPathService(ros::NodeHandle& private_nh, const QueryServicesConfig& config,
                  const mvog::PlanningConfig& planning, const std::string& frame_id,
                  const SharedMap& shared_map, const tf2_ros::Buffer& tf_buffer);

  /// Validated already (a new occupancy threshold): the next request uses it.
  void setPlanning(const mvog::PlanningConfig& planning);

 private:
  bool planPath(mvog::PlanPath::Request& request, mvog::PlanPath::Response& response);

  const QueryServicesConfig config_;
  std::mutex planning_mutex_;
  mvog::PlanningConfig planning_;  // under planning_mutex_
  const std::string frame_id_;
  const SharedMap& map_;
  const tf2_ros::Buffer& tf_buffer_;
  ros::Publisher path_publisher_;
  ros::ServiceServer plan_path_;
};

}  // namespace mvog_ros
