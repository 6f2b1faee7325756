#include "mvog_ros/frames.h"

#include <tf2_eigen/tf2_eigen.h>

namespace mvog_ros {

Eigen::Isometry3d latestTransform(const tf2_ros::Buffer& tf_buffer, const std::string& map_frame,
                                  const std::string& frame, double timeout) {
  try {
    return tf2::transformToEigen(
        tf_buffer.lookupTransform(map_frame, frame, ros::Time(0), ros::Duration(timeout)));
  } catch (const tf2::TransformException& e) {
    throw TransformUnavailable("cannot transform from '" + frame + "' to '" + map_frame +
                               "': " + e.what());
  }
}

}  // namespace mvog_ros
