#include "mvog_ros/insertion_worker.h"

#include <chrono>
#include <utility>

#include <ros/console.h>

namespace mvog_ros {
namespace {

// Readings inserted under one hold of the map's lock: ~50 ms at 5 cm, the longest insertion
// keeps a query waiting.
constexpr std::size_t kReadingsPerLock = 16384;

}  // namespace

InsertionWorker::InsertionWorker(const InsertionWorkerConfig& config, SharedMap& shared_map)
    : config_(config), map_(shared_map), thread_(&InsertionWorker::run, this) {}

InsertionWorker::~InsertionWorker() { stop(); }

void InsertionWorker::enqueue(mvog::Scan&& scan, const std::string& source) {
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
    queue_.push_back({std::move(scan), source});
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
    QueuedScan queued;
    {
      std::unique_lock<std::mutex> lock(queue_mutex_);
      queue_changed_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
      if (queue_.empty()) return;  // stopping, and what was queued is in the map
      queued = std::move(queue_.front());
      queue_.pop_front();
    }
    const auto start = std::chrono::steady_clock::now();
    const mvog::InsertionResult result = insert(queued.scan);
    insertion_nanoseconds_ +=
        static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                       std::chrono::steady_clock::now() - start)
                                       .count());
    readings_inserted_ += result.inserted();
    readings_rejected_ += result.rejected();
    ++messages_inserted_;
    if (result.rejected_out_of_bounds > 0) {
      ROS_WARN_THROTTLE(kWarningPeriod,
                        "mvog: %zu readings of a %s lie beyond ~max_coordinate and were rejected",
                        result.rejected_out_of_bounds, queued.source.c_str());
    }
  }
}

mvog::InsertionResult InsertionWorker::insert(const mvog::Scan& scan) {
  if (config_.clear_conflicting_free_space) {
    // Sec. V.B's conflicts are those within one scan: the scan goes in whole.
    std::unique_lock<WriterPreferringMutex> lock(map_.mutex);
    return map_.map.insertScan(scan, config_);
  }
  // Piece by piece, the same map (mvog::splitScan), and queries and publications wait for one
  // piece at most instead of a whole cloud.
  mvog::InsertionResult result;
  for (const mvog::Scan& piece : mvog::splitScan(scan, kReadingsPerLock)) {
    std::unique_lock<WriterPreferringMutex> lock(map_.mutex);
    result += map_.map.insertScan(piece, config_);
  }
  return result;
}

InsertionStatistics InsertionWorker::statistics() const {
  InsertionStatistics statistics;
  statistics.messages_inserted = messages_inserted_.load();
  statistics.messages_dropped_queue = messages_dropped_queue_.load();
  statistics.readings_inserted = readings_inserted_.load();
  statistics.readings_rejected = readings_rejected_.load();
  statistics.insertion_seconds = 1e-9 * static_cast<double>(insertion_nanoseconds_.load());
  return statistics;
}

void InsertionWorker::resetStatistics() {
  for (std::atomic<std::uint64_t>* counter :
       {&messages_inserted_, &messages_dropped_queue_, &readings_inserted_, &readings_rejected_,
        &insertion_nanoseconds_}) {
    counter->store(0);
  }
}

}  // namespace mvog_ros
