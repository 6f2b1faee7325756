#pragma once

#include <stdexcept>
#include <string>

#include <tf2_ros/buffer.h>
#include <Eigen/Geometry>

namespace mvog_ros {

/// A transform that a request or a part of the server needs and tf does not have.
class TransformUnavailable : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// `frame` as tf2 names frames: a tf1-style leading '/' dropped (tf2 refuses such names).
std::string tf2FrameId(const std::string& frame);

/// The latest transform from `frame` into `map_frame`, waiting up to `timeout` s of wall time for
/// it (ROS time may stand still: a replayed bag over). Throws
/// TransformUnavailable: "cannot transform from 'FRAME' to 'MAP_FRAME': why".
Eigen::Isometry3d latestTransform(const tf2_ros::Buffer& tf_buffer, const std::string& map_frame,
                                  const std::string& frame, double timeout);

}  // namespace mvog_ros
