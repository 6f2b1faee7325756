// What mvog::Map promises about threads, checked under ThreadSanitizer by scripts/sanitizers.sh
// (and under AddressSanitizer + UBSan there too):
//  - insertScan with insertion_threads > 1 runs its own threads without data races, and builds the
//    same map as one thread;
//  - const methods may run concurrently with each other (many readers, no writer);
//  - the server's pattern (src/ros/mapper.cpp): one writer (insertScan with threads, decay) under
//    the exclusive side of its map lock (mvog_ros/writer_preferring_mutex.h), readers (point
//    queries, cross-sections, projections, change tracking, serialisation, memory usage) under its
//    shared side.
// Map is documented as not thread-safe for a writer against readers: that is not tested.
// No wall-clock time is asserted; every loop runs a fixed amount of work.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <mutex>
#include <random>
#include <shared_mutex>
#include <thread>
#include <vector>

#include "mvog/map.h"
#include "mvog/map_io.h"
#include "mvog_ros/writer_preferring_mutex.h"

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

mvog::MapConfig smallConfig() {
  mvog::MapConfig config;
  config.resolution = 0.1;
  config.max_coordinate = 100.0;
  return config;
}

/// A depth-camera-like scan: `count` rays from `origin` into a box of walls, some out of range.
mvog::Scan makeScan(std::uint32_t seed, std::size_t count, const Eigen::Vector3d& origin) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> angle(-1.2, 1.2);
  std::uniform_real_distribution<double> elevation(-0.5, 0.5);
  std::uniform_real_distribution<double> range(0.5, 4.0);
  mvog::Scan scan;
  scan.origin = origin;
  const double heading = 0.7 * seed;
  for (std::size_t k = 0; k < count; ++k) {
    const double a = heading + angle(random);
    const double e = elevation(random);
    const Eigen::Vector3d direction(std::cos(a) * std::cos(e), std::sin(a) * std::cos(e),
                                    std::sin(e));
    const Eigen::Vector3f end = (origin + range(random) * direction).cast<float>();
    if (k % 10 == 9) {
      scan.out_of_range.push_back(end);
    } else {
      scan.hits.push_back(end);
    }
  }
  return scan;
}

mvog::InsertionConfig threads(int insertion_threads) {
  mvog::InsertionConfig config;
  config.insertion_threads = insertion_threads;
  config.max_range = 5.0;
  return config;
}

TEST(Concurrency, ThreadedInsertionIsRaceFreeAndBuildsTheSameMap) {
  mvog::Map one(smallConfig());
  mvog::Map four(smallConfig());
  for (std::uint32_t seed = 1; seed <= 3; ++seed) {
    const mvog::Scan scan = makeScan(seed, 4000, {0.1 * seed, -0.2 * seed, 1.0});
    const mvog::InsertionResult a = one.insertScan(scan, threads(1));
    const mvog::InsertionResult b = four.insertScan(scan, threads(4));
    EXPECT_EQ(a.inserted(), b.inserted());
    EXPECT_EQ(a.rejected(), b.rejected());
  }
  EXPECT_EQ(mvog::serializeMap(one), mvog::serializeMap(four));
}

/// Everything a reader of the server asks, folded into a number that must not depend on timing.
double readEverything(const mvog::Map& map, std::uint32_t seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> coordinate(-4.0, 4.0);
  double sum = 0.0;
  for (int k = 0; k < 200; ++k) {
    const mvog::PointOccupancy o =
        map.occupancy({coordinate(random), coordinate(random), coordinate(random) * 0.3 + 1.0});
    sum += o.probability.value_or(-1.0f);
  }
  sum += map.occupancy({std::nan(""), 0.0, 0.0}).known() ? 1000.0 : 0.0;
  const mvog::CellRange bounds = map.bounds();
  if (!bounds.empty()) {
    const mvog::CrossSection section = map.crossSection(1.0, bounds);
    for (float p : section.values) sum += std::isnan(p) ? 0.0 : p;
    const mvog::Projection projection = map.projection(0.5, 1.5, 0.5, bounds);
    for (mvog::OccupancyState s : projection.values) sum += static_cast<int>(s);
  }
  sum += static_cast<double>(map.memoryUsage().cells_with_volumes);
  sum += static_cast<double>(map.tilesModifiedSince(0).size());
  sum += static_cast<double>(mvog::serializeMap(map).size());
  std::size_t volumes = 0;
  map.forEachVolume(
      [&](const mvog::CellIndex&, mvog::VolumeSign, const mvog::Volume&) { ++volumes; });
  sum += static_cast<double>(volumes);
  return sum;
}

TEST(Concurrency, ConstQueriesRunConcurrently) {
  mvog::Map map(smallConfig());
  map.insertScan(makeScan(7, 3000, {0.0, 0.0, 1.0}), threads(1));
  map.decay(0.9);
  const mvog::Map& reader = map;
  std::vector<double> expected;
  for (std::uint32_t t = 0; t < 4; ++t) expected.push_back(readEverything(reader, t));

  std::vector<double> results(4, 0.0);
  std::vector<std::thread> readers;
  for (std::uint32_t t = 0; t < 4; ++t) {
    readers.emplace_back([&, t] {
      for (int round = 0; round < 3; ++round) {
        const double value = readEverything(reader, t);
        if (round == 0) results[t] = value;
        if (value != results[t]) results[t] = std::nan("");
      }
    });
  }
  for (std::thread& thread : readers) thread.join();
  for (std::size_t t = 0; t < 4; ++t) EXPECT_EQ(results[t], expected[t]) << "reader " << t;
}

TEST(Concurrency, OneWriterAndReadersUnderTheServersMapLock) {
  constexpr std::uint32_t kScans = 12;
  constexpr int kReads = 12;
  mvog::Map map(smallConfig());
  mvog_ros::WriterPreferringMutex mutex;
  std::atomic<std::uint64_t> reads{0};

  std::thread writer([&] {
    for (std::uint32_t seed = 1; seed <= kScans; ++seed) {
      const mvog::Scan scan = makeScan(seed, 1500, {0.2 * seed - 1.0, 0.1 * seed, 1.0});
      {
        std::unique_lock<mvog_ros::WriterPreferringMutex> lock(mutex);
        map.insertScan(scan, threads(seed % 2 == 0 ? 3 : 1));
      }
      if (seed % 4 == 0) {
        std::unique_lock<mvog_ros::WriterPreferringMutex> lock(mutex);
        map.decay(0.8);
      }
    }
  });
  std::vector<std::thread> readers;
  for (std::uint32_t t = 0; t < 3; ++t) {
    readers.emplace_back([&, t] {
      std::uint64_t last_revision = 0;
      for (int k = 0; k < kReads; ++k) {
        std::shared_lock<mvog_ros::WriterPreferringMutex> lock(mutex);
        EXPECT_GE(map.revision(), last_revision);
        last_revision = map.revision();
        const std::vector<std::uint8_t> bytes = mvog::serializeMap(map);
        const mvog::Map copy = mvog::deserializeMap(bytes.data(), bytes.size());
        EXPECT_EQ(copy.memoryUsage().cells_with_volumes, map.memoryUsage().cells_with_volumes);
        readEverything(map, t);
        ++reads;
      }
    });
  }
  writer.join();
  for (std::thread& thread : readers) thread.join();
  EXPECT_EQ(reads.load(), 3u * kReads);

  // The readers changed nothing: the same map as the same writes alone.
  mvog::Map alone(smallConfig());
  for (std::uint32_t seed = 1; seed <= kScans; ++seed) {
    alone.insertScan(makeScan(seed, 1500, {0.2 * seed - 1.0, 0.1 * seed, 1.0}), threads(1));
    if (seed % 4 == 0) alone.decay(0.8);
  }
  EXPECT_EQ(mvog::serializeMap(map), mvog::serializeMap(alone));
}

}  // namespace
