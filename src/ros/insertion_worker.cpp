#include "mvog_ros/insertion_worker.h"

#include <algorithm>
#include <chrono>
#include <mutex>
#include <shared_mutex>
#include <utility>

#include <ros/console.h>

namespace mvog_ros {
namespace {

/// The fewest readings for which a scan goes in on ~backlog_insertion_threads: a smaller one (a
/// 2D laser's few hundred) is inserted in well under a millisecond, about what handing its parts
/// to other threads and waiting for them costs, and a bag replayed fast sends many such scans.
constexpr std::size_t kMinReadingsForBacklogThreads = 10000;

}  // namespace

InsertionWorker::InsertionWorker(const InsertionWorkerConfig& config, SharedMap& shared_map)
    : config_(config),
      reconfigured_(config),
      map_(shared_map),
      thread_(&InsertionWorker::run, this) {}

void InsertionWorker::reconfigure(const mvog::InsertionConfig& insertion) {
  std::lock_guard<std::mutex> lock(reconfigured_mutex_);
  reconfigured_ = insertion;
}

InsertionWorker::~InsertionWorker() { stop(); }

void InsertionWorker::enqueue(SensorReadings&& readings, const std::string& source) {
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    if (queue_.size() >= static_cast<std::size_t>(config_.insertion_queue_size)) {
      queue_.pop_front();  // keep the newest: the oldest view is the least useful
      ++messages_dropped_queue_;
      ROS_WARN_THROTTLE(kWarningPeriod,
                        "mvog: insertion is slower than the sensors; dropped the oldest waiting "
                        "message (%llu so far)",
                        static_cast<unsigned long long>(messages_dropped_queue_.load()));
    }
    queue_.push_back({std::move(readings), source});
  }
  queue_changed_.notify_one();
}

void InsertionWorker::stop() {
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    stopping_ = true;
  }
  queue_changed_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void InsertionWorker::run() {
  for (;;) {
    QueuedReadings queued;
    bool backlog = false;  // another message waits behind this one, and it is large
    {
      std::unique_lock<std::mutex> lock(queue_mutex_);
      queue_changed_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
      if (queue_.empty()) return;  // stopping, and what was queued is in the map
      queued = std::move(queue_.front());
      queue_.pop_front();
      backlog = !queue_.empty() && readingCount(queued.readings) >= kMinReadingsForBacklogThreads;
    }
    const auto start = std::chrono::steady_clock::now();
    const mvog::InsertionResult result = insert(queued.readings, backlog);
    insertion_nanoseconds_ +=
        static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                       std::chrono::steady_clock::now() - start)
                                       .count());
    readings_inserted_ += result.inserted();
    rays_walked_ += result.rays_walked;
    readings_rejected_ += result.rejected();
    out_of_range_readings_ += result.out_of_range_readings;
    obstacle_nanoseconds_ += static_cast<std::uint64_t>(1e9 * result.obstacle_seconds);
    out_of_range_nanoseconds_ += static_cast<std::uint64_t>(1e9 * result.out_of_range_seconds);
    ++messages_inserted_;
    if (backlog) ++backlog_insertions_;
    {
      std::lock_guard<std::mutex> lock(origin_mutex_);
      latest_origin_ = sensorOrigin(queued.readings);
    }
    if (result.rejected_out_of_bounds > 0) {
      ROS_WARN_THROTTLE(kWarningPeriod,
                        "mvog: %zu readings of a %s lie beyond ~max_coordinate and were rejected",
                        result.rejected_out_of_bounds, queued.source.c_str());
    }
  }
}

mvog::InsertionResult InsertionWorker::insert(const SensorReadings& readings, bool backlog) {
  // The scan goes in whole (Fig. 2: the constraints once per scan). Its rasterisation reads
  // nothing of the map but its configuration: it runs outside the lock, which queries and
  // publications then wait for only while the scan's columns are merged.
  mvog::InsertionConfig insertion = config_;
  {
    std::lock_guard<std::mutex> lock(reconfigured_mutex_);
    insertion.min_range = reconfigured_.min_range;
    insertion.max_range = reconfigured_.max_range;
    insertion.evidence_limit = reconfigured_.evidence_limit;
  }
  if (backlog) {
    insertion.insertion_threads =
        std::max(insertion.insertion_threads, config_.backlog_insertion_threads);
  }
  mvog::MapConfig map_config;
  {
    std::shared_lock<WriterPreferringMutex> lock(map_.mutex);
    map_config = map_.map.config();
  }
  auto prepare = [&](const mvog::MapConfig& config) {
    if (const auto* depth = std::get_if<DepthImageReadings>(&readings)) {
      update_.prepare(depth->frame, config, insertion);
    } else {
      update_.prepare(std::get<mvog::Scan>(readings), config, insertion);
    }
  };
  prepare(map_config);
  std::unique_lock<WriterPreferringMutex> lock(map_.mutex);
  if (!update_.preparedFor(map_.map.config())) {
    // ~load_map put a map of another configuration in place meanwhile.
    prepare(map_.map.config());
  }
  return map_.map.apply(update_);
}

InsertionStatistics InsertionWorker::statistics() const {
  InsertionStatistics statistics;
  statistics.messages_inserted = messages_inserted_.load();
  statistics.backlog_insertions = backlog_insertions_.load();
  statistics.messages_dropped_queue = messages_dropped_queue_.load();
  statistics.readings_inserted = readings_inserted_.load();
  statistics.rays_walked = rays_walked_.load();
  statistics.readings_rejected = readings_rejected_.load();
  statistics.insertion_seconds = 1e-9 * static_cast<double>(insertion_nanoseconds_.load());
  statistics.out_of_range_readings = out_of_range_readings_.load();
  statistics.obstacle_seconds = 1e-9 * static_cast<double>(obstacle_nanoseconds_.load());
  statistics.out_of_range_seconds = 1e-9 * static_cast<double>(out_of_range_nanoseconds_.load());
  return statistics;
}

std::optional<Eigen::Vector3d> InsertionWorker::latestOrigin() const {
  std::lock_guard<std::mutex> lock(origin_mutex_);
  return latest_origin_;
}

void InsertionWorker::resetStatistics() {
  for (std::atomic<std::uint64_t>* counter :
       {&messages_inserted_, &backlog_insertions_, &messages_dropped_queue_, &readings_inserted_,
        &rays_walked_, &readings_rejected_, &insertion_nanoseconds_, &out_of_range_readings_,
        &obstacle_nanoseconds_, &out_of_range_nanoseconds_}) {
    counter->store(0);
  }
}

}  // namespace mvog_ros
