#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>

#include "mvog/map.h"
#include "mvog/scan_update.h"
#include "mvog_ros/conversions.h"
#include "mvog_ros/mapper_config.h"
#include "mvog_ros/shared_map.h"

namespace mvog_ros {

/// What the insertion worker did since the start or the last reset.
struct InsertionStatistics {
  std::uint64_t messages_inserted = 0;
  std::uint64_t backlog_insertions = 0;      // on ~backlog_insertion_threads, another waiting
  std::uint64_t messages_dropped_queue = 0;  // the oldest waiting, when the queue was full
  std::uint64_t readings_inserted = 0;
  std::uint64_t rays_walked = 0;        // for free space: mvog::InsertionResult::rays_walked
  std::uint64_t readings_rejected = 0;  // by the core: mvog::InsertionResult::rejected()
  double insertion_seconds = 0.0;
  std::uint64_t out_of_range_readings = 0;
  /// Thread time rasterising the obstacle readings and the out-of-range readings.
  double obstacle_seconds = 0.0;
  double out_of_range_seconds = 0.0;
};

/// Inserts converted sensor messages into the map, on a thread of its own behind a bounded queue
/// (~insertion_queue_size): when the sensors outpace it, the oldest waiting message is dropped
/// and counted, so that the newest view is kept. The only writer of readings into the map.
class InsertionWorker {
 public:
  InsertionWorker(const InsertionWorkerConfig& config, SharedMap& shared_map);
  /// stop()
  ~InsertionWorker();
  InsertionWorker(const InsertionWorker&) = delete;
  InsertionWorker& operator=(const InsertionWorker&) = delete;

  /// Queues `readings` for insertion; `source` (its message type) names them in warnings.
  void enqueue(SensorReadings&& readings, const std::string& source);
  /// ~min_range, ~max_range and ~evidence_limit changed (RuntimeReconfigure, validated
  /// already): the next scan inserted uses them (`insertion`'s other fields are start-only).
  void reconfigure(const mvog::InsertionConfig& insertion);
  /// Inserts what is queued, then ends the thread: nothing enqueued afterwards is inserted.
  void stop();

  InsertionStatistics statistics() const;
  void resetStatistics();
  /// Where the latest scan inserted was taken from (its origin, map frame), if any was.
  std::optional<Eigen::Vector3d> latestOrigin() const;

 private:
  struct QueuedReadings {
    SensorReadings readings;
    std::string source;
  };

  void run();
  /// The worker's one call into the core: `readings` into the map, prepared outside the map's
  /// lock and applied under its write lock; with ~backlog_insertion_threads if `backlog`.
  mvog::InsertionResult insert(const SensorReadings& readings, bool backlog);

  // Its ranges and evidence limit: those at start (reconfigured_ follows them).
  const InsertionWorkerConfig config_;
  mutable std::mutex reconfigured_mutex_;
  mvog::InsertionConfig reconfigured_;  // under reconfigured_mutex_
  SharedMap& map_;
  mvog::ScanUpdate update_;  // its buffers and threads, kept from scan to scan

  std::mutex queue_mutex_;
  std::condition_variable queue_changed_;
  std::deque<QueuedReadings> queue_;
  bool stopping_ = false;

  std::atomic<std::uint64_t> messages_inserted_{0};
  std::atomic<std::uint64_t> backlog_insertions_{0};
  std::atomic<std::uint64_t> messages_dropped_queue_{0};
  std::atomic<std::uint64_t> readings_inserted_{0};
  std::atomic<std::uint64_t> rays_walked_{0};
  std::atomic<std::uint64_t> readings_rejected_{0};
  std::atomic<std::uint64_t> insertion_nanoseconds_{0};
  std::atomic<std::uint64_t> out_of_range_readings_{0};
  std::atomic<std::uint64_t> obstacle_nanoseconds_{0};
  std::atomic<std::uint64_t> out_of_range_nanoseconds_{0};
  mutable std::mutex origin_mutex_;
  std::optional<Eigen::Vector3d> latest_origin_;  // under origin_mutex_

  std::thread thread_;  // last: it runs on the members above
};

}  // namespace mvog_ros
