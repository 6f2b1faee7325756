#include "mvog_ros/inputs/point_cloud_input.h"

#include "mvog_ros/conversions.h"

namespace mvog_ros {

PointCloudInput::PointCloudInput(ros::NodeHandle& nh, const std::string& topic,
                                 const SensorInputContext& context)
    : SensorInput(nh, context) {
  subscribe<sensor_msgs::PointCloud2>(nh, topic, this);
}

PointCloudInput::~PointCloudInput() { stop(); }

void PointCloudInput::convertAndEnqueue(const sensor_msgs::PointCloud2& cloud,
                                        const Eigen::Isometry3d& map_from_sensor) {
  enqueueConverted("PointCloud2", [&](std::size_t& skipped) {
    mvog::Scan converted = pointCloudToScan(
        cloud, map_from_sensor, static_cast<std::size_t>(context_.config.max_points_per_message));
    if (context_.config.voxel_filter_size > 0.0) {
      skipped = voxelFilter(converted.hits, context_.config.voxel_filter_size);
    }
    return converted;
  });
}

}  // namespace mvog_ros
