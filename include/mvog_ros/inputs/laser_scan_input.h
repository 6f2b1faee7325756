#pragma once

#include <atomic>
#include <string>

#include <sensor_msgs/LaserScan.h>

#include "mvog_ros/inputs/sensor_input.h"

namespace mvog_ros {

/// A LaserScan topic, its scans converted by laserScanToScan (REP-117): out-of-range beams are
/// free space up to min(range_max, ~max_range), beams that say nothing are counted as rejected
/// readings.
class LaserScanInput : public SensorInput {
 public:
  LaserScanInput(ros::NodeHandle& nh, const std::string& topic, const SensorInputContext& context,
                 double max_range);
  ~LaserScanInput() override;

  /// ~max_range changed (RuntimeReconfigure): the next scan converted uses it.
  void setMaxRange(double max_range) { max_range_ = max_range; }

  /// Converts `scan` with the sensor's pose and enqueues it; an invalid scan is dropped, counted.
  void convertAndEnqueue(const sensor_msgs::LaserScan& scan,
                         const Eigen::Isometry3d& map_from_sensor);

 private:
  std::atomic<double> max_range_;  // read once per scan
};

}  // namespace mvog_ros
