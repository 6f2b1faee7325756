#include "mvog_ros/services/plan_path_service.h"

#include <optional>
#include <shared_mutex>

#include <nav_msgs/Path.h>

#include "mvog_ompl/sphere_planner.h"
#include "mvog_ros/services/query_requests.h"

namespace mvog_ros {

// The response's status is the planner's.
static_assert(mvog::PlanPath::Response::PLANNED ==
              static_cast<std::uint8_t>(mvog_ompl::PlanStatus::kPlanned));
static_assert(mvog::PlanPath::Response::INVALID_REQUEST ==
              static_cast<std::uint8_t>(mvog_ompl::PlanStatus::kInvalidRequest));
static_assert(mvog::PlanPath::Response::START_BLOCKED ==
              static_cast<std::uint8_t>(mvog_ompl::PlanStatus::kStartBlocked));
static_assert(mvog::PlanPath::Response::GOAL_BLOCKED ==
              static_cast<std::uint8_t>(mvog_ompl::PlanStatus::kGoalBlocked));
static_assert(mvog::PlanPath::Response::NO_PATH ==
              static_cast<std::uint8_t>(mvog_ompl::PlanStatus::kNoPath));
static_assert(mvog::PlanPath::Response::PATH_REFUSED ==
              static_cast<std::uint8_t>(mvog_ompl::PlanStatus::kPathRefused));

PlanPathService::PlanPathService(ros::NodeHandle& private_nh, const QueryServicesConfig& config,
                                 const mvog::PlanningConfig& planning, const std::string& frame_id,
                                 const SharedMap& shared_map, const tf2_ros::Buffer& tf_buffer)
    : config_(config),
      planning_(planning),
      frame_id_(frame_id),
      map_(shared_map),
      tf_buffer_(tf_buffer),
      path_publisher_(private_nh.advertise<nav_msgs::Path>("planned_path", 1, true)),
      plan_path_(private_nh.advertiseService("plan_path", &PlanPathService::planPath, this)) {}

void PlanPathService::setPlanning(const mvog::PlanningConfig& planning) {
  std::lock_guard<std::mutex> lock(planning_mutex_);
  planning_ = planning;
}

bool PlanPathService::planPath(mvog::PlanPath::Request& request,
                               mvog::PlanPath::Response& response) {
  response.path.header.frame_id = frame_id_;
  response.status = mvog::PlanPath::Response::INVALID_REQUEST;
  const std::optional<Eigen::Isometry3d> map_from_frame = mapFromQueryFrame(
      tf_buffer_, frame_id_, request.frame_id, config_.tf_timeout, response.message);
  if (!map_from_frame) return true;
  mvog_ompl::PlanRequest plan;
  plan.start = *map_from_frame * toEigen(request.start);
  plan.goal = *map_from_frame * toEigen(request.goal);
  plan.robot = {request.radius, request.allow_unknown != 0};
  plan.time_limit = request.time_limit;
  mvog::PlanningConfig planning;
  {
    std::lock_guard<std::mutex> lock(planning_mutex_);
    planning = planning_;
  }
  mvog_ompl::PlanResult result;
  {
    // The live map, unchanged while the planner looks at it.
    std::shared_lock<WriterPreferringMutex> lock(map_.mutex);
    result = mvog_ompl::planPath(map_.map, plan, planning);
  }
  response.status = static_cast<std::uint8_t>(result.status);
  response.message = result.message;
  response.planning_time = result.seconds;
  if (result.status != mvog_ompl::PlanStatus::kPlanned) return true;
  response.path.header.stamp = ros::Time::now();
  for (const Eigen::Vector3d& waypoint : result.waypoints) {
    geometry_msgs::PoseStamped pose;
    pose.header = response.path.header;
    pose.pose.position.x = waypoint.x();
    pose.pose.position.y = waypoint.y();
    pose.pose.position.z = waypoint.z();
    pose.pose.orientation.w = 1.0;
    response.path.poses.push_back(pose);
  }
  path_publisher_.publish(response.path);
  return true;
}

}  // namespace mvog_ros
