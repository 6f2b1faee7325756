#include "mvog_ros/inputs/laser_scan_input.h"

#include "mvog_ros/conversions.h"

namespace mvog_ros {

LaserScanInput::LaserScanInput(ros::NodeHandle& nh, const std::string& topic,
                               const SensorInputContext& context, double max_range)
    : SensorInput(nh, context), max_range_(max_range) {
  subscribe<sensor_msgs::LaserScan>(nh, topic, this);
}

LaserScanInput::~LaserScanInput() { stop(); }

void LaserScanInput::convertAndEnqueue(const sensor_msgs::LaserScan& scan,
                                       const Eigen::Isometry3d& map_from_sensor) {
  enqueueConverted("LaserScan", [&](std::size_t& skipped) {
    return laserScanToScan(scan, map_from_sensor, max_range_.load(),
                           static_cast<std::size_t>(context_.config.max_points_per_message),
                           skipped);
  });
}

}  // namespace mvog_ros
