// InsertionWorker (mvog_ros/insertion_worker.h): every queued scan goes into the map or is
// counted as dropped (the oldest first when the queue is full), pieces of large scans build the
// map of the whole scan, depth images go in straight from their pixels, and stop() inserts what
// is queued.
#include <gtest/gtest.h>

#include <cstring>
#include <mutex>
#include <optional>
#include <random>
#include <thread>
#include <vector>

#include <ros/time.h>

#include "mvog/depth_image.h"
#include "mvog/map_io.h"
#include "mvog_ros/insertion_worker.h"

namespace mvog_ros {
namespace {

mvog::MapConfig mapConfig() {
  mvog::MapConfig config;
  config.resolution = 0.1;
  config.max_coordinate = 100.0;
  return config;
}

/// `hits` obstacle readings from `origin`, some NaN (rejected by the core), around (5, 0, 1).
mvog::Scan scanOf(std::size_t hits, std::size_t nan_hits, const Eigen::Vector3d& origin,
                  std::uint32_t seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<float> spread(-2.0f, 2.0f);
  mvog::Scan scan;
  scan.origin = origin;
  for (std::size_t k = 0; k < hits; ++k) scan.hits.emplace_back(5.0f, spread(random), 1.0f);
  for (std::size_t k = 0; k < nan_hits; ++k) scan.hits.emplace_back(NAN, 0.0f, 1.0f);
  scan.out_of_range.emplace_back(0.0f, 5.0f, 1.0f);
  return scan;
}

class InsertionWorkerTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { ros::Time::init(); }  // the throttled warnings read the time
};

TEST_F(InsertionWorkerTest, InsertsWhatIsQueuedAndCountsWhatItDid) {
  SharedMap shared_map{mvog::Map(mapConfig())};
  InsertionWorkerConfig config;
  config.insertion_queue_size = 10;
  InsertionWorker worker(config, shared_map);
  for (std::uint32_t k = 0; k < 5; ++k) worker.enqueue(scanOf(100, 2, {0, 0, 1}, k), "test");
  worker.stop();  // inserts what is queued first
  const InsertionStatistics statistics = worker.statistics();
  EXPECT_EQ(statistics.messages_inserted, 5u);
  EXPECT_EQ(statistics.messages_dropped_queue, 0u);
  EXPECT_EQ(statistics.readings_inserted, 5u * 101);  // hits and the out-of-range reading
  EXPECT_EQ(statistics.readings_rejected, 5u * 2);    // the NaN hits
  // For free space: at most one ray per reading (one per end voxel by default).
  EXPECT_GT(statistics.rays_walked, 0u);
  EXPECT_LE(statistics.rays_walked, statistics.readings_inserted);
  EXPECT_GE(statistics.insertion_seconds, 0.0);
  EXPECT_EQ(shared_map.map.occupancy({5.05, 0.05, 1.0}).state(0.5),
            mvog::OccupancyState::kOccupied);

  worker.resetStatistics();
  const InsertionStatistics reset = worker.statistics();
  EXPECT_EQ(reset.messages_inserted, 0u);
  EXPECT_EQ(reset.readings_inserted, 0u);
  EXPECT_EQ(reset.rays_walked, 0u);
  EXPECT_EQ(reset.backlog_insertions, 0u);
  EXPECT_EQ(reset.readings_rejected, 0u);
  EXPECT_EQ(reset.insertion_seconds, 0.0);
}

TEST_F(InsertionWorkerTest, AFullQueueDropsTheOldestAndKeepsTheNewest) {
  SharedMap shared_map{mvog::Map(mapConfig())};
  InsertionWorkerConfig config;
  config.insertion_queue_size = 1;
  InsertionWorker worker(config, shared_map);
  constexpr std::uint32_t kScans = 6;
  {
    // While the map is held, the worker cannot insert: the queue fills up.
    std::unique_lock<WriterPreferringMutex> hold(shared_map.mutex);
    for (std::uint32_t k = 0; k < kScans; ++k) {
      mvog::Scan scan = scanOf(10, 0, {0, 0, 1}, k);
      if (k == kScans - 1) scan.hits = {{3.05f, 7.05f, 1.0f}};  // the newest, seen nowhere else
      worker.enqueue(std::move(scan), "test");
    }
  }
  worker.stop();
  const InsertionStatistics statistics = worker.statistics();
  // The worker may have taken the first scan before the map was held: 1 or 2 inserted.
  EXPECT_EQ(statistics.messages_inserted + statistics.messages_dropped_queue, kScans);
  EXPECT_GE(statistics.messages_dropped_queue, kScans - 2);
  EXPECT_EQ(shared_map.map.occupancy({3.05, 7.05, 1.0}).state(0.5),
            mvog::OccupancyState::kOccupied);
}

TEST_F(InsertionWorkerTest, AScanPreparedOutsideTheLockBuildsTheMapOfInsertScan) {
  // The worker rasterises outside the map's lock and applies under it: the map of
  // Map::insertScan, with the default rules and with the paper's, on 1 or 2 threads.
  const mvog::Scan large = scanOf(50000, 10, {0.3, -0.2, 1.2}, 7);
  for (const mvog::ModelRules& rules : {mvog::ModelRules{}, mvog::ModelRules::paper()}) {
    for (int threads : {1, 2}) {
      mvog::MapConfig map_config = mapConfig();
      map_config.rules = rules;
      InsertionWorkerConfig config;
      config.insertion_threads = threads;
      mvog::Map whole(map_config);
      const mvog::InsertionResult expected = whole.insertScan(large, config);

      SharedMap shared_map{mvog::Map(map_config)};
      InsertionWorker worker(config, shared_map);
      worker.enqueue(mvog::Scan(large), "test");
      worker.stop();
      EXPECT_EQ(mvog::serializeMap(shared_map.map), mvog::serializeMap(whole))
          << threads << " threads";
      EXPECT_EQ(worker.statistics().readings_inserted, expected.inserted());
      EXPECT_EQ(worker.statistics().readings_rejected, expected.rejected());
      EXPECT_EQ(worker.statistics().out_of_range_readings, expected.out_of_range_readings);
      EXPECT_EQ(worker.statistics().rays_walked, expected.rays_walked);
    }
  }
}

TEST_F(InsertionWorkerTest, ABacklogInsertedOnMoreThreadsBuildsTheSameMap) {
  // Scans queued faster than the worker inserts them go in on ~backlog_insertion_threads while
  // another waits: the map of inserting them one by one on one thread, bit for bit.
  std::vector<mvog::Scan> scans;
  for (std::uint32_t k = 0; k < 12; ++k) {
    scans.push_back(scanOf(20000, 0, {0.1 * k, -0.2, 1.0 + 0.05 * k}, k));
  }
  mvog::Map one_by_one(mapConfig());
  for (const mvog::Scan& scan : scans) one_by_one.insertScan(scan);

  SharedMap shared_map{mvog::Map(mapConfig())};
  InsertionWorkerConfig config;
  config.insertion_queue_size = 100;
  config.backlog_insertion_threads = 4;
  InsertionWorker worker(config, shared_map);
  {
    // The worker waits for the map while the scans queue up: it may have taken the first, and
    // every one after it but the last has another behind it.
    std::unique_lock<WriterPreferringMutex> lock(shared_map.mutex);
    for (const mvog::Scan& scan : scans) worker.enqueue(mvog::Scan(scan), "test");
  }
  worker.stop();
  EXPECT_EQ(worker.statistics().messages_inserted, scans.size());
  EXPECT_GE(worker.statistics().backlog_insertions, scans.size() - 2);
  EXPECT_LE(worker.statistics().backlog_insertions, scans.size() - 1);
  EXPECT_EQ(mvog::serializeMap(shared_map.map), mvog::serializeMap(one_by_one));
}

/// A 160 x 120 depth image (32FC1) of a wall 3 m ahead, the camera at (0, 0, 1) looking along +x,
/// every 7th pixel without a measurement (NaN), as the server queues it (DepthImageReadings).
DepthImageReadings depthImageOfAWall(float wall, std::uint32_t seed) {
  constexpr std::uint32_t kWidth = 160;
  constexpr std::uint32_t kHeight = 120;
  auto image = boost::make_shared<sensor_msgs::Image>();
  image->width = kWidth;
  image->height = kHeight;
  image->encoding = "32FC1";
  image->step = kWidth * sizeof(float);
  image->data.resize(std::size_t{image->step} * kHeight);
  std::mt19937 random(seed);
  std::uniform_real_distribution<float> noise(-0.01f, 0.01f);
  for (std::size_t k = 0; k < std::size_t{kWidth} * kHeight; ++k) {
    const float depth = k % 7 == 0 ? NAN : wall + noise(random);
    std::memcpy(image->data.data() + k * sizeof(float), &depth, sizeof depth);
  }
  sensor_msgs::CameraInfo info;
  info.width = kWidth;
  info.height = kHeight;
  info.K = {130.0, 0.0, 79.5, 0.0, 130.0, 59.5, 0.0, 0.0, 1.0};
  Eigen::Matrix3d looking_along_x;
  looking_along_x << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translate(Eigen::Vector3d(0.0, 0.0, 1.0));
  pose.rotate(looking_along_x);
  return {image, depthFrameOf(*image, info, pose, mvog::DepthImageConfig{}, 1000000)};
}

TEST_F(InsertionWorkerTest, DepthImagesGoInStraightFromTheirPixelsAsTheirScansWould) {
  // Queued as images (no Scan of their pixels), on one thread or on the backlog's four: the map
  // of inserting each image's Scan one by one, the pixels without a measurement counted.
  std::vector<DepthImageReadings> images;
  for (std::uint32_t k = 0; k < 6; ++k)
    images.push_back(depthImageOfAWall(3.0f + 0.1f * static_cast<float>(k), k));
  mvog::Map one_by_one(mapConfig());
  std::size_t skipped_total = 0;
  for (const DepthImageReadings& image : images) {
    std::size_t skipped = 0;
    one_by_one.insertScan(mvog::backProjectDepthImage(image.frame, skipped));
    skipped_total += skipped;
  }
  ASSERT_GT(skipped_total, 0u);
  for (int backlog_threads : {1, 4}) {
    SharedMap shared_map{mvog::Map(mapConfig())};
    InsertionWorkerConfig config;
    config.insertion_queue_size = 100;
    config.backlog_insertion_threads = backlog_threads;
    InsertionWorker worker(config, shared_map);
    {
      std::unique_lock<WriterPreferringMutex> lock(shared_map.mutex);
      for (const DepthImageReadings& image : images)
        worker.enqueue(DepthImageReadings(image), "test");
    }
    worker.stop();
    EXPECT_EQ(worker.statistics().messages_inserted, images.size());
    EXPECT_EQ(worker.statistics().readings_rejected, skipped_total);
    EXPECT_EQ(mvog::serializeMap(shared_map.map), mvog::serializeMap(one_by_one))
        << backlog_threads << " backlog threads";
    const std::optional<Eigen::Vector3d> origin = worker.latestOrigin();
    ASSERT_TRUE(origin.has_value());
    EXPECT_EQ(*origin, Eigen::Vector3d(0.0, 0.0, 1.0));
  }
}

TEST_F(InsertionWorkerTest, ScansGoIntoMapsReplacedWhileTheyArePrepared) {
  // ~load_map may put a map of another resolution or other rules in place between a scan's
  // preparation (outside the lock) and its application: the worker prepares it again for the
  // map in place. Maps of two configurations replace each other while scans are inserted.
  SharedMap shared_map{mvog::Map(mapConfig())};
  InsertionWorkerConfig config;
  config.insertion_queue_size = 1000;
  InsertionWorker worker(config, shared_map);
  mvog::MapConfig other = mapConfig();
  other.resolution *= 2.0;
  other.rules = mvog::ModelRules::paper();
  constexpr int kScans = 200;
  std::thread loader([&] {
    for (int k = 0; k < kScans; ++k) {
      std::unique_lock<WriterPreferringMutex> lock(shared_map.mutex);
      shared_map.replace(mvog::Map(k % 2 == 0 ? other : mapConfig()));
    }
  });
  for (int k = 0; k < kScans; ++k) worker.enqueue(scanOf(200, 0, {0.3, -0.2, 1.2}, 3), "test");
  loader.join();
  worker.stop();
  EXPECT_EQ(worker.statistics().messages_inserted, static_cast<std::uint64_t>(kScans));
  EXPECT_EQ(worker.statistics().readings_inserted, kScans * 201u);  // 200 hits, 1 out of range
  EXPECT_EQ(shared_map.map.resolution(), mapConfig().resolution);
}

TEST_F(InsertionWorkerTest, NothingIsInsertedAfterStop) {
  SharedMap shared_map{mvog::Map(mapConfig())};
  InsertionWorker worker(InsertionWorkerConfig(), shared_map);
  worker.stop();
  worker.enqueue(scanOf(10, 0, {0, 0, 1}, 1), "test");
  worker.stop();  // stopping twice is fine
  EXPECT_EQ(worker.statistics().messages_inserted, 0u);
  EXPECT_TRUE(shared_map.map.empty());
}

}  // namespace
}  // namespace mvog_ros
