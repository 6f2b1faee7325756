#include "mvog_ros/publications/statistics_publication.h"

#include <shared_mutex>

namespace mvog_ros {

StatisticsPublication::StatisticsPublication(
    ros::NodeHandle& private_nh, const PublicationsConfig& config, const std::string& frame_id,
    const SharedMap& shared_map, const SensorInputs& inputs, const InsertionWorker& insertion)
    : frame_id_(frame_id), map_(shared_map), inputs_(inputs), insertion_(insertion) {
  publisher_ = private_nh.advertise<mvog::MapStatistics>("statistics", 1, true);
  timer_ = private_nh.createTimer(ros::Duration(config.statistics_period),
                                  &StatisticsPublication::publish, this);
}

void StatisticsPublication::publish(const ros::TimerEvent&) { publisher_.publish(statistics()); }

mvog::MapStatistics StatisticsPublication::statistics() {
  mvog::MapStatistics statistics;
  {
    std::shared_lock<WriterPreferringMutex> lock(map_.mutex);
    const mvog::MemoryUsage memory = map_.map.memoryUsage();
    statistics.resolution = map_.map.resolution();
    statistics.cells_with_volumes = memory.cells_with_volumes;
    statistics.positive_volumes = memory.positive_volumes;
    statistics.negative_volumes = memory.negative_volumes;
    statistics.minimal_grid_cells = memory.minimal_grid_cells;
    statistics.bytes_held = memory.bytes_held;
    statistics.table_one_bytes = memory.table_one_bytes;
  }
  const InputStatistics inputs = inputs_.statistics();
  const InsertionStatistics insertion = insertion_.statistics();
  const ros::WallTime now = ros::WallTime::now();
  statistics.readings_inserted = insertion.readings_inserted;
  const double elapsed = (now - last_statistics_time_).toSec();
  if (elapsed > 0.0 && statistics.readings_inserted >= readings_at_last_statistics_) {
    statistics.readings_per_second =
        static_cast<double>(statistics.readings_inserted - readings_at_last_statistics_) / elapsed;
  }
  readings_at_last_statistics_ = statistics.readings_inserted;
  last_statistics_time_ = now;
  statistics.readings_rejected = inputs.readings_rejected + insertion.readings_rejected;
  statistics.insertion_seconds = insertion.insertion_seconds;
  statistics.messages_inserted = insertion.messages_inserted;
  statistics.messages_dropped_tf = inputs.messages_dropped_tf;
  statistics.messages_dropped_queue = insertion.messages_dropped_queue;
  statistics.messages_dropped_invalid = inputs.messages_dropped_invalid;
  statistics.header.frame_id = frame_id_;
  statistics.header.stamp = ros::Time::now();
  return statistics;
}

}  // namespace mvog_ros
