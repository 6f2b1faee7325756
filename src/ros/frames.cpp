#include "mvog_ros/frames.h"

#include <tf2_eigen/tf2_eigen.h>

namespace mvog_ros {

/// How often a wait for a transform asks tf again (s of wall time).
constexpr double kTransformPollPeriod = 0.005;

std::string tf2FrameId(const std::string& frame) {
  return !frame.empty() && frame.front() == '/' ? frame.substr(1) : frame;
}

Eigen::Isometry3d latestTransform(const tf2_ros::Buffer& tf_buffer, const std::string& map_frame,
                                  const std::string& frame, double timeout) {
  auto unavailable = [&](const std::string& why) {
    return TransformUnavailable("cannot transform from '" + frame + "' to '" + map_frame +
                                "': " + why);
  };
  const std::string tf2_frame = tf2FrameId(frame);
  // The wait runs on the wall clock, not on tf2's ROS time: replaying a bag with --clock and
  // without --keep-alive, ROS time stops at the bag's end, and a request in a frame tf does not
  // know would wait for ever.
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout);
  for (;;) {
    std::string why;  // tf2 appends to it: one poll's reason
    if (tf_buffer.canTransform(map_frame, tf2_frame, ros::Time(0), &why)) break;
    if (ros::WallTime::now() >= deadline || !ros::ok()) throw unavailable(why);
    ros::WallDuration(kTransformPollPeriod).sleep();
  }
  try {
    return tf2::transformToEigen(tf_buffer.lookupTransform(map_frame, tf2_frame, ros::Time(0)));
  } catch (const tf2::TransformException& e) {  // gone from the buffer since canTransform
    throw unavailable(e.what());
  }
}

}  // namespace mvog_ros
