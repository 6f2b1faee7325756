#include "mvog_ros/publications/statistics_publication.h"

#include <shared_mutex>

namespace mvog_ros {

StatisticsPublication::StatisticsPublication(
    ros::NodeHandle& private_nh, const PublicationsConfig& config, const std::string& frame_id,
    const SharedMap& shared_map, const SensorInputs& inputs, const InsertionWorker& insertion)
    : frame_id_(frame_id),
      map_(shared_map),
      inputs_(inputs),
      insertion_(insertion),
      publisher_(private_nh.advertise<mvog::MapStatistics>("statistics", 1, true)),
      diagnostics_(private_nh, private_nh, private_nh.getNamespace()) {
  diagnostics_.setHardwareID("none");  // software, no device
  diagnostics_.add("mapping", this, &StatisticsPublication::diagnose);
  timer_ = private_nh.createTimer(ros::Duration(config.statistics_period),
                                  &StatisticsPublication::publish, this);
}

void StatisticsPublication::publish(const ros::TimerEvent&) {
  previous_ = latest_;
  latest_ = statistics();
  publisher_.publish(latest_);
  diagnostics_.force_update();  // every ~statistics_period, whatever ~diagnostic_period says
}

void StatisticsPublication::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  const mvog::MapStatistics& s = latest_;
  // Counts restart at a reset: then everything counted since is new.
  auto since_previous = [](std::uint64_t now, std::uint64_t before) {
    return now >= before ? now - before : now;
  };
  const std::uint64_t dropped_tf =
      since_previous(s.messages_dropped_tf, previous_.messages_dropped_tf);
  const std::uint64_t dropped_queue =
      since_previous(s.messages_dropped_queue, previous_.messages_dropped_queue);
  const std::uint64_t dropped_invalid =
      since_previous(s.messages_dropped_invalid, previous_.messages_dropped_invalid);
  const std::uint64_t dropped_camera_info =
      since_previous(s.messages_dropped_camera_info, previous_.messages_dropped_camera_info);
  if (dropped_tf + dropped_queue + dropped_invalid + dropped_camera_info > 0) {
    status.summaryf(diagnostic_msgs::DiagnosticStatus::WARN,
                    "dropping messages: %llu without transform, %llu for a full insertion queue, "
                    "%llu invalid, %llu without camera info since the last report",
                    static_cast<unsigned long long>(dropped_tf),
                    static_cast<unsigned long long>(dropped_queue),
                    static_cast<unsigned long long>(dropped_invalid),
                    static_cast<unsigned long long>(dropped_camera_info));
  } else {
    status.summaryf(diagnostic_msgs::DiagnosticStatus::OK, "%llu messages inserted",
                    static_cast<unsigned long long>(s.messages_inserted));
  }
  // The fields of ~statistics, under their names there.
  status.add("frame_id", s.header.frame_id);
  status.add("resolution", s.resolution);
  status.add("cells_with_volumes", s.cells_with_volumes);
  status.add("positive_volumes", s.positive_volumes);
  status.add("negative_volumes", s.negative_volumes);
  status.add("minimal_grid_cells", s.minimal_grid_cells);
  status.add("bytes_held", s.bytes_held);
  status.add("table_one_bytes", s.table_one_bytes);
  status.add("readings_inserted", s.readings_inserted);
  status.add("rays_walked", s.rays_walked);
  status.add("readings_rejected", s.readings_rejected);
  status.add("readings_per_second", s.readings_per_second);
  status.add("insertion_seconds", s.insertion_seconds);
  status.add("out_of_range_readings", s.out_of_range_readings);
  status.add("out_of_range_time_share", s.out_of_range_time_share);
  status.add("messages_inserted", s.messages_inserted);
  status.add("backlog_insertions", s.backlog_insertions);
  status.add("messages_dropped_tf", s.messages_dropped_tf);
  status.add("messages_dropped_queue", s.messages_dropped_queue);
  status.add("messages_dropped_invalid", s.messages_dropped_invalid);
  status.add("messages_dropped_camera_info", s.messages_dropped_camera_info);
}

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
  statistics.rays_walked = insertion.rays_walked;
  const double elapsed = (now - last_statistics_time_).toSec();
  if (elapsed > 0.0 && statistics.readings_inserted >= readings_at_last_statistics_) {
    statistics.readings_per_second =
        static_cast<double>(statistics.readings_inserted - readings_at_last_statistics_) / elapsed;
  }
  readings_at_last_statistics_ = statistics.readings_inserted;
  last_statistics_time_ = now;
  statistics.readings_rejected = inputs.readings_rejected + insertion.readings_rejected;
  statistics.insertion_seconds = insertion.insertion_seconds;
  statistics.out_of_range_readings = insertion.out_of_range_readings;
  const double rasterising = insertion.obstacle_seconds + insertion.out_of_range_seconds;
  statistics.out_of_range_time_share =
      rasterising > 0.0 ? insertion.out_of_range_seconds / rasterising : 0.0;
  statistics.messages_inserted = insertion.messages_inserted;
  statistics.backlog_insertions = insertion.backlog_insertions;
  statistics.messages_dropped_tf = inputs.messages_dropped_tf;
  statistics.messages_dropped_queue = insertion.messages_dropped_queue;
  statistics.messages_dropped_invalid = inputs.messages_dropped_invalid;
  statistics.messages_dropped_camera_info = inputs.messages_dropped_camera_info;
  statistics.header.frame_id = frame_id_;
  statistics.header.stamp = ros::Time::now();
  return statistics;
}

}  // namespace mvog_ros
