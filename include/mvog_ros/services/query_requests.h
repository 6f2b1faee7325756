#pragma once

#include <cstddef>
#include <optional>
#include <string>

#include <geometry_msgs/Point.h>
#include <tf2_ros/buffer.h>
#include <Eigen/Geometry>

namespace mvog_ros {

// What the services that take points (QueryServices, PlanningServices, MapEditServices) share.

/// A point of a request, as the core takes it.
inline Eigen::Vector3d toEigen(const geometry_msgs::Point& point) {
  return {point.x, point.y, point.z};
}

/// Whether a request of `count` points (segments, boxes: `what`) is within ~max_query_points;
/// if not, `refusal` says so.
bool withinMaxQueryPoints(std::size_t count, const char* what, int max_query_points,
                          std::string& refusal);

/// The transform taking points of a request's `frame_id` into the map frame `map_frame`, at the
/// latest time tf has (waiting up to `timeout` s): the identity for an empty frame_id or the map
/// frame itself. Nothing if tf cannot tell, with `refusal` saying why.
std::optional<Eigen::Isometry3d> mapFromQueryFrame(const tf2_ros::Buffer& tf_buffer,
                                                   const std::string& map_frame,
                                                   const std::string& frame_id, double timeout,
                                                   std::string& refusal);

}  // namespace mvog_ros
