#pragma once

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

  /// Converts `scan` with the sensor's pose and enqueues it; an invalid scan is dropped, counted.
  void convertAndEnqueue(const sensor_msgs::LaserScan& scan,
                         const Eigen::Isometry3d& map_from_sensor);

 private:
  const double max_range_;
};

}  // namespace mvog_ros
