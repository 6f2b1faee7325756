#pragma once

#include <string>

#include <sensor_msgs/PointCloud2.h>

#include "mvog_ros/inputs/sensor_input.h"

namespace mvog_ros {

/// A PointCloud2 topic, its clouds of any layout converted by pointCloudToScan, and thinned by
/// PCL's voxel filter when ~voxel_filter_size is set.
class PointCloudInput : public SensorInput {
 public:
  PointCloudInput(ros::NodeHandle& nh, const std::string& topic, const SensorInputContext& context);
  ~PointCloudInput() override;

  /// Converts `cloud` with the sensor's pose and enqueues it; an invalid cloud is dropped,
  /// counted.
  void convertAndEnqueue(const sensor_msgs::PointCloud2& cloud,
                         const Eigen::Isometry3d& map_from_sensor);
};

}  // namespace mvog_ros
