#pragma once

#include <cstdint>
#include <string>

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>

#include "mvog/MapStatistics.h"
#include "mvog_ros/inputs/sensor_inputs.h"
#include "mvog_ros/insertion_worker.h"
#include "mvog_ros/mapper_config.h"
#include "mvog_ros/shared_map.h"

namespace mvog_ros {

/// ~statistics (mvog/MapStatistics, latched) every ~statistics_period: the map's size and what
/// the sensor inputs and the insertion worker counted since the start or the last ~reset. The
/// same figures go to /diagnostics (diagnostic_msgs, through diagnostic_updater:
/// rqt_runtime_monitor, rostopic echo /diagnostics) as the status "NODE: mapping", a warning while
/// messages are being dropped.
class StatisticsPublication {
 public:
  StatisticsPublication(ros::NodeHandle& private_nh, const PublicationsConfig& config,
                        const std::string& frame_id, const SharedMap& shared_map,
                        const SensorInputs& inputs, const InsertionWorker& insertion);

 private:
  void publish(const ros::TimerEvent&);
  /// The figures now; readings_per_second since the previous call (the timer's only).
  mvog::MapStatistics statistics();
  /// The status "mapping" from the latest statistics, compared with those before.
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);

  const std::string frame_id_;
  const SharedMap& map_;
  const SensorInputs& inputs_;
  const InsertionWorker& insertion_;

  std::uint64_t readings_at_last_statistics_ = 0;
  ros::WallTime last_statistics_time_ = ros::WallTime::now();
  mvog::MapStatistics latest_;    // the timer's only, as the two below
  mvog::MapStatistics previous_;  // the statistics before latest_
  ros::Publisher publisher_;
  diagnostic_updater::Updater diagnostics_;
  ros::Timer timer_;
};

}  // namespace mvog_ros
