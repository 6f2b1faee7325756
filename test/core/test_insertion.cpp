// Insertion of readings and scans (Sec. III-B, Fig. 2): eqs. (3)-(6) on the rays of Fig. 3 with
// the paper's model, the InsertionConfig options, the scan update (order and threads do not
// matter, the two phases), the model's rules (Sec. V.B, V.C, counting per scan) against a plain
// reference implementation, and the Sec. III-A invariants after many random readings.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "mvog/constraints.h"
#include "mvog/map.h"
#include "mvog/scan_update.h"
#include "reference_model.h"
#include "test_util.h"

namespace mvog {
namespace {

using test::allVolumes;
using test::kFloatInf;
using test::kFloatNaN;
using test::totalMass;
using test::unitConfig;
using test::volumeIs;

// ---- Fig. 3 (s = 1, so heights in grid units are metres) --------------------------------------

TEST(Insertion, Fig3LeftRayHasPaddingVolume) {
  Map map(unitConfig());
  const InsertionResult result = map.insertReading({0, 0, 0}, {0, 4.5, 10}, ReadingKind::kObstacle);
  EXPECT_EQ(result.obstacle_readings, 1u);
  // x = 0 lies in cell i = 0. The projection runs along +y from 0 to 4.5 through cells
  // j = 0..4; the ray rises z = (10 / 4.5) y, so it crosses the wall y = j at z = 2.222 j.
  const double slope = 10.0 / 4.5;
  for (int j = 0; j < 4; ++j) {
    SCOPED_TRACE(::testing::Message() << "cell (0, " << j << ")");
    // Eq. (3): [z_enter, z_exit] = [2.222 j, 2.222 (j + 1)]; the height 2.222 >= 1, so eq. (6)
    // leaves it, and at density 1 its mass is its height.
    const CellVolumes cell = map.cellVolumes({0, j});
    EXPECT_TRUE(cell.positive.empty());
    ASSERT_EQ(cell.negative.size(), 1u);
    EXPECT_TRUE(volumeIs(cell.negative[0], slope * j, slope * (j + 1), slope));
  }
  // Last cell j = 4: z_enter = 2.222 * 4 = 8.889 and L'_z = 10, |z_enter - L'_z| = 1.111 > 1.
  // Eq. (5): V = [10 - 0.5, 10 + 0.5] = [9.5, 10.5], mass 1.
  // The padding V' spans z_enter to V's bottom: [8.889, 9.5], height 0.611 < 1, so eq. (6)
  // centres it on (8.889 + 9.5) / 2 = 9.194: [8.694, 9.694], mass 1.
  const CellVolumes last = map.cellVolumes({0, 4});
  ASSERT_EQ(last.positive.size(), 1u);
  EXPECT_TRUE(volumeIs(last.positive[0], 9.5, 10.5, 1.0));
  ASSERT_EQ(last.negative.size(), 1u);
  const double pad_centre = 0.5 * (4 * slope + 9.5);
  EXPECT_TRUE(volumeIs(last.negative[0], pad_centre - 0.5, pad_centre + 0.5, 1.0));
  EXPECT_EQ(test::observedCells(map).size(), 5u);
  EXPECT_EQ(allVolumes(map).size(), 6u);
}

TEST(Insertion, Fig3RightRayHasNoPaddingVolume) {
  Map map(unitConfig());
  map.insertReading({0, 0, 0}, {0, 10.5, 4}, ReadingKind::kObstacle);
  // Cells j = 0..10 along +y; z = (4 / 10.5) y crosses the wall y = j at z = 0.381 j.
  const double slope = 4.0 / 10.5;
  for (int j = 0; j < 10; ++j) {
    SCOPED_TRACE(::testing::Message() << "cell (0, " << j << ")");
    // Eq. (3): [0.381 j, 0.381 (j + 1)] has height 0.381 < 1; eq. (6) centres it on
    // 0.381 (j + 0.5) with height 1 and mass 1.
    const CellVolumes cell = map.cellVolumes({0, j});
    EXPECT_TRUE(cell.positive.empty());
    ASSERT_EQ(cell.negative.size(), 1u);
    const double centre = slope * (j + 0.5);
    EXPECT_TRUE(volumeIs(cell.negative[0], centre - 0.5, centre + 0.5, 1.0));
  }
  // Last cell j = 10: z_enter = 3.810, L'_z = 4, |z_enter - L'_z| = 0.190 <= 1: only V of eq. (5),
  // [3.5, 4.5] with mass 1, and no negative volume.
  const CellVolumes last = map.cellVolumes({0, 10});
  ASSERT_EQ(last.positive.size(), 1u);
  EXPECT_TRUE(volumeIs(last.positive[0], 3.5, 4.5, 1.0));
  EXPECT_TRUE(last.negative.empty());
  EXPECT_EQ(test::observedCells(map).size(), 11u);
}

TEST(Insertion, Fig3LeftRayAsOutOfRangeReadingIsFreeUpToItsEnd) {
  Map map(unitConfig());
  const InsertionResult result =
      map.insertReading({0, 0, 0}, {0, 4.5, 10}, ReadingKind::kOutOfRange);
  EXPECT_EQ(result.out_of_range_readings, 1u);
  EXPECT_EQ(result.obstacle_readings, 0u);
  // Cells j = 0..3 as for the obstacle reading; the last cell gets eq. (4):
  // [min(z_enter, L'_z), max(z_enter, L'_z)] = [8.889, 10], mass 1.111, and no positive volume.
  const double slope = 10.0 / 4.5;
  for (int j = 0; j < 4; ++j) {
    const CellVolumes cell = map.cellVolumes({0, j});
    ASSERT_EQ(cell.negative.size(), 1u);
    EXPECT_TRUE(volumeIs(cell.negative[0], slope * j, slope * (j + 1), slope));
  }
  const CellVolumes last = map.cellVolumes({0, 4});
  EXPECT_TRUE(last.positive.empty());
  ASSERT_EQ(last.negative.size(), 1u);
  EXPECT_TRUE(volumeIs(last.negative[0], 4 * slope, 10.0, 10.0 - 4 * slope));
  map.forEachVolume([](const CellIndex&, VolumeSign sign, const Volume&) {
    EXPECT_EQ(sign, VolumeSign::kNegative);
  });
}

// ---- Eq. (5), both cases, in both directions -------------------------------------------------

TEST(Insertion, DescendingRayPadsDownToTheObstacleTop) {
  Map map(unitConfig());
  map.insertReading({0.5, 0.5, 10}, {1.5, 0.5, 0}, ReadingKind::kObstacle);
  // Cell (0, 0): z from 10 down to 5 at the wall x = 1: eq. (3) gives [5, 10], mass 5.
  const CellVolumes first = map.cellVolumes({0, 0});
  ASSERT_EQ(first.negative.size(), 1u);
  EXPECT_TRUE(volumeIs(first.negative[0], 5.0, 10.0, 5.0));
  // Cell (1, 0): z_enter = 5, L'_z = 0, |5 - 0| > 1: V = [-0.5, 0.5] and V' from V's top up to
  // z_enter: [0.5, 5], mass 4.5.
  const CellVolumes last = map.cellVolumes({1, 0});
  ASSERT_EQ(last.positive.size(), 1u);
  EXPECT_TRUE(volumeIs(last.positive[0], -0.5, 0.5, 1.0));
  ASSERT_EQ(last.negative.size(), 1u);
  EXPECT_TRUE(volumeIs(last.negative[0], 0.5, 5.0, 4.5));
}

TEST(Insertion, EntryExactlyOneAboveTheObstacleNeedsNoPadding) {
  Map map(unitConfig());
  map.insertReading({0.5, 0.5, 0}, {1.5, 0.5, 2}, ReadingKind::kObstacle);
  // Cell (0, 0): [0, 1] (height exactly 1). Cell (1, 0): z_enter = 1, L'_z = 2, |1 - 2| = 1 <= 1:
  // only V = [1.5, 2.5].
  const CellVolumes first = map.cellVolumes({0, 0});
  ASSERT_EQ(first.negative.size(), 1u);
  EXPECT_TRUE(volumeIs(first.negative[0], 0.0, 1.0, 1.0));
  const CellVolumes last = map.cellVolumes({1, 0});
  ASSERT_EQ(last.positive.size(), 1u);
  EXPECT_TRUE(volumeIs(last.positive[0], 1.5, 2.5, 1.0));
  EXPECT_TRUE(last.negative.empty());
}

TEST(Insertion, VerticalRays) {
  Map map(unitConfig());
  // Straight up 5: one cell, z_enter = 0, L'_z = 5: V = [4.5, 5.5], V' = [0, 4.5] (mass 4.5).
  map.insertReading({0.5, 0.5, 0}, {0.5, 0.5, 5}, ReadingKind::kObstacle);
  CellVolumes cell = map.cellVolumes({0, 0});
  ASSERT_EQ(cell.positive.size(), 1u);
  ASSERT_EQ(cell.negative.size(), 1u);
  EXPECT_TRUE(volumeIs(cell.positive[0], 4.5, 5.5, 1.0));
  EXPECT_TRUE(volumeIs(cell.negative[0], 0.0, 4.5, 4.5));
  // Straight down 0.8 in another cell: |0 - (-0.8)| <= 1, V = [-1.3, -0.3] only.
  map.insertReading({-2.5, 3.5, 0}, {-2.5, 3.5, -0.8}, ReadingKind::kObstacle);
  cell = map.cellVolumes({-3, 3});
  ASSERT_EQ(cell.positive.size(), 1u);
  EXPECT_TRUE(volumeIs(cell.positive[0], -1.3, -0.3, 1.0));
  EXPECT_TRUE(cell.negative.empty());
}

TEST(Insertion, HorizontalRayMakesUnitVolumesAroundItsHeight) {
  // A horizontal ray crosses every cell at one height z: eq. (6) gives [z - 0.5, z + 0.5].
  Map map(MapConfig{0.5, 1000.0, ModelRules::paper()});
  map.insertReading({0.1, 0.1, 1.0}, {2.1, 0.1, 1.0},
                    ReadingKind::kObstacle);  // grid: x 0.2 -> 4.2, z = 2
  for (int i = 0; i < 4; ++i) {
    const CellVolumes cell = map.cellVolumes({i, 0});
    ASSERT_EQ(cell.negative.size(), 1u) << "cell " << i;
    EXPECT_TRUE(volumeIs(cell.negative[0], 1.5, 2.5, 1.0));
  }
  const CellVolumes last = map.cellVolumes({4, 0});
  ASSERT_EQ(last.positive.size(), 1u);
  EXPECT_TRUE(volumeIs(last.positive[0], 1.5, 2.5, 1.0));
  EXPECT_TRUE(last.negative.empty());
}

// ---- Merging through the map (eqs. 7, 8) and mass conservation -------------------------------

TEST(Insertion, ReadingsMergeAndConserveMass) {
  Map map(unitConfig());
  map.insertReading({0.5, 0.5, 0}, {0.5, 0.5, 2},
                    ReadingKind::kOutOfRange);  // eq. (4): [0, 2], mass 2
  EXPECT_DOUBLE_EQ(totalMass(map), 2.0);
  map.insertReading({0.5, 0.5, 2.5}, {0.5, 0.5, 4.5},
                    ReadingKind::kOutOfRange);  // [2.5, 4.5], gap 0.5
  // Eq. (8): [0, 4.5], mass 2 + 0.5 + 2 = 4.5.
  CellVolumes cell = map.cellVolumes({0, 0});
  ASSERT_EQ(cell.negative.size(), 1u);
  EXPECT_TRUE(volumeIs(cell.negative[0], 0.0, 4.5, 4.5));
  EXPECT_DOUBLE_EQ(totalMass(map), 4.5);
  map.insertReading({0.5, 0.5, 1}, {0.5, 0.5, 3},
                    ReadingKind::kOutOfRange);  // [1, 3] inside: eq. (7), mass + 2
  cell = map.cellVolumes({0, 0});
  ASSERT_EQ(cell.negative.size(), 1u);
  EXPECT_TRUE(volumeIs(cell.negative[0], 0.0, 4.5, 6.5));
  EXPECT_DOUBLE_EQ(totalMass(map), 6.5);
  map.insertReading({0.5, 0.5, 6}, {0.5, 0.5, 7},
                    ReadingKind::kOutOfRange);  // gap 1.5: a second volume
  EXPECT_EQ(map.cellVolumes({0, 0}).negative.size(), 2u);
  EXPECT_DOUBLE_EQ(totalMass(map), 7.5);
  // Two hits 0.8 apart: [2.5, 3.5] and [4.3, 5.3] merge through the gap of 0.8:
  // [2.5, 5.3], mass 1 + 0.8 + 1 = 2.8.
  map.insertReading({0.5, 0.5, 0}, {0.5, 0.5, 3}, ReadingKind::kObstacle);
  map.insertReading({0.5, 0.5, 0}, {0.5, 0.5, 4.8}, ReadingKind::kObstacle);
  cell = map.cellVolumes({0, 0});
  ASSERT_EQ(cell.positive.size(), 1u);
  EXPECT_TRUE(volumeIs(cell.positive[0], 2.5, 5.3, 2.8));
}

TEST(Insertion, RandomReadingsKeepTheInvariants) {
  // Thousands of random readings, one at a time: every list keeps the Sec. III-A constraints,
  // and the total mass grows by at least 1 per reading (every reading creates at least one
  // volume, of height >= 1 at density 1, and masses only ever add up).
  Map map(MapConfig{0.5, 1000.0, ModelRules::paper()});
  std::mt19937 rng(2024);
  std::bernoulli_distribution is_obstacle(0.7);
  double previous_total = 0.0;
  for (int k = 0; k < 4000; ++k) {
    const Eigen::Vector3d origin = test::randomPoint(rng, 20.0, 3.0);
    const Eigen::Vector3d end = test::randomPoint(rng, 20.0, 3.0);
    ASSERT_EQ(
        map.insertReading(origin, end,
                          is_obstacle(rng) ? ReadingKind::kObstacle : ReadingKind::kOutOfRange)
            .inserted(),
        1u);
    const double total = totalMass(map);
    ASSERT_GE(total, previous_total + 1.0 - 1e-6 * total) << "after reading " << k;
    previous_total = total;
    if (k % 500 == 0) {
      ASSERT_TRUE(test::mapSatisfiesConstraints(map)) << "after reading " << k;
    }
  }
  EXPECT_TRUE(test::mapSatisfiesConstraints(map));
  EXPECT_GE(previous_total, 4000.0);
}

// ---- InsertionConfig ---------------------------------------------------------------------------

TEST(Insertion, MaxRangeTurnsFarHitsIntoFreeSpace) {
  Map map(unitConfig());
  InsertionConfig config;
  config.max_range = 4.0;
  // A hit 10 away along +x is cut at 4: free space over x in [0.5, 4.5], no obstacle.
  const InsertionResult result =
      map.insertReading({0.5, 0.5, 0.5}, {10.5, 0.5, 0.5}, ReadingKind::kObstacle, config);
  EXPECT_EQ(result.obstacle_readings, 0u);
  EXPECT_EQ(result.out_of_range_readings, 1u);
  EXPECT_EQ(result.truncated_to_max_range, 1u);
  for (int i = 0; i <= 4; ++i) {
    const CellVolumes cell = map.cellVolumes({i, 0});
    EXPECT_TRUE(cell.positive.empty());
    ASSERT_EQ(cell.negative.size(), 1u) << "cell " << i;
    EXPECT_TRUE(volumeIs(cell.negative[0], 0.0, 1.0, 1.0));
  }
  EXPECT_TRUE(map.cellVolumes({5, 0}).negative.empty());
  EXPECT_EQ(map.bounds().max.x, 4);
  // An out-of-range reading is cut too, and is not counted as a truncated hit.
  const InsertionResult free_result =
      map.insertReading({0.5, 0.5, 0.5}, {-9.5, 0.5, 0.5}, ReadingKind::kOutOfRange, config);
  EXPECT_EQ(free_result.out_of_range_readings, 1u);
  EXPECT_EQ(free_result.truncated_to_max_range, 0u);
  EXPECT_EQ(map.bounds().min.x, -4);
  // A hit at exactly max_range stays an obstacle.
  const InsertionResult at_range =
      map.insertReading({0.5, 0.5, 0.5}, {0.5, 4.5, 0.5}, ReadingKind::kObstacle, config);
  EXPECT_EQ(at_range.obstacle_readings, 1u);
  EXPECT_EQ(map.cellVolumes({0, 4}).positive.size(), 1u);
}

TEST(Insertion, MinRangeDropsNearHitsOnly) {
  Map map(unitConfig());
  InsertionConfig config;
  config.min_range = 3.0;
  InsertionResult result =
      map.insertReading({0.5, 0.5, 0}, {2.5, 0.5, 0}, ReadingKind::kObstacle, config);
  EXPECT_EQ(result.rejected_too_close, 1u);
  EXPECT_EQ(result.inserted(), 0u);
  EXPECT_TRUE(map.empty());
  // Out-of-range readings carry free space whatever their length.
  result = map.insertReading({0.5, 0.5, 0}, {2.5, 0.5, 0}, ReadingKind::kOutOfRange, config);
  EXPECT_EQ(result.out_of_range_readings, 1u);
  // A hit at exactly min_range is kept.
  result = map.insertReading({0.5, 0.5, 0}, {0.5, 3.5, 0}, ReadingKind::kObstacle, config);
  EXPECT_EQ(result.obstacle_readings, 1u);
  EXPECT_EQ(map.cellVolumes({0, 3}).positive.size(), 1u);
}

TEST(Insertion, OutOfRangeReadingsCanBeIgnored) {
  Map map(unitConfig());
  InsertionConfig config;
  config.insert_out_of_range = false;
  config.max_range = 5.0;
  EXPECT_EQ(map.insertReading({0.5, 0.5, 0}, {3.5, 0.5, 0}, ReadingKind::kOutOfRange, config)
                .ignored_out_of_range,
            1u);
  // A hit beyond max_range becomes an out-of-range reading, and is ignored too.
  const InsertionResult far =
      map.insertReading({0.5, 0.5, 0}, {9.5, 0.5, 0}, ReadingKind::kObstacle, config);
  EXPECT_EQ(far.ignored_out_of_range, 1u);
  EXPECT_EQ(far.inserted(), 0u);
  EXPECT_TRUE(map.empty());
  // Hits in range still bring their free space.
  map.insertReading({0.5, 0.5, 0}, {3.5, 0.5, 0}, ReadingKind::kObstacle, config);
  EXPECT_EQ(map.cellVolumes({1, 0}).negative.size(), 1u);
  EXPECT_EQ(map.cellVolumes({3, 0}).positive.size(), 1u);
}

TEST(Insertion, WithoutNegativeSpaceOnlyObstaclesAreStored) {
  Map map(unitConfig());
  InsertionConfig config;
  config.model_negative_space = false;
  const InsertionResult free_result =
      map.insertReading({0.5, 0.5, 0}, {5.5, 0.5, 0}, ReadingKind::kOutOfRange, config);
  EXPECT_EQ(free_result.out_of_range_readings, 1u);
  EXPECT_TRUE(allVolumes(map).empty());
  EXPECT_TRUE(map.empty());  // bounds() holds cells with volumes only
  map.insertReading({0.5, 0.5, 0}, {0.5, 5.5, 9}, ReadingKind::kObstacle,
                    config);  // would need padding too
  const std::vector<test::VolumeRecord> volumes = allVolumes(map);
  ASSERT_EQ(volumes.size(), 1u);
  EXPECT_EQ(volumes[0], (test::VolumeRecord{0, 5, 0, 8.5f, 9.5f, 1.0f}));
  EXPECT_EQ(map.bounds().min, (CellIndex{0, 5}));
  EXPECT_EQ(map.bounds().max, (CellIndex{0, 5}));
}

TEST(Insertion, HitsInsideOneObstacleAddTheirMassesInOneSum) {
  // Eq. (7) merges a scan's volumes with the list at once: the masses 2^24 + 1 + 1 sum to
  // 2^24 + 2, a float. Added one after the other, each sum rounded to float, they would leave 2^24.
  Map map(unitConfig());
  map.setCellVolumes({0, 0}, CellVolumes{{Volume{0.0f, 10.0f, 16777216.0f}}, {}});
  Scan scan;
  scan.origin = {0.5, 0.5, 20.0};
  scan.hits = {{0.5f, 0.5f, 2.0f}, {0.5f, 0.5f, 7.0f}};  // [1.5, 2.5] and [6.5, 7.5], mass 1 each
  InsertionConfig config;
  config.model_negative_space = false;
  config.evidence_limit = std::numeric_limits<double>::infinity();  // the sum itself is tested
  map.insertScan(scan, config);
  const CellVolumes held = map.cellVolumes({0, 0});
  ASSERT_EQ(held.positive.size(), 1u);
  EXPECT_EQ(held.positive[0].bottom, 0.0f);
  EXPECT_EQ(held.positive[0].top, 10.0f);
  EXPECT_EQ(held.positive[0].mass, 16777218.0f);
}

TEST(Insertion, BoundsHoldOnlyCellsWithVolumes) {
  // A ray starting on the wall it leaves through never crosses its start cell: the start cell
  // gets no volume, and bounds() must not include it.
  Map map(unitConfig());
  map.insertReading({2.0, 0.5, 0}, {-0.5, 0.5, 0}, ReadingKind::kOutOfRange);
  EXPECT_TRUE(map.cellVolumes({2, 0}).negative.empty());
  EXPECT_EQ(map.bounds().min, (CellIndex{-1, 0}));
  EXPECT_EQ(map.bounds().max, (CellIndex{1, 0}));
  Scan scan;
  scan.origin = {4.0, 0.5, 0};
  scan.hits.push_back({3.5f, 0.5f, 0.0f});
  map.insertScan(scan);
  EXPECT_TRUE(map.cellVolumes({4, 0}).negative.empty());
  EXPECT_EQ(map.bounds().max, (CellIndex{3, 0}));
}

TEST(Insertion, ResultCountsEveryReadingOnce) {
  Map map(unitConfig(100.0));
  InsertionConfig config;
  config.min_range = 0.5;
  config.max_range = 20.0;
  Scan scan;
  scan.origin = {0.5, 0.5, 0.0};
  scan.hits = {{3, 1, 0},         {-4, 2, 1},        {5, -6, 0},  // obstacles
               {kFloatNaN, 0, 0}, {0, kFloatInf, 0},              // non-finite
               {150, 0, 0},                                       // beyond max_coordinate
               {0.6f, 0.5f, 0},   {0.5f, 0.5f, 0},                // too close (one of zero length)
               {30, 0, 0}};                                       // truncated to max_range
  scan.out_of_range = {{10, 10, 0}, {-10, 3, 2}, {0, 0, -kFloatInf}, {0, -101, 0}, {0.5f, 0.5f, 0}};
  const InsertionResult result = map.insertScan(scan, config);
  EXPECT_EQ(result.obstacle_readings, 3u);
  EXPECT_EQ(result.out_of_range_readings, 3u);  // two free endpoints and the truncated hit
  EXPECT_EQ(result.truncated_to_max_range, 1u);
  EXPECT_EQ(result.rejected_non_finite, 3u);
  EXPECT_EQ(result.rejected_out_of_bounds, 2u);
  EXPECT_EQ(result.rejected_too_close, 3u);
  EXPECT_EQ(result.ignored_out_of_range, 0u);
  EXPECT_EQ(result.inserted() + result.rejected(), scan.hits.size() + scan.out_of_range.size());

  config.insert_out_of_range = false;
  const InsertionResult ignoring = map.insertScan(scan, config);
  EXPECT_EQ(ignoring.obstacle_readings, 3u);
  EXPECT_EQ(ignoring.out_of_range_readings, 0u);
  EXPECT_EQ(ignoring.truncated_to_max_range, 0u);
  EXPECT_EQ(ignoring.ignored_out_of_range, 3u);
  EXPECT_EQ(ignoring.inserted() + ignoring.rejected(), scan.hits.size() + scan.out_of_range.size());

  InsertionResult sum = result;
  sum += ignoring;
  EXPECT_EQ(sum.obstacle_readings, 6u);
  EXPECT_EQ(sum.out_of_range_readings, 3u);
  EXPECT_EQ(sum.truncated_to_max_range, 1u);
  EXPECT_EQ(sum.rejected_non_finite, 6u);
  EXPECT_EQ(sum.rejected_out_of_bounds, 4u);
  EXPECT_EQ(sum.rejected_too_close, 6u);
  EXPECT_EQ(sum.ignored_out_of_range, 3u);
}

// ---- The scan update (Fig. 2) ------------------------------------------------------------------

/// Whether two lists hold the same volumes, bit for bit.
bool sameBits(const std::vector<Volume>& a, const std::vector<Volume>& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(Volume)) == 0);
}

TEST(Insertion, CellsHoldExactlyWhatTheListRulesGive) {
  // Vertical readings reach one cell each, so with the paper's model what each cell must hold
  // follows from makeVolume and the list rules alone (Sec. III-B.2: an obstacle's positive
  // volume, then the padding below or above it; free space from the start to the end of an
  // out-of-range reading). Many readings into 2 x 2 cells make both lists of each cell grow,
  // merge, shrink and grow again, which the map does in tiles written in place or rebuilt, with
  // masses rescaled after decay: it must hold exactly the lists the rules give, bit for bit.
  // With split_free_space_at_obstacles too (Sec. V.C): the negative list is then cut at the
  // obstacles of the column's positive list as each reading leaves it.
  ModelRules split = ModelRules::paper();
  split.split_free_space_at_obstacles = true;
  for (const ModelRules& rules : {ModelRules::paper(), split}) {
    SCOPED_TRACE(rules.split_free_space_at_obstacles ? "split" : "paper");
    Map map(unitConfig(10000.0, rules));
    std::vector<std::vector<Volume>> positive(4);
    std::vector<std::vector<Volume>> negative(4);
    ListMerger merger;
    const FreeSpaceRules free_space_rules{rules.split_free_space_at_obstacles, false};
    // Merges `added` (none, one volume) into one list of a cell as a reading does.
    auto insert_into = [&](std::vector<Volume>& list, VolumeRun added, VolumeRun obstacles,
                           FreeSpaceRules list_rules) {
      std::vector<Volume> out;
      merger.merge(list, added, obstacles, list_rules, 1.0f, out);
      list = out;
    };
    // Short rays at one of 8 levels 12 apart: volumes of one level merge, different levels stay
    // apart, so the lists hold up to 8 volumes and a volume bridging two of a level shrinks them.
    std::mt19937 rng(5);
    std::uniform_int_distribution<int> level_of(0, 7);
    std::uniform_int_distribution<int> quarters(0, 8);
    std::uniform_int_distribution<int> length_in_eighths(1, 20);
    std::uniform_int_distribution<int> cell_of(0, 3);
    std::bernoulli_distribution is_obstacle(0.4);
    std::bernoulli_distribution upwards(0.5);
    for (int step = 0; step < 4000; ++step) {
      const int c = cell_of(rng);
      const double x = (c % 2) + 0.5;
      const double y = (c / 2) + 0.5;
      // The first readings stay on one level, so that columns hold one free-space volume for a
      // while (the commonest case, which the map updates in place).
      const int level = step < 400 ? 0 : level_of(rng);
      const double z0 = 12.0 * level + quarters(rng) / 4.0;
      const double length = length_in_eighths(rng) / 8.0;
      const double z1 = upwards(rng) ? z0 + length : z0 - length;
      const bool obstacle = is_obstacle(rng);
      map.insertReading({x, y, z0}, {x, y, z1},
                        obstacle ? ReadingKind::kObstacle : ReadingKind::kOutOfRange);
      const auto start_z = static_cast<float>(z0);
      const auto end_z = static_cast<float>(z1);
      if (obstacle) {
        const Volume hit = makeVolume(end_z - 0.5f, end_z + 0.5f);
        insert_into(positive[c], VolumeRun(&hit, 1), {}, {});
        const Volume free = makeVolume(start_z, z0 < z1 ? hit.bottom : hit.top);
        insert_into(negative[c], VolumeRun(&free, std::fabs(z0 - z1) > 1.0 ? 1 : 0), positive[c],
                    free_space_rules);
      } else {
        const Volume free = makeVolume(start_z, end_z);
        insert_into(negative[c], VolumeRun(&free, 1), positive[c], free_space_rules);
      }
      const CellVolumes held = map.cellVolumes({c % 2, c / 2});
      ASSERT_TRUE(sameBits(held.positive, positive[c]))
          << "positive list of cell " << c << ", step " << step;
      ASSERT_TRUE(sameBits(held.negative, negative[c]))
          << "negative list of cell " << c << ", step " << step;
      if (step % 500 == 499) {
        // Decay by 1/2: exact in float, so the rules' masses halve exactly too (Sec. III-E), and
        // the map rescales a tile's masses when it next writes to it.
        map.decay(0.5);
        for (auto* lists : {&positive, &negative}) {
          for (std::vector<Volume>& list : *lists) {
            for (Volume& v : list) v.mass *= 0.5f;
          }
        }
      }
    }
    std::size_t most_positive = 0;
    std::size_t most_negative = 0;
    for (int c = 0; c < 4; ++c) {
      most_positive = std::max(most_positive, positive[c].size());
      most_negative = std::max(most_negative, negative[c].size());
    }
    EXPECT_GE(most_positive, 3u);  // the lists did hold several volumes
    EXPECT_GE(most_negative, 2u);
  }
}

TEST(Insertion, NewVolumesBesideAColumnsVolumesAreMergedAsTheRulesSay) {
  // A vertical ray through one cell, beside volumes already there (free ones split at an
  // obstacle, Sec. V.C): the cell must hold what ListMerger gives, bit for bit, whether its free
  // volume grows the run it reaches (overlapping it, across a gap of eq. 8, past both of its
  // ends), bridges two runs, reaches past a piece into the next or across an obstacle, or its
  // volumes lie apart from all (near, but more than kMaxMergeGap away).
  ModelRules rules = ModelRules::paper();
  rules.split_free_space_at_obstacles = true;
  struct Case {
    const char* name;
    CellVolumes given;
    float z0;
    float z1;
    ReadingKind kind;
  };
  constexpr ReadingKind kFreeReading = ReadingKind::kOutOfRange;
  constexpr ReadingKind kHit = ReadingKind::kObstacle;
  const CellVolumes pieces{{{3, 4, 1}}, {{1, 3, 2}, {3, 4, 1}, {4, 6, 2}}};
  const std::vector<Case> cases{
      {"grows a volume upwards", {{}, {{0, 2, 3}}}, 1.5f, 4.0f, kFreeReading},
      {"across a gap below", {{}, {{2, 4, 3}}}, 0.25f, 1.5f, kFreeReading},
      {"across a gap above", {{}, {{2, 4, 3}}}, 4.5f, 6.0f, kFreeReading},
      {"past both ends of a volume", {{}, {{2, 4, 3}}}, 1.0f, 5.0f, kFreeReading},
      {"bridges two runs", {{}, {{0, 2, 2}, {3.5f, 5, 1.5f}}}, 2.25f, 3.25f, kFreeReading},
      {"across a gap up to the next run", {{}, {{0, 2, 2}, {4, 5, 1}}}, 2.5f, 3.5f, kFreeReading},
      {"grows the piece below an obstacle", pieces, 0.0f, 2.5f, kFreeReading},
      {"grows the piece above an obstacle", pieces, 5.0f, 7.5f, kFreeReading},
      {"past both ends of a run of pieces", pieces, -1.0f, 8.0f, kFreeReading},
      {"into the next piece from below", pieces, -0.5f, 3.5f, kFreeReading},
      {"into the next piece from above", pieces, 3.5f, 7.0f, kFreeReading},
      {"grows an obstacle's piece",
       {{{0, 1, 1}}, {{0, 1, 1}, {1, 3, 2}}},
       -2.0f,
       0.5f,
       kFreeReading},
      {"over an obstacle beyond the run", {{{5, 6, 1}}, {{1, 3, 2}}}, 2.0f, 5.5f, kFreeReading},
      {"across an obstacle", {{{2, 3, 1}}, {}}, 0.0f, 5.0f, kFreeReading},
      {"from an obstacle's top", {{{0, 1, 1}}, {}}, 1.0f, 4.0f, kFreeReading},
      {"a little more than a gap above", {{{0, 1, 1}}, {{1, 3, 2}}}, 4.25f, 6.0f, kFreeReading},
      {"a hit near an obstacle", {{{2, 3, 1}}, {}}, 8.0f, 4.25f, kHit},
      {"a hit on an obstacle's top", {{{2, 3, 1}}, {}}, 8.0f, 3.5f, kHit},
      {"a hit a little more than a gap away", {{{2, 3, 1}}, {}}, 8.0f, 4.75f, kHit},
      {"a hit near free space", {{{0, 1, 1}}, {{1, 3, 2}}}, 3.5f, 6.0f, kHit},
      {"a hit above everything", {{{0, 1, 1}}, {{1, 3, 2}}}, 8.0f, 8.6f, kHit}};
  ListMerger merger;
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    Map map(unitConfig(10000.0, rules));
    map.setCellVolumes({0, 0}, c.given);
    map.insertReading({0.5, 0.5, c.z0}, {0.5, 0.5, c.z1}, c.kind);
    // The reading's volumes (Sec. III-B.2): a hit's of eq. (5) and the free space up to it.
    std::vector<Volume> hits;
    std::vector<Volume> free;
    if (c.kind == kHit) {
      hits.push_back(makeVolume(c.z1 - 0.5f, c.z1 + 0.5f));
      if (std::fabs(c.z0 - c.z1) > 1.0f) {
        free.push_back(makeVolume(c.z0, c.z0 < c.z1 ? hits[0].bottom : hits[0].top));
      }
    } else {
      free.push_back(makeVolume(c.z0, c.z1));
    }
    CellVolumes expected;
    merger.merge(c.given.positive, hits, {}, {}, 1.0f, expected.positive);
    merger.merge(c.given.negative, free, expected.positive, FreeSpaceRules{true, false}, 1.0f,
                 expected.negative);
    const CellVolumes held = map.cellVolumes({0, 0});
    EXPECT_TRUE(sameBits(held.positive, expected.positive));
    EXPECT_TRUE(sameBits(held.negative, expected.negative));
  }
}

/// The model's rules the properties below hold for: the paper's, the defaults, and each
/// default rule alone.
std::vector<ModelRules> everyRuleSet() {
  std::vector<ModelRules> sets{ModelRules::paper(), ModelRules{}};
  ModelRules clip = ModelRules::paper();
  clip.clip_free_space_at_hits = true;
  ModelRules per_scan = ModelRules::paper();
  per_scan.mass_counting = MassCounting::kPerScan;
  ModelRules split = ModelRules::paper();
  split.split_free_space_at_obstacles = true;
  sets.insert(sets.end(), {clip, per_scan, split});
  return sets;
}

std::string describe(const ModelRules& rules) {
  std::ostringstream text;
  text << "clip " << rules.clip_free_space_at_hits << ", per scan "
       << (rules.mass_counting == MassCounting::kPerScan) << ", split "
       << rules.split_free_space_at_obstacles;
  return text.str();
}

/// Insertions walking every reading's ray, one ray per end voxel and one path per end column
/// (FreeSpaceRays), each with unbounded evidence and with InsertionConfig::evidence_limit 3
/// (reached within the tests' scans); each scan a group of its own, as the references make them
/// (hit_memory_scans 0: the Rules.HitMemory tests check the scan groups).
std::vector<InsertionConfig> everyRayChoice() {
  std::vector<InsertionConfig> choices;
  for (FreeSpaceRays rays : {FreeSpaceRays::kEveryReading, FreeSpaceRays::kOnePerEndVoxel,
                             FreeSpaceRays::kOnePathPerEndColumn}) {
    for (double evidence_limit : {std::numeric_limits<double>::infinity(), 3.0}) {
      InsertionConfig insertion;
      insertion.hit_memory_scans = 0;
      insertion.free_space_rays = rays;
      insertion.evidence_limit = evidence_limit;
      choices.push_back(insertion);
    }
  }
  return choices;
}

std::string describe(const InsertionConfig& insertion) {
  const char* rays[] = {", every reading's ray", ", one ray per end voxel",
                        ", one path per end column"};
  return std::string(rays[static_cast<int>(insertion.free_space_rays)]) +
         (std::isinf(insertion.evidence_limit) ? "" : ", evidence limit 3");
}

/// Scans from a few origins over about 8 x 8 tiles, with hits near each other (so that columns
/// receive hits and free space of the same scan) and far.
std::vector<Scan> testScans(unsigned seed) {
  std::mt19937 rng(seed);
  return {test::randomScan(rng, {0.0, 0.0, 0.0}, 5000, 1500, 12.0),
          test::randomScan(rng, {-5.5, 3.25, 1.0}, 1500, 500, 4.0),
          test::randomScan(rng, {4.0, -3.0, -1.0}, 1500, 500, 12.0),
          test::randomScan(rng, {0.2, 0.1, 0.3}, 3000, 0, 3.0)};
}

TEST(Insertion, TheMapDependsOnTheSetOfReadingsNotTheirOrder) {
  MapConfig map_config;
  map_config.resolution = 0.25;
  for (const ModelRules& rules : everyRuleSet()) {
    SCOPED_TRACE(describe(rules));
    map_config.rules = rules;
    Map in_order(map_config);
    Map shuffled(map_config);
    std::mt19937 rng(3);
    for (Scan scan : testScans(21)) {
      in_order.insertScan(scan);
      std::shuffle(scan.hits.begin(), scan.hits.end(), rng);
      std::shuffle(scan.out_of_range.begin(), scan.out_of_range.end(), rng);
      shuffled.insertScan(scan);
    }
    EXPECT_TRUE(test::sameVolumes(allVolumes(shuffled), allVolumes(in_order)));
    EXPECT_TRUE(test::mapSatisfiesConstraints(in_order));
  }
}

TEST(Insertion, ThreadsBuildTheSameMap) {
  // Scans into maps built with 1 to 4 threads: identical volumes, bit for bit.
  MapConfig map_config;
  map_config.resolution = 0.25;
  const std::vector<Scan> scans = testScans(99);
  for (const ModelRules& rules : {ModelRules::paper(), ModelRules{}}) {
    SCOPED_TRACE(describe(rules));
    map_config.rules = rules;
    std::vector<std::vector<test::VolumeRecord>> maps;
    std::vector<CellRange> bounds;
    for (int threads = 1; threads <= 4; ++threads) {
      Map map(map_config);
      InsertionConfig config;
      config.insertion_threads = threads;
      for (const Scan& scan : scans) map.insertScan(scan, config);
      maps.push_back(allVolumes(map));
      bounds.push_back(map.bounds());
    }
    EXPECT_LT(bounds[0].min.x, -40);
    EXPECT_LT(bounds[0].min.y, -40);
    for (int threads = 2; threads <= 4; ++threads) {
      EXPECT_TRUE(test::sameVolumes(maps[threads - 1], maps[0])) << threads << " threads";
      EXPECT_EQ(bounds[threads - 1].min, bounds[0].min);
      EXPECT_EQ(bounds[threads - 1].max, bounds[0].max);
    }
  }
}

TEST(Insertion, ThreadsSplittingACamerasFieldOfViewBuildTheSameMap) {
  // Threads share a scan's readings by their direction around its origin. A camera looking along
  // +x (where the directions' order wraps round), a fan seen almost edge-on, a vertical ray and
  // readings that are refused (not finite, at the origin, beyond max_coordinate), each scan with
  // 1 to 4 threads: the same volumes bit for bit, every reading counted once.
  MapConfig map_config;
  map_config.resolution = 0.1;
  map_config.max_coordinate = 50.0;
  Scan camera;
  camera.origin = {0.25, -0.125, 1.0};  // exact in float: a hit there has length 0
  for (int row = -20; row <= 20; ++row) {
    for (int column = -30; column <= 30; ++column) {
      const double depth = 2.0 + 0.05 * ((row * 7 + column * 3) % 11);
      const Eigen::Vector3d ray(depth, depth * column / 50.0, depth * row / 60.0);
      const Eigen::Vector3f end = (camera.origin + ray).cast<float>();
      ((row + column) % 9 == 0 ? camera.out_of_range : camera.hits).push_back(end);
    }
  }
  camera.hits.push_back({0.25f, -0.125f, 0.25f});  // straight down: no direction in xy
  camera.hits.push_back(camera.origin.cast<float>());
  camera.hits.push_back({std::numeric_limits<float>::quiet_NaN(), 0.0f, 0.0f});
  camera.hits.push_back({80.0f, 0.0f, 0.0f});
  Scan edge_on;
  edge_on.origin = {-1.0, 2.0, 0.5};
  for (int k = 0; k < 400; ++k) {
    edge_on.hits.push_back({static_cast<float>(-1.0 + 6.0 * k / 400.0), 2.05f, 0.5f});
  }
  const std::size_t num_readings = camera.hits.size() + camera.out_of_range.size() +
                                   edge_on.hits.size() + edge_on.out_of_range.size();
  InsertionConfig truncating;
  truncating.max_range = 2.2;
  InsertionConfig ignoring_out_of_range;
  ignoring_out_of_range.insert_out_of_range = false;
  for (const InsertionConfig& insertion : {InsertionConfig{}, truncating, ignoring_out_of_range}) {
    for (const ModelRules& rules : {ModelRules::paper(), ModelRules{}}) {
      SCOPED_TRACE(describe(rules));
      SCOPED_TRACE("max_range " + std::to_string(insertion.max_range) + ", insert_out_of_range " +
                   std::to_string(insertion.insert_out_of_range));
      map_config.rules = rules;
      std::vector<std::vector<test::VolumeRecord>> maps;
      std::vector<InsertionResult> results;
      for (int threads = 1; threads <= 4; ++threads) {
        Map map(map_config);
        InsertionConfig config = insertion;
        config.insertion_threads = threads;
        InsertionResult result = map.insertScan(camera, config);
        result += map.insertScan(edge_on, config);
        maps.push_back(allVolumes(map));
        results.push_back(result);
      }
      EXPECT_EQ(results[0].rejected_non_finite, 1u);
      EXPECT_EQ(results[0].rejected_too_close, 1u);
      EXPECT_EQ(results[0].rejected_out_of_bounds, 1u);
      EXPECT_EQ(results[0].truncated_to_max_range > 0, insertion.max_range < 10.0);
      EXPECT_EQ(results[0].ignored_out_of_range > 0, !insertion.insert_out_of_range);
      for (int threads = 1; threads <= 4; ++threads) {
        const InsertionResult& r = results[threads - 1];
        EXPECT_EQ(r.inserted() + r.rejected(), num_readings) << threads << " threads";
        EXPECT_TRUE(test::sameVolumes(maps[threads - 1], maps[0])) << threads << " threads";
        EXPECT_EQ(r.obstacle_readings, results[0].obstacle_readings) << threads << " threads";
        EXPECT_EQ(r.out_of_range_readings, results[0].out_of_range_readings);
        EXPECT_EQ(r.truncated_to_max_range, results[0].truncated_to_max_range);
        EXPECT_EQ(r.rejected_non_finite, results[0].rejected_non_finite);
        EXPECT_EQ(r.rejected_too_close, results[0].rejected_too_close);
        EXPECT_EQ(r.rejected_out_of_bounds, results[0].rejected_out_of_bounds);
        EXPECT_EQ(r.ignored_out_of_range, results[0].ignored_out_of_range);
      }
    }
  }
}

TEST(Insertion, AReadingIsTheScanOfOneReading) {
  for (const ModelRules& rules : everyRuleSet()) {
    SCOPED_TRACE(describe(rules));
    Map by_reading(unitConfig(10000.0, rules));
    Map by_scan(unitConfig(10000.0, rules));
    std::mt19937 rng(8);
    for (int k = 0; k < 300; ++k) {
      const Eigen::Vector3d origin = test::randomPoint(rng, 10.0, 2.0);
      const Eigen::Vector3f end = test::randomPoint(rng, 10.0, 2.0).cast<float>();
      const bool obstacle = k % 3 != 0;
      by_reading.insertReading(origin, end.cast<double>(),
                               obstacle ? ReadingKind::kObstacle : ReadingKind::kOutOfRange);
      Scan scan;
      scan.origin = origin;
      (obstacle ? scan.hits : scan.out_of_range).push_back(end);
      by_scan.insertScan(scan);
    }
    EXPECT_TRUE(test::sameVolumes(allVolumes(by_reading), allVolumes(by_scan)));
  }
}

TEST(Insertion, PreparingOutsideTheMapAndApplyingBuildTheSameMap) {
  // ScanUpdate::prepare reads nothing of the map: a server prepares outside its lock.
  MapConfig map_config;
  map_config.resolution = 0.25;
  Map direct(map_config);
  Map two_phases(map_config);
  ScanUpdate update;
  for (const Scan& scan : testScans(4)) {
    const InsertionResult expected = direct.insertScan(scan);
    update.prepare(scan, map_config, {});
    EXPECT_EQ(update.result().inserted(), expected.inserted());
    const InsertionResult applied = two_phases.apply(update);
    EXPECT_EQ(applied.obstacle_readings, expected.obstacle_readings);
  }
  EXPECT_TRUE(test::sameVolumes(allVolumes(two_phases), allVolumes(direct)));
  // An update prepared for another configuration is refused, the map untouched.
  MapConfig other = map_config;
  other.resolution = 0.5;
  update.prepare(testScans(5)[0], other, {});
  const std::uint64_t revision = two_phases.revision();
  EXPECT_THROW(two_phases.apply(update), ConfigError);
  EXPECT_EQ(two_phases.revision(), revision);
  other = map_config;
  other.rules = ModelRules::paper();
  update.prepare(testScans(5)[0], other, {});
  EXPECT_THROW(two_phases.apply(update), ConfigError);
}

TEST(Insertion, OneUpdateAppliedToMapsInTurnBuildsEachAsItsOwnInsertionWould) {
  // An update keeps its working memory from scan to scan, whichever map it is applied to and
  // with however many threads: nothing of one application may reach the next (the cells a scan
  // gave their first volume among them, which make the map's bounds).
  MapConfig map_config;
  map_config.resolution = 0.25;
  Map near(map_config), far(map_config), near_direct(map_config), far_direct(map_config);
  ScanUpdate update;
  std::mt19937 rng(11);
  for (int k = 0; k < 4; ++k) {
    const Scan near_scan = test::randomScan(rng, {0.0, 0.0, 0.0}, 1500, 300, 6.0);
    const Scan far_scan = test::randomScan(rng, {60.0, -40.0, 2.0}, 1500, 300, 6.0);
    InsertionConfig insertion;
    insertion.insertion_threads = 1 + k % 3;
    update.prepare(near_scan, map_config, insertion);
    near.apply(update);
    insertion.insertion_threads = 1 + (k + 1) % 3;
    update.prepare(far_scan, map_config, insertion);
    far.apply(update);
    near_direct.insertScan(near_scan);
    far_direct.insertScan(far_scan);
  }
  EXPECT_TRUE(test::sameVolumes(allVolumes(near), allVolumes(near_direct)));
  EXPECT_TRUE(test::sameVolumes(allVolumes(far), allVolumes(far_direct)));
  for (const auto& [map, direct] : {std::pair<const Map*, const Map*>{&near, &near_direct},
                                    std::pair<const Map*, const Map*>{&far, &far_direct}}) {
    EXPECT_EQ(map->bounds().min.x, direct->bounds().min.x);
    EXPECT_EQ(map->bounds().min.y, direct->bounds().min.y);
    EXPECT_EQ(map->bounds().max.x, direct->bounds().max.x);
    EXPECT_EQ(map->bounds().max.y, direct->bounds().max.y);
  }
}

TEST(Insertion, EveryRuleSetEqualsThePlainReference) {
  // The map against test::ReferenceModel, scan after scan: the scratch tiles, the joins, the
  // shortcuts and tiles written in place change nothing the rules decide.
  for (const ModelRules& rules : everyRuleSet()) {
    for (const InsertionConfig& insertion : everyRayChoice()) {
      SCOPED_TRACE(describe(rules) + describe(insertion));
      test::MapBesideReference maps(MapConfig{0.25, 10000.0, rules});
      std::vector<Scan> scans = testScans(17);
      // Dense: about 8 readings in a voxel, most voxels walked along one ray.
      std::mt19937 rng(4);
      scans.push_back(test::randomScan(rng, {0.1, 0.2, 0.3}, 4000, 1000, 0.8));
      for (const Scan& scan : scans) ASSERT_TRUE(maps.insert(scan, insertion));
      EXPECT_TRUE(test::mapSatisfiesConstraints(maps.map));
    }
  }
}

/// A scan of a planar laser at `height` (m) from `origin`'s xy: `beams` level readings over 360
/// degrees at random ranges up to 6 m, every fifth without a return, and every seventh rising by
/// `rise` per metre along its main axis (x or y).
Scan planarLaserScan(std::mt19937& rng, const Eigen::Vector2d& origin, double height, int beams,
                     double rise) {
  Scan scan;
  scan.origin = {origin.x(), origin.y(), height};
  std::uniform_real_distribution<double> range(0.3, 6.0);
  for (int k = 0; k < beams; ++k) {
    const double angle = 2.0 * M_PI * k / beams;
    Eigen::Vector3d end =
        scan.origin + range(rng) * Eigen::Vector3d(std::cos(angle), std::sin(angle), 0.0);
    if (k % 7 == 0) {
      end.z() += rise * std::max(std::fabs(end.x() - origin.x()), std::fabs(end.y() - origin.y()));
    }
    (k % 5 == 0 ? scan.out_of_range : scan.hits).push_back(end.cast<float>());
  }
  return scan;
}

TEST(Insertion, LevelAndShallowRaysEqualThePlainReference) {
  // A 2D laser's rays are level: each enters and leaves every cell at one height. Rays that rise
  // less than half a cell per cell cross every cell lower than one (eq. 6 lifts each crossing).
  // Beside them, rays rising by a hair, by just under and just over half a cell a cell, and by
  // more than a cell a cell (some crossings higher than one). At heights on a cell boundary, just
  // off it and far from it, with and without negative zero, and near 2^20 cells, the map must equal
  // test::ReferenceModel, which makes every cell's volume from its entry and exit heights (eq. 6).
  std::mt19937 rng(5);
  for (const ModelRules& rules : everyRuleSet()) {
    for (const InsertionConfig& insertion : everyRayChoice()) {
      // One ray per end voxel walks the rays one path per end column walks unless two voxels of
      // 4 readings share a column, which these planar scans' 121 beams at random ranges hardly
      // give: not run twice in the longest test under the sanitizers (the others run all three).
      if (insertion.free_space_rays == FreeSpaceRays::kOnePerEndVoxel) continue;
      SCOPED_TRACE(describe(rules) + describe(insertion));
      test::MapBesideReference maps(MapConfig{0.05, 60000.0, rules});
      for (const double height : {0.3, 0.025, 0.02500001, -0.0, 1.7e-8, -2.4, 52428.0, -52429.0}) {
        for (const double rise : {0.0, 1e-7, 0.499, 0.501, 1.5}) {
          const Eigen::Vector2d origin(std::uniform_real_distribution<double>(-1.0, 1.0)(rng),
                                       std::uniform_real_distribution<double>(-1.0, 1.0)(rng));
          ASSERT_TRUE(maps.insert(planarLaserScan(rng, origin, height, 121, rise), insertion))
              << "height " << height << ", rise " << rise;
        }
      }
      EXPECT_TRUE(test::mapSatisfiesConstraints(maps.map));
    }
  }
}

TEST(Insertion, ColumnsCrossedAtManyHeightsEqualThePlainReference) {
  // A rotating lidar's beams cross a column far from the sensor at as many heights, too far apart
  // to join: one scan gives such a column dozens of free intervals, which the scan's scratch
  // keeps in runs of one arena that grow (8, 16, 32, 64 intervals) and move, their old room
  // reused by other columns' runs. Here a fan of 41 beams in a vertical plane (each rising 0.15 m
  // a metre more than the one below), at five azimuths, hits and readings without a return, in a
  // shuffled order (a beam meets a column below, above or between the intervals it holds), from
  // three origins: the map must equal test::ReferenceModel's under every rule set (masses
  // counted per scan and per reading).
  std::mt19937 rng(8);
  for (const ModelRules& rules : everyRuleSet()) {
    for (const InsertionConfig& insertion : everyRayChoice()) {
      SCOPED_TRACE(describe(rules) + describe(insertion));
      test::MapBesideReference maps(MapConfig{0.25, 10000.0, rules});
      for (int k = 0; k < 3; ++k) {
        Scan scan;
        scan.origin = {0.1 * k, -0.05 * k, 1.0 + 0.2 * k};
        std::uniform_real_distribution<double> range(6.0, 8.0);
        for (int azimuth = 0; azimuth < 5; ++azimuth) {
          const double angle = 0.02 * azimuth + 0.3 * k;
          for (int beam = -20; beam <= 20; ++beam) {
            const double distance = range(rng);
            const Eigen::Vector3d end =
                scan.origin +
                distance * Eigen::Vector3d(std::cos(angle), std::sin(angle), 0.15 * beam);
            (beam % 6 == 0 ? scan.out_of_range : scan.hits).push_back(end.cast<float>());
          }
        }
        std::shuffle(scan.hits.begin(), scan.hits.end(), rng);
        ASSERT_TRUE(maps.insert(scan, insertion)) << "scan " << k;
      }
      EXPECT_TRUE(test::mapSatisfiesConstraints(maps.map));
    }
  }
}

TEST(Insertion, ThreadsBuildTheSameMapFromLevelScans) {
  // A level scan's threads keep one bit a cell for its one free volume (its readings at its
  // origin's height, in float as in double: 0.375 m). A scan with a few rising rays in one
  // direction has a thread whose readings are not all level beside threads whose are, their parts
  // joined in the columns near the origin that both reach. Hits within and beyond max_range, and
  // readings without a return freed up to out_of_range_free_length (both truncate level rays).
  // With 1 to 4 threads: the same volumes, bit for bit, as test::ReferenceModel's.
  InsertionConfig truncating;
  truncating.max_range = 2.5;
  for (const InsertionConfig& insertion : {InsertionConfig{}, truncating}) {
    for (const ModelRules& rules : {ModelRules::paper(), ModelRules{}}) {
      SCOPED_TRACE(describe(rules) + ", max_range " + std::to_string(insertion.max_range));
      std::vector<Scan> scans;
      std::mt19937 rng(12);
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector2d origin(std::uniform_real_distribution<double>(-1.0, 1.0)(rng),
                                     std::uniform_real_distribution<double>(-1.0, 1.0)(rng));
        scans.push_back(planarLaserScan(rng, origin, 0.375, 240, 0.0));
      }
      for (int k = 0; k < 6; ++k) {  // rising rays within 0.1 rad of +x, in the second scan
        const Eigen::Vector3d ray(2.0 + 0.5 * k, 0.04 * k, 0.1 + 0.25 * k);
        scans[1].hits.push_back((scans[1].origin + ray).cast<float>());
      }
      const MapConfig map_config{0.05, 60000.0, rules};
      test::ReferenceModel reference(map_config);
      for (const Scan& scan : scans) reference.insertScan(scan, insertion);
      for (int threads = 1; threads <= 4; ++threads) {
        Map map(map_config);
        InsertionConfig config = insertion;
        config.insertion_threads = threads;
        for (const Scan& scan : scans) map.insertScan(scan, config);
        EXPECT_TRUE(test::sameAsReference(map, reference)) << threads << " threads";
      }
    }
  }
}

TEST(Insertion, ATileRewrittenForSomeCellsKeepsItsOtherCells) {
  // A tile is rebuilt when some of its lists change length; its other cells are copied in runs.
  // Cells at the ends of the words of a tile's bitmap (local indices 0, 63, 64, 127, 128, 191,
  // 192, 255 of the 16 x 16 cells), then some of them changed, a new cell between them, and a
  // cell of 300 positive volumes (a tile stored with wide counts): against the plain reference
  // after every reading.
  const std::vector<std::pair<int, int>> word_ends = {{0, 0}, {15, 3},  {0, 4},  {15, 7},
                                                      {0, 8}, {15, 11}, {0, 12}, {15, 15}};
  for (const ModelRules& rules : {ModelRules::paper(), ModelRules{}}) {
    SCOPED_TRACE(describe(rules));
    test::MapBesideReference maps(test::unitConfig(10000.0, rules));
    // A vertical reading in cell (x, y) from height `from` down (or up) to a hit at `to`.
    auto vertical = [&](int x, int y, double from, double to) {
      Scan scan;
      scan.origin = {x + 0.5, y + 0.5, from};
      scan.hits.push_back(
          {static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f, static_cast<float>(to)});
      return maps.insert(scan);
    };
    for (const auto& [x, y] : word_ends) ASSERT_TRUE(vertical(x, y, 0.5, 5.5));
    for (const auto& [x, y] : {word_ends[1], word_ends[2], word_ends[5], word_ends[6]}) {
      ASSERT_TRUE(vertical(x, y, 20.5, 30.5));  // a second positive and negative volume
    }
    ASSERT_TRUE(vertical(4, 6, 0.5, 2.5));  // local 100: a new cell amid the others
    for (int k = 0; k < 300; ++k) ASSERT_TRUE(vertical(7, 9, 1000.5, 40.0 + 3.0 * k));
    EXPECT_EQ(maps.map.cellVolumes({7, 9}).positive.size(), 300u);
    for (const auto& [x, y] : word_ends) ASSERT_TRUE(vertical(x, y, 60.5, 70.5));
    EXPECT_TRUE(test::mapSatisfiesConstraints(maps.map));
  }
}

// ---- The model's rules
// ---------------------------------------------------------------------------

/// A scan along +x at height 0.5 in cells of 1 m: A hits cell (5, 0), B passes through it at
/// A's height on its way to cell (8, 0), C passes above it.
Scan scanThroughAHit() {
  Scan scan;
  scan.origin = {0.5, 0.5, 0.5};
  scan.hits.push_back({5.5f, 0.5f, 0.5f});          // A: positive [0, 1] in cell (5, 0)
  scan.hits.push_back({8.5f, 0.5f, 0.5f});          // B: crosses cell (5, 0) at z = 0.5
  scan.out_of_range.push_back({9.5f, 0.5f, 9.5f});  // C: crosses cell (5, 0) at z in [5, 6]
  return scan;
}

TEST(Rules, AScansFreeSpaceIsClippedAroundItsOwnHits) {
  // Sec. V.B: B's free space in A's cell is where A hit, and goes; C's is above, and stays.
  ModelRules rules = ModelRules::paper();
  rules.clip_free_space_at_hits = true;
  Map map(unitConfig(10000.0, rules));
  map.insertScan(scanThroughAHit());
  const CellVolumes cell = map.cellVolumes({5, 0});
  ASSERT_EQ(cell.positive.size(), 1u);
  EXPECT_TRUE(volumeIs(cell.positive[0], 0.0, 1.0, 1.0));
  ASSERT_EQ(cell.negative.size(), 1u);
  EXPECT_TRUE(volumeIs(cell.negative[0], 5.0, 6.0, 1.0));
  EXPECT_EQ(*map.occupancy({5.5, 0.5, 0.5}).probability, 1.0f);
  // Cells without a hit of this scan keep all their free space; B's own hit stays.
  EXPECT_EQ(map.cellVolumes({4, 0}).negative.size(), 2u);
  EXPECT_EQ(map.cellVolumes({8, 0}).positive.size(), 1u);
  // The paper's model frees A's hit with B's ray: p = 1/2 there.
  Map paper(unitConfig());
  paper.insertScan(scanThroughAHit());
  EXPECT_EQ(paper.cellVolumes({5, 0}).negative.size(), 2u);
  EXPECT_FLOAT_EQ(*paper.occupancy({5.5, 0.5, 0.5}).probability, 0.5f);
}

TEST(Rules, ClippingKeepsFreeSpaceBesideAHitAndDropsASliver) {
  ModelRules rules = ModelRules::paper();
  rules.clip_free_space_at_hits = true;
  Map map(unitConfig(10000.0, rules));
  // A steep hit straight up: V = [4.5, 5.5] and its padding [0.5, 4.5] touch without overlap,
  // so the padding stays whole.
  Scan up;
  up.origin = {0.5, 0.5, 0.5};
  up.hits.push_back({0.5f, 0.5f, 5.0f});
  map.insertScan(up);
  CellVolumes cell = map.cellVolumes({0, 0});
  ASSERT_EQ(cell.negative.size(), 1u);
  EXPECT_TRUE(volumeIs(cell.negative[0], 0.5, 4.5, 4.0));
  // Vertical rays in cell (3, 0): a hit at 2 (V = [1.5, 2.5], padding [0, 1.5]) and free space
  // to 1.8 and to 3. The scan's free space [0, 3] (mass 1.5 + 1.8 + 3) loses [1.5, 2.5] to the
  // hit; the part above it, [2.5, 3], is lower than a volume and dropped; [0, 1.5] keeps its
  // density: mass 6.3 / 2.
  Scan column;
  column.origin = {3.5, 0.5, 0.0};
  column.hits.push_back({3.5f, 0.5f, 2.0f});
  column.out_of_range.push_back({3.5f, 0.5f, 1.8f});
  column.out_of_range.push_back({3.5f, 0.5f, 3.0f});
  map.insertScan(column);
  cell = map.cellVolumes({3, 0});
  ASSERT_EQ(cell.positive.size(), 1u);
  EXPECT_TRUE(volumeIs(cell.positive[0], 1.5, 2.5, 1.0));
  ASSERT_EQ(cell.negative.size(), 1u);
  EXPECT_TRUE(volumeIs(cell.negative[0], 0.0, 1.5, 3.15));
  EXPECT_FALSE(map.occupancy({3.5, 0.5, 2.75}).known());
}

TEST(Rules, ClippingIsWithinOneScan) {
  // A later scan's free space clears an earlier scan's hit as in the paper (what lets a person
  // who walked away be forgotten): the hit's column gets free space at its height. Each scan a
  // group of its own (hit_memory_scans 0; with the default the line scans of a group keep it:
  // HitMemoryForgetsAfterItsScans...).
  Map map(unitConfig(10000.0, ModelRules{}));
  InsertionConfig own_hits_only;
  own_hits_only.hit_memory_scans = 0;
  Scan first;
  first.origin = {0.5, 0.5, 0.5};
  first.hits.push_back({3.5f, 0.5f, 0.5f});
  map.insertScan(first, own_hits_only);
  Scan second = first;
  second.hits = {{6.5f, 0.5f, 0.5f}};
  map.insertScan(second, own_hits_only);
  const PointOccupancy at_hit = map.occupancy({3.5, 0.5, 0.5});
  ASSERT_TRUE(at_hit.known());
  EXPECT_FLOAT_EQ(*at_hit.probability, 0.5f);  // one hit, one pass: each counted once
}

/// A scan from (0.5, 0.5, 0.5) of one hit at (3.5, 0.5, 0.5) (cell (3, 0), its volume [0, 1]).
Scan scanHittingCellThree() {
  Scan scan;
  scan.origin = {0.5, 0.5, 0.5};
  scan.hits.push_back({3.5f, 0.5f, 0.5f});
  return scan;
}

/// A level scan from the same origin whose ray passes through cell (3, 0) to a hit at 6.5.
Scan scanThroughCellThree() {
  Scan scan = scanHittingCellThree();
  scan.hits = {{6.5f, 0.5f, 0.5f}};
  return scan;
}

TEST(Rules, HitMemoryClipsTheNextScansFreeSpaceAroundTheHitsBeforeIt) {
  // Sec. V.B's scan groups (InsertionConfig::hit_memory_scans): the second scan's ray through the
  // first scan's hit adds no free space there while the first scan is within the memory; the
  // third scan's, one scan later, does (ClippingIsWithinOneScan: 0, a scan's own hits only).
  Map map(unitConfig(10000.0, ModelRules{}));
  InsertionConfig insertion;
  insertion.hit_memory_scans = 1;
  map.insertScan(scanHittingCellThree(), insertion);
  map.insertScan(scanThroughCellThree(), insertion);
  EXPECT_TRUE(map.cellVolumes({3, 0}).negative.empty());
  EXPECT_FLOAT_EQ(*map.occupancy({3.5, 0.5, 0.5}).probability, 1.0f);
  EXPECT_FALSE(map.cellVolumes({2, 0}).negative.empty());  // no hit there: freed as ever
  map.insertScan(scanThroughCellThree(), insertion);
  EXPECT_FLOAT_EQ(*map.occupancy({3.5, 0.5, 0.5}).probability, 0.5f);  // one hit, one pass
}

TEST(Rules, HitMemoryKeepsTheFreeSpaceAboveAndBelowARememberedHit) {
  // A steep ray through the column of the first scan's hit keeps its free space outside the
  // hit's volume [0, 1], as the clipping of a scan's own hits does: no free mass at the hit.
  Map map(unitConfig(10000.0, ModelRules{}));
  InsertionConfig insertion;
  insertion.hit_memory_scans = 2;
  map.insertScan(scanHittingCellThree(), insertion);
  Scan steep;
  steep.origin = {3.5, 0.5, 10.5};
  steep.hits = {{3.5f, 0.5f, -9.5f}};
  map.insertScan(steep, insertion);
  EXPECT_EQ(map.occupancy({3.5, 0.5, 5.5}).state(0.5), OccupancyState::kFree);
  EXPECT_EQ(map.occupancy({3.5, 0.5, -5.5}).state(0.5), OccupancyState::kFree);
  EXPECT_FLOAT_EQ(*map.occupancy({3.5, 0.5, 0.5}).probability, 1.0f);
}

TEST(Rules, HitMemoryForgetsAfterItsScansAfterAnInsertionWithoutItAndAfterClear) {
  // With 2 the hit clips the next two scans' free space, not the third's; an insertion with 0, a
  // scan that is not a line, or Map::clear, forgets the hits kept.
  auto passes_until_freed = [](auto between) {
    Map map(unitConfig(10000.0, ModelRules{}));
    InsertionConfig insertion;
    insertion.hit_memory_scans = 2;
    map.insertScan(scanHittingCellThree(), insertion);
    between(map);
    int passes = 0;
    while (map.cellVolumes({3, 0}).negative.empty() && passes < 5) {
      map.insertScan(scanThroughCellThree(), insertion);
      ++passes;
    }
    return passes;
  };
  EXPECT_EQ(passes_until_freed([](Map&) {}), 3);
  EXPECT_EQ(passes_until_freed([](Map& map) {
              InsertionConfig without;
              without.hit_memory_scans = 0;
              map.insertScan(Scan{{0.5, 0.5, 0.5}, {{0.5f, 5.5f, 0.5f}}, {}}, without);
            }),
            1);
  // A scan that is not a line (its readings in no one plane through its origin: a camera's, a
  // sweep's) is a group of its own: it forgets the line scans' hits.
  EXPECT_EQ(
      passes_until_freed([](Map& map) {
        InsertionConfig with_memory;
        with_memory.hit_memory_scans = 2;
        map.insertScan(
            Scan{{0.5, 0.5, 0.5}, {{0.5f, 5.5f, 0.5f}, {0.5f, 5.5f, 3.5f}, {4.5f, 4.5f, 0.5f}}, {}},
            with_memory);
      }),
      1);
  // A rejected reading (here the first) does not make a line of the others.
  EXPECT_EQ(
      passes_until_freed([](Map& map) {
        InsertionConfig with_memory;
        with_memory.hit_memory_scans = 2;
        const float nan = std::numeric_limits<float>::quiet_NaN();
        map.insertScan(
            Scan{{0.5, 0.5, 0.5},
                 {{nan, 0.5f, 0.5f}, {0.5f, 5.5f, 0.5f}, {0.5f, 5.5f, 3.5f}, {4.5f, 4.5f, 0.5f}},
                 {}},
            with_memory);
      }),
      1);
  // An insertion that inserts no reading (every one rejected) is no scan: the hits stay kept.
  EXPECT_EQ(passes_until_freed([](Map& map) {
              InsertionConfig without;
              without.hit_memory_scans = 0;
              const float nan = std::numeric_limits<float>::quiet_NaN();
              map.insertScan(Scan{{0.5, 0.5, 0.5}, {{nan, 0.5f, 0.5f}}, {}}, without);
            }),
            3);
  EXPECT_EQ(passes_until_freed([](Map& map) { map.clear(); }), 1);
}

TEST(Rules, HitMemoryNeedsClippingAtHits) {
  // Without Sec. V.B's clipping (clip_free_space_at_hits off) no hit clips free space, its own
  // or its group's: the second scan frees the first one's hit as with no memory.
  ModelRules rules;
  rules.clip_free_space_at_hits = false;
  Map map(unitConfig(10000.0, rules));
  InsertionConfig insertion;
  insertion.hit_memory_scans = 3;
  map.insertScan(scanHittingCellThree(), insertion);
  map.insertScan(scanThroughCellThree(), insertion);
  EXPECT_FLOAT_EQ(*map.occupancy({3.5, 0.5, 0.5}).probability, 0.5f);
}

/// A tilting laser's lines from (0.3, 0.2, 1.1): `lines` scans of 361 readings at random ranges,
/// each in the plane through the origin that holds the y axis and is tilted by a further 0.02 rad
/// about it, line by line.
std::vector<Scan> tiltingLaserLines(unsigned seed, int lines) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> range(1.0, 9.0);
  std::vector<Scan> scans;
  for (int line = 0; line < lines; ++line) {
    Scan scan;
    scan.origin = {0.3, 0.2, 1.1};
    const double tilt = -0.3 + 0.02 * line;
    const Eigen::Vector3d ahead(std::cos(tilt), 0.0, std::sin(tilt));
    for (int k = 0; k <= 360; ++k) {
      const double azimuth = (k - 180) * M_PI / 360.0;
      const Eigen::Vector3d direction =
          std::cos(azimuth) * ahead + std::sin(azimuth) * Eigen::Vector3d::UnitY();
      scan.hits.push_back((scan.origin + range(rng) * direction).cast<float>());
    }
    scans.push_back(scan);
  }
  return scans;
}

TEST(Rules, HitMemoryBuildsTheSameMapWithAnyThreads) {
  // The recent hits are read by every thread's tiles and recorded after the scan: 1 to 3
  // threads build the same map of a tilting laser's lines, which the memory changes.
  MapConfig map_config;
  map_config.resolution = 0.25;
  const std::vector<Scan> scans = tiltingLaserLines(7, 12);
  std::vector<std::vector<test::VolumeRecord>> maps;
  for (int threads = 1; threads <= 3; ++threads) {
    Map map(map_config);
    InsertionConfig insertion;
    insertion.insertion_threads = threads;
    insertion.hit_memory_scans = 2;
    for (const Scan& scan : scans) map.insertScan(scan, insertion);
    maps.push_back(allVolumes(map));
  }
  for (int threads = 2; threads <= 3; ++threads) {
    EXPECT_TRUE(test::sameVolumes(maps[threads - 1], maps[0])) << threads << " threads";
  }
  InsertionConfig without_memory;
  without_memory.hit_memory_scans = 0;
  Map without(map_config);
  for (const Scan& scan : scans) without.insertScan(scan, without_memory);
  EXPECT_FALSE(test::sameVolumes(allVolumes(without), maps[0]));
  // The lines are line scans; the same readings a hair off their plane are not, and each is then
  // a group of its own, as without the memory.
  InsertionConfig with_memory;
  with_memory.hit_memory_scans = 2;
  Map off_plane(map_config);
  for (Scan scan : scans) {
    scan.hits[90].z() += 0.01f;  // 1 cm: 0.04 cells, beyond a thousandth of one
    off_plane.insertScan(scan, with_memory);
  }
  Map off_plane_without(map_config);
  for (Scan scan : scans) {
    scan.hits[90].z() += 0.01f;
    off_plane_without.insertScan(scan, without_memory);
  }
  EXPECT_TRUE(test::sameVolumes(allVolumes(off_plane), allVolumes(off_plane_without)));
  // HitMemoryScope::kEveryScan groups them all the same.
  with_memory.hit_memory_scope = HitMemoryScope::kEveryScan;
  Map every_scan(map_config);
  for (Scan scan : scans) {
    scan.hits[90].z() += 0.01f;
    every_scan.insertScan(scan, with_memory);
  }
  EXPECT_FALSE(test::sameVolumes(allVolumes(every_scan), allVolumes(off_plane_without)));
}

TEST(Rules, PerScanAHeightCountsOncePerScan) {
  // 100 rays of one scan through cell (2, 0) at the same height, ending in cell (5, 0).
  Scan scan;
  scan.origin = {0.5, 0.5, 0.5};
  for (int k = 0; k < 100; ++k)
    scan.hits.push_back({5.5f, 0.5f + 0.001f * static_cast<float>(k), 0.5f});
  for (const MassCounting counting : {MassCounting::kPerScan, MassCounting::kPerReading}) {
    ModelRules rules = ModelRules::paper();
    rules.mass_counting = counting;
    Map map(unitConfig(10000.0, rules));
    map.insertScan(scan);
    map.insertScan(scan);
    const CellVolumes passed = map.cellVolumes({2, 0});
    ASSERT_EQ(passed.negative.size(), 1u);
    const CellVolumes hit = map.cellVolumes({5, 0});
    ASSERT_EQ(hit.positive.size(), 1u);
    // Per scan: density 1 per scan, 2 scans; per reading: 100 readings a scan.
    const float expected = counting == MassCounting::kPerScan ? 2.0f : 200.0f;
    EXPECT_FLOAT_EQ(passed.negative[0].density(), expected);
    EXPECT_NEAR(hit.positive[0].density(), expected, expected * 0.01f);
  }
}

TEST(Rules, PerScanTheScansFreeHeightsJoinAcrossGapsOfOne) {
  // Cell (2, 0) holds free space [0.5, 1.5] from an earlier scan. A scan then crosses it at
  // [-0.5, 0.5] and [1.5, 2.5]: per scan, the scan saw [-0.5, 2.5] at its vertical resolution
  // (the gap it leaves is 1), density 1 over it: 1 + 3 = 4. Per reading (the paper), eq. (7)
  // joins the three volumes, which touch: 1 + 1 + 1 = 3.
  Scan earlier;
  earlier.origin = {0.5, 0.5, 0.0};
  earlier.out_of_range.push_back({3.5f, 0.5f, 1.5f});  // z 0.75 to 1.25 in cell 2: [0.5, 1.5]
  Scan later = earlier;
  later.out_of_range = {{3.5f, 0.5f, 0.0f}, {3.5f, 0.5f, 3.0f}};  // [-0.5, 0.5], [1.5, 2.5]
  for (const MassCounting counting : {MassCounting::kPerScan, MassCounting::kPerReading}) {
    ModelRules rules = ModelRules::paper();
    rules.mass_counting = counting;
    Map map(unitConfig(10000.0, rules));
    map.insertScan(earlier);
    map.insertScan(later);
    const CellVolumes cell = map.cellVolumes({2, 0});
    ASSERT_EQ(cell.negative.size(), 1u);
    EXPECT_TRUE(
        volumeIs(cell.negative[0], -0.5, 2.5, counting == MassCounting::kPerScan ? 4.0 : 3.0));
  }
}

TEST(Rules, ARayWithoutAReturnFreesOnlyItsFirstMetres) {
  // out_of_range_free_length 5 m: a ray without a return 20 m long frees 5 m; a hit 20 m away
  // frees its whole ray; with the paper's rule (infinity) the ray without a return frees 20 m.
  for (const double free_length : {5.0, std::numeric_limits<double>::infinity()}) {
    ModelRules rules;
    rules.out_of_range_free_length = free_length;
    Map map(unitConfig(10000.0, rules));
    Scan scan;
    scan.origin = {0.5, 0.5, 0.5};
    scan.out_of_range.push_back({20.5f, 0.5f, 0.5f});
    scan.hits.push_back({0.5f, 20.5f, 0.5f});
    map.insertScan(scan);
    EXPECT_EQ(map.occupancy({4.5, 0.5, 0.5}).state(0.5), OccupancyState::kFree);
    EXPECT_EQ(map.occupancy({10.5, 0.5, 0.5}).known(), std::isinf(free_length));
    EXPECT_EQ(map.occupancy({0.5, 10.5, 0.5}).state(0.5), OccupancyState::kFree);
    EXPECT_EQ(map.occupancy({0.5, 20.5, 0.5}).state(0.5), OccupancyState::kOccupied);
  }
}

TEST(Rules, ARingOfLaserHitsStaysOccupied) {
  // 5 identical scans of 360 beams, every range 4 m, from a laser at (0, 0, 1), cells of 0.1 m:
  // the beams to neighbouring ring cells cross ring cells on their way. With the defaults every
  // ring point is occupied (the scan does not free its own hits); the paper's model loses some.
  Scan scan;
  scan.origin = {0.0, 0.0, 1.0};
  for (int beam = 0; beam < 360; ++beam) {
    const double angle = beam * M_PI / 180.0;
    scan.hits.push_back(Eigen::Vector3f(static_cast<float>(4.0 * std::cos(angle)),
                                        static_cast<float>(4.0 * std::sin(angle)), 1.0f));
  }
  auto occupied_on_ring = [&](const ModelRules& rules, double threshold) {
    MapConfig config;
    config.resolution = 0.1;
    config.rules = rules;
    Map map(config);
    for (int k = 0; k < 5; ++k) map.insertScan(scan);
    int occupied = 0;
    for (int k = 0; k < 60; ++k) {
      const double angle = (k + 0.5) * 2.0 * M_PI / 60.0;
      const Eigen::Vector3d point(4.0 * std::cos(angle), 4.0 * std::sin(angle), 1.0);
      occupied += map.occupancy(point).state(threshold) == OccupancyState::kOccupied;
      // The 2 m circle is free.
      EXPECT_EQ(map.occupancy(point / 2.0 + Eigen::Vector3d(0, 0, 0.5)).state(threshold),
                OccupancyState::kFree);
    }
    return occupied;
  };
  const int occupied = occupied_on_ring(ModelRules{}, kDefaultOccupancyThreshold);
  EXPECT_GE(occupied, 50);
  EXPECT_GE(occupied, occupied_on_ring(ModelRules::paper(), kPaperOccupancyThreshold));
}

}  // namespace
}  // namespace mvog
