#pragma once

#include <memory>
#include <string>
#include <vector>

#include "mvog_ros/inputs/sensor_input.h"

namespace mvog_ros {

class LaserScanInput;
class DepthImageInput;

/// The server's sensor inputs: a LaserScanInput for `scan` and each of ~scan_topics, a
/// PointCloudInput for `cloud_in` and each of ~cloud_topics, a DepthImageInput for each of
/// ~depth_topics (topics relative to `nh`), and the counts of what they dropped.
class SensorInputs {
 public:
  /// `max_range`: ~max_range, where LaserScan out-of-range readings end at the latest;
  /// `depth_no_return_length`: where those of depth images end (DepthImageConfig).
  SensorInputs(ros::NodeHandle nh, const SensorInputsConfig& config, const std::string& frame_id,
               double max_range, double depth_no_return_length, const tf2_ros::Buffer& tf_buffer,
               EnqueueReadings enqueue);

  /// ~max_range changed (RuntimeReconfigure): as the constructor's arguments, for the next
  /// message each input converts.
  void setMaxRange(double max_range, double depth_no_return_length);
  /// Every input stops taking messages (SensorInput::stop).
  void stop();

  InputStatistics statistics() const { return counters_.statistics(); }
  void resetStatistics() { counters_.reset(); }

 private:
  InputCounters counters_;
  std::vector<std::unique_ptr<SensorInput>> inputs_;
  // Those of inputs_ that convert with ~max_range.
  std::vector<LaserScanInput*> scan_inputs_;
  std::vector<DepthImageInput*> depth_inputs_;
};

}  // namespace mvog_ros
