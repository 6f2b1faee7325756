// The map as a whole: decay (Sec. III-E), growth and bounds (Sec. V.A), rejected readings,
// memory accounting (Table I), configuration checks and change tracking.
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "mvog/map.h"
#include "mvog/planning_config.h"
#include "test_util.h"

namespace mvog {
namespace {

using test::allVolumes;
using test::coarseRandomMap;
using test::kInf;
using test::kNaN;
using test::unitConfig;

/// Probabilities over the region of coarseRandomMap, bit for bit.
std::vector<std::uint32_t> probe(const Map& map) { return test::probabilityBits(map, 6.0, 3.0); }

std::size_t countKnown(const std::vector<std::uint32_t>& bits) {
  std::size_t known = 0;
  for (std::uint32_t b : bits) known += b != test::kUnknownBits;
  return known;
}

// ---- Decay (Sec. III-E) -------------------------------------------------------------------------

TEST(Decay, MultipliesEveryMassByTheFactor) {
  Map map = coarseRandomMap(1);
  const std::vector<CellIndex> cells = test::observedCells(map);
  std::vector<CellVolumes> before;
  for (const CellIndex& cell : cells) before.push_back(map.cellVolumes(cell));
  const auto expect_scaled = [&](double factor) {
    for (std::size_t k = 0; k < cells.size(); ++k) {
      const CellVolumes now = map.cellVolumes(cells[k]);
      ASSERT_EQ(now.positive.size(), before[k].positive.size());
      ASSERT_EQ(now.negative.size(), before[k].negative.size());
      for (const auto& [now_list, old_list] : {std::pair{&now.positive, &before[k].positive},
                                               std::pair{&now.negative, &before[k].negative}}) {
        for (std::size_t v = 0; v < now_list->size(); ++v) {
          ASSERT_EQ((*now_list)[v].bottom, (*old_list)[v].bottom);
          ASSERT_EQ((*now_list)[v].top, (*old_list)[v].top);
          ASSERT_FLOAT_EQ((*now_list)[v].mass, static_cast<float>((*old_list)[v].mass * factor));
        }
      }
    }
  };
  map.decay(0.5);
  expect_scaled(0.5);
  map.decay(0.9);
  expect_scaled(0.45);
  map.decay(1.0);
  expect_scaled(0.45);
}

TEST(Decay, ProbabilitiesAreUnchangedAfterManySteps) {
  for (double k_d : {0.5, 0.9, 0.999, 1e-10, 1e-300, std::numeric_limits<double>::denorm_min()}) {
    SCOPED_TRACE(::testing::Message() << "k_d = " << k_d);
    Map map = coarseRandomMap(2);
    const std::vector<std::uint32_t> before = probe(map);
    ASSERT_GT(countKnown(before), 1000u);
    for (int step = 0; step < 500; ++step) map.decay(k_d);
    EXPECT_TRUE(test::sameProbabilities(probe(map), before));  // bit for bit
    EXPECT_TRUE(test::mapSatisfiesConstraints(map));
  }
}

TEST(Decay, UntouchedCellsKeepTheirProbabilitiesWhileOthersAreUpdated) {
  // Decay steps interleaved with readings elsewhere (x > 25 m): the cells around the origin,
  // which receive no new reading, keep every probability bit for bit.
  Map map = coarseRandomMap(3);
  const std::vector<std::uint32_t> before = probe(map);
  std::mt19937 rng(4);
  for (int step = 0; step < 600; ++step) {
    map.decay(step % 2 == 0 ? 0.5 : 0.8);
    if (step % 20 == 0) map.insertScan(test::randomScan(rng, {30.0, 0.0, 0.0}, 200, 50, 5.0));
  }
  EXPECT_TRUE(test::sameProbabilities(probe(map), before));
  EXPECT_GT(map.bounds().max.x, 150);  // the readings went in, at x > 25 m
  EXPECT_TRUE(test::mapSatisfiesConstraints(map));
}

TEST(Decay, NewReadingsWeighMoreThanOldOnes) {
  // An obstacle seen once, then free space seen once through it, with and without a decay of 0.5
  // in between (s = 1). Vertical hit: V = [4.5, 5.5] mass 1, V' = [0, 4.5] mass 4.5.
  Map decayed(unitConfig());
  Map kept(unitConfig());
  for (Map* map : {&decayed, &kept})
    map->insertReading({0.5, 0.5, 0}, {0.5, 0.5, 5}, ReadingKind::kObstacle);
  decayed.decay(0.5);
  for (Map* map : {&decayed, &kept})
    map->insertReading({0.5, 0.5, 0}, {0.5, 0.5, 6}, ReadingKind::kOutOfRange);
  // Decayed: V mass 0.5; free [0, 6] = 0.5 * 4.5 + 6 = 8.25, rho- = 1.375;
  // p(5) = 0.5 / (0.5 + 1.375) = 0.2667. Kept: p(5) = 1 / (1 + 10.5 / 6) = 0.3636.
  const CellVolumes cell = decayed.cellVolumes({0, 0});
  ASSERT_EQ(cell.positive.size(), 1u);
  ASSERT_EQ(cell.negative.size(), 1u);
  EXPECT_TRUE(test::volumeIs(cell.positive[0], 4.5, 5.5, 0.5));
  EXPECT_TRUE(test::volumeIs(cell.negative[0], 0.0, 6.0, 8.25));
  const float p_decayed = decayed.occupancy({0.5, 0.5, 5.0}).probability.value();
  const float p_kept = kept.occupancy({0.5, 0.5, 5.0}).probability.value();
  EXPECT_NEAR(p_decayed, 0.5 / 1.875, 1e-6);
  EXPECT_NEAR(p_kept, 1.0 / 2.75, 1e-6);
  EXPECT_LT(p_decayed, p_kept);
  EXPECT_NEAR(decayed.occupancy({0.5, 0.5, 5.0}).positive_density, 0.5, 1e-6);
  EXPECT_NEAR(decayed.occupancy({0.5, 0.5, 5.0}).negative_density, 1.375, 1e-6);
}

TEST(Decay, LongDecayedReadingsGiveWayToNewOnes) {
  // After 500 halvings the old obstacle weighs 2^-500 of a new reading: one free reading makes
  // the point free, and the map stays valid. A tile no reading writes keeps its probabilities;
  // masses in the tile written, decayed below float range against the new ones, become 0.
  Map map(unitConfig());
  map.insertReading({0.5, 0.5, 0}, {0.5, 0.5, 5}, ReadingKind::kObstacle);
  map.insertReading({3.5, 0.5, 0}, {3.5, 0.5, 5}, ReadingKind::kObstacle);    // same tile
  map.insertReading({40.5, 0.5, 0}, {40.5, 0.5, 5}, ReadingKind::kObstacle);  // untouched below
  const PointOccupancy untouched = map.occupancy({40.5, 0.5, 5.0});
  for (int step = 0; step < 500; ++step) map.decay(0.5);
  map.insertReading({0.5, 0.5, 0}, {0.5, 0.5, 6}, ReadingKind::kOutOfRange);
  const PointOccupancy p = map.occupancy({0.5, 0.5, 5.0});
  ASSERT_TRUE(p.known());
  EXPECT_LT(*p.probability, 1e-6f);
  EXPECT_NEAR(p.negative_density, 1.0, 1e-6);
  EXPECT_EQ(map.occupancy({40.5, 0.5, 5.0}).probability, untouched.probability);
  EXPECT_FALSE(map.occupancy({3.5, 0.5, 5.0}).known());
  EXPECT_TRUE(test::mapSatisfiesConstraints(map));
  // Fresh readings get the masses of fresh readings.
  map.insertReading({-5.5, 0.5, 0}, {-5.5, 0.5, 5}, ReadingKind::kObstacle);
  const CellVolumes fresh = map.cellVolumes({-6, 0});
  ASSERT_EQ(fresh.positive.size(), 1u);
  EXPECT_TRUE(test::volumeIs(fresh.positive[0], 4.5, 5.5, 1.0));
}

TEST(Decay, SurvivesDecayBeyondAnyExponentRange) {
  // 20000 steps of the smallest positive double: some 2^24.4 binary orders of decay, beyond what
  // 32-bit exponents hold without rebasing. Probabilities stay bit for bit; readings added in the
  // middle and at the end get the masses of fresh readings.
  Map map = coarseRandomMap(10);
  const std::vector<std::uint32_t> before = probe(map);
  constexpr double kTiny = std::numeric_limits<double>::denorm_min();
  for (int step = 0; step < 10000; ++step) map.decay(kTiny);
  map.insertReading({30.5, 0.5, 0}, {30.5, 0.5, 1}, ReadingKind::kObstacle);
  for (int step = 0; step < 10000; ++step) map.decay(kTiny);
  EXPECT_TRUE(test::sameProbabilities(probe(map), before));
  map.insertReading({30.5, 0.5, 0}, {30.5, 0.5, 1}, ReadingKind::kObstacle);
  const CellVolumes cell = map.cellVolumes(map.cellAtPoint(30.5, 0.5));
  // s = 5: V = [4.5, 5.5] and V' = [0, 4.5] in grid units; the first reading's masses, decayed
  // by 2^-(2^23.4) since, vanished in the merge.
  ASSERT_EQ(cell.positive.size(), 1u);
  ASSERT_EQ(cell.negative.size(), 1u);
  EXPECT_TRUE(test::volumeIs(cell.positive[0], 4.5, 5.5, 1.0));
  EXPECT_TRUE(test::volumeIs(cell.negative[0], 0.0, 4.5, 4.5));
  EXPECT_TRUE(test::mapSatisfiesConstraints(map));
}

TEST(Decay, RefusesFactorsOutsideZeroOne) {
  Map map = coarseRandomMap(5);
  const std::vector<test::VolumeRecord> before = allVolumes(map);
  for (double k_d : {0.0, -0.5, 1.0000001, 2.0, kNaN, kInf, -kInf}) {
    try {
      map.decay(k_d);
      ADD_FAILURE() << "accepted k_d = " << k_d;
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("k_d"), std::string::npos) << e.what();
    }
  }
  EXPECT_TRUE(test::sameVolumes(allVolumes(map), before));
}

// ---- Growth, bounds and rejected readings
// ---------------------------------------------------------

TEST(Map, GrowsInAllFourDirections) {
  Map map(unitConfig());
  map.insertReading({0.5, 0.5, 0}, {3.5, 2.5, 1}, ReadingKind::kObstacle);
  const std::vector<test::VolumeRecord> first = allVolumes(map);
  EXPECT_EQ(map.bounds().min, (CellIndex{0, 0}));
  EXPECT_EQ(map.bounds().max, (CellIndex{3, 2}));
  const std::size_t tiles = map.memoryUsage().tiles;
  // Far readings in +x, -x, +y, -y, each from a sensor beside it.
  const std::vector<std::pair<Eigen::Vector3d, CellRange>> far{
      {{500.5, 0.5, 0}, {{0, 0}, {500, 2}}},
      {{-700.5, 1.5, 0}, {{-701, 0}, {500, 2}}},
      {{2.5, 900.5, 0}, {{-701, 0}, {500, 900}}},
      {{1.5, -300.5, 0}, {{-701, -301}, {500, 900}}}};
  for (const auto& [end, bounds] : far) {
    map.insertReading(end + Eigen::Vector3d(0.2, 0.2, 0), end, ReadingKind::kObstacle);
    EXPECT_EQ(map.bounds().min, bounds.min);
    EXPECT_EQ(map.bounds().max, bounds.max);
    EXPECT_EQ(map.cellVolumes(map.cellAtPoint(end.x(), end.y())).positive.size(), 1u);
  }
  EXPECT_GT(map.memoryUsage().tiles, tiles);
  // The first reading's volumes are all still there, unchanged.
  std::vector<test::VolumeRecord> now;
  map.forEachVolumeIn({{0, 0}, {3, 2}}, [&](const CellIndex& c, VolumeSign s, const Volume& v) {
    now.emplace_back(c.x, c.y, static_cast<int>(s), v.bottom, v.top, v.mass);
  });
  EXPECT_TRUE(test::sameVolumes(now, first));
  EXPECT_TRUE(test::mapSatisfiesConstraints(map));
}

TEST(Map, RejectsReadingsBeyondMaxCoordinate) {
  Map map(unitConfig(100.0));
  map.insertReading({0.5, 0.5, 0}, {5.5, 0.5, 0}, ReadingKind::kObstacle);
  const std::vector<test::VolumeRecord> before = allVolumes(map);
  const std::uint64_t revision = map.revision();
  const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> far{
      {{0, 0, 0}, {150, 0, 0}}, {{0, 0, 0}, {0, -100.5, 0}}, {{0, 0, 0}, {0, 0, 1000}},
      {{101, 0, 0}, {0, 0, 0}}, {{0, 0, -200}, {1, 1, 1}},   {{1e30, 0, 0}, {0, 0, 0}}};
  for (const auto& [origin, end] : far) {
    for (ReadingKind kind : {ReadingKind::kObstacle, ReadingKind::kOutOfRange}) {
      const InsertionResult result = map.insertReading(origin, end, kind);
      EXPECT_EQ(result.rejected_out_of_bounds, 1u);
      EXPECT_EQ(result.inserted(), 0u);
    }
  }
  Scan scan;
  scan.hits = {{150, 0, 0}, {0, 0, -150}};
  scan.out_of_range = {{-150, 0, 0}};
  EXPECT_EQ(map.insertScan(scan).rejected_out_of_bounds, 3u);
  EXPECT_TRUE(test::sameVolumes(allVolumes(map), before));
  EXPECT_EQ(map.revision(), revision);
  EXPECT_EQ(map.bounds().max, (CellIndex{5, 0}));
  // Exactly at max_coordinate is still inside.
  EXPECT_EQ(map.insertReading({0, 0, 0}, {100, 0, 0}, ReadingKind::kObstacle).obstacle_readings,
            1u);
  EXPECT_EQ(map.bounds().max, (CellIndex{100, 0}));
}

TEST(Map, RejectsNonFiniteReadings) {
  Map map(unitConfig());
  map.insertReading({0.5, 0.5, 0}, {5.5, 0.5, 0}, ReadingKind::kObstacle);
  const std::vector<test::VolumeRecord> before = allVolumes(map);
  const std::uint64_t revision = map.revision();
  const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> bad{
      {{kNaN, 0, 0}, {1, 1, 1}}, {{0, kInf, 0}, {1, 1, 1}},  {{0, 0, -kInf}, {1, 1, 1}},
      {{0, 0, 0}, {kNaN, 1, 1}}, {{0, 0, 0}, {1, -kInf, 1}}, {{0, 0, 0}, {1, 1, kNaN}}};
  for (const auto& [origin, end] : bad) {
    for (ReadingKind kind : {ReadingKind::kObstacle, ReadingKind::kOutOfRange}) {
      EXPECT_EQ(map.insertReading(origin, end, kind).rejected_non_finite, 1u);
    }
  }
  Scan scan;
  scan.origin = {kNaN, 0, 0};
  scan.hits = {{1, 1, 1}};
  scan.out_of_range = {{2, 2, 2}};
  EXPECT_EQ(map.insertScan(scan).rejected_non_finite, 2u);
  EXPECT_TRUE(test::sameVolumes(allVolumes(map), before));
  EXPECT_EQ(map.revision(), revision);
}

TEST(Map, ClearEmptiesTheMapAndResetsDecay) {
  Map map = coarseRandomMap(6);
  map.decay(0.25);
  const std::uint64_t revision = map.revision();
  map.clear();
  EXPECT_TRUE(map.empty());
  EXPECT_TRUE(allVolumes(map).empty());
  EXPECT_GT(map.revision(), revision);
  const MemoryUsage usage = map.memoryUsage();
  EXPECT_EQ(usage.positive_volumes + usage.negative_volumes, 0u);
  EXPECT_EQ(usage.table_one_bytes, 0u);
  map.insertReading({0.5, 0.5, 0}, {0.5, 0.5, 5}, ReadingKind::kObstacle);
  EXPECT_TRUE(test::volumeIs(map.cellVolumes({2, 2}).positive.at(0), 24.5, 25.5, 1.0));
}

TEST(Map, MoveKeepsTheVolumes) {
  Map map = coarseRandomMap(7);
  const std::vector<test::VolumeRecord> before = allVolumes(map);
  Map moved(std::move(map));
  EXPECT_TRUE(test::sameVolumes(allVolumes(moved), before));
  Map assigned(unitConfig());
  assigned = std::move(moved);
  EXPECT_TRUE(test::sameVolumes(allVolumes(assigned), before));
  EXPECT_EQ(assigned.resolution(), 0.2);
}

// ---- setCellVolumes
// ------------------------------------------------------------------------------

TEST(Map, SetCellVolumesRefusesListsBreakingTheConstraints) {
  Map map(unitConfig());
  const std::vector<std::vector<Volume>> bad{{{0, 0.5f, 1}},
                                             {{0, 1, 1}, {1.5f, 3, 1}},
                                             {{0, 2, 1}, {1, 3, 1}},
                                             {{0, 1, -1}},
                                             {{0, 1, std::numeric_limits<float>::quiet_NaN()}},
                                             {{3, 4, 1}, {0, 1, 1}}};
  for (const std::vector<Volume>& list : bad) {
    EXPECT_THROW(map.setCellVolumes({0, 0}, CellVolumes{list, {}}), ConfigError);
    EXPECT_THROW(map.setCellVolumes({0, 0}, CellVolumes{{}, list}), ConfigError);
  }
  EXPECT_TRUE(map.empty());
  EXPECT_TRUE(allVolumes(map).empty());
}

TEST(Map, SetCellVolumesRefusesCellsBeyondMaxCoordinate) {
  Map map(unitConfig(100.0));  // readings reach cells -101..100
  const CellVolumes volumes{{{0, 1, 1}}, {}};
  EXPECT_NO_THROW(map.setCellVolumes({-101, 101}, volumes));
  for (const CellIndex& cell : {CellIndex{102, 0}, CellIndex{0, -102},
                                CellIndex{std::numeric_limits<std::int32_t>::min(), 0}}) {
    try {
      map.setCellVolumes(cell, volumes);
      ADD_FAILURE() << "accepted (" << cell.x << ", " << cell.y << ")";
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("cell"), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(allVolumes(map).size(), 1u);
}

TEST(Map, SetCellVolumesOnADecayedMapKeepsTheGivenMasses) {
  Map map(unitConfig());
  map.decay(0.3);
  map.setCellVolumes({1, 2}, CellVolumes{{{0, 2, 3}}, {{-4, -1, 0.25f}}});
  const CellVolumes cell = map.cellVolumes({1, 2});
  EXPECT_FLOAT_EQ(cell.positive.at(0).mass, 3.0f);
  EXPECT_FLOAT_EQ(cell.negative.at(0).mass, 0.25f);
  EXPECT_NEAR(map.occupancy({1.5, 2.5, 1.0}).positive_density, 1.5, 1e-6);
  // A new reading there merges at its own real mass: [0.5, 1.5] (mass 1) into [0, 2] (mass 3).
  map.insertReading({1.5, 2.5, 1.0}, {1.6, 2.6, 1.0}, ReadingKind::kObstacle);
  EXPECT_FLOAT_EQ(map.cellVolumes({1, 2}).positive.at(0).mass, 4.0f);
  // Masses beyond float range in the decayed unit are refused, the map unchanged.
  const float huge = std::numeric_limits<float>::max();
  EXPECT_THROW(map.setCellVolumes({1, 2}, CellVolumes{{{0, 2, huge}}, {}}), ConfigError);
  EXPECT_FLOAT_EQ(map.cellVolumes({1, 2}).positive.at(0).mass, 4.0f);
}

TEST(Map, SetCellVolumesAfterDecayKeepsTheDecayedMassesOfTheTilesOtherCells) {
  // Decay multiplies every mass by k_d; setting one cell replaces that cell's lists only, so the
  // other cells of its tile keep their decayed masses.
  Map map(unitConfig());
  map.setCellVolumes({1, 2}, CellVolumes{{{0, 2, 4}}, {{-4, -1, 2}}});
  map.decay(0.5);
  map.setCellVolumes({3, 2}, CellVolumes{{{0, 1, 1}}, {}});
  ASSERT_EQ(Map::tileOf({1, 2}), Map::tileOf({3, 2}));
  EXPECT_EQ(allVolumes(map),
            (std::vector<test::VolumeRecord>{
                {1, 2, 0, 0.f, 2.f, 2.f}, {1, 2, 1, -4.f, -1.f, 1.f}, {3, 2, 0, 0.f, 1.f, 1.f}}));
  map.decay(0.5);
  EXPECT_FLOAT_EQ(map.cellVolumes({1, 2}).positive.at(0).mass, 1.0f);
  EXPECT_FLOAT_EQ(map.cellVolumes({3, 2}).positive.at(0).mass, 0.5f);
}

TEST(Map, SetCellVolumesStoresFreeSpaceAcrossAnObstacleAsTheMergeCutsIt) {
  // Sec. III-A allows one negative volume across a positive one; under
  // split_free_space_at_obstacles it is stored cut at the obstacle's bottom and top, each piece
  // with the mass within its heights (density 0.5 here), as an insertion's merge leaves it.
  const ModelRules rules;  // the defaults split free space at obstacles
  ASSERT_TRUE(rules.split_free_space_at_obstacles);
  Map given_whole(unitConfig(10000.0, rules));
  Map given_cut(unitConfig(10000.0, rules));
  given_whole.setCellVolumes({0, 0}, CellVolumes{{{2, 4, 1}}, {{0, 10, 5}}});
  given_cut.setCellVolumes({0, 0}, CellVolumes{{{2, 4, 1}}, {{0, 2, 1}, {2, 4, 1}, {4, 10, 3}}});
  EXPECT_EQ(allVolumes(given_whole), (std::vector<test::VolumeRecord>{{0, 0, 0, 2.f, 4.f, 1.f},
                                                                      {0, 0, 1, 0.f, 2.f, 1.f},
                                                                      {0, 0, 1, 2.f, 4.f, 1.f},
                                                                      {0, 0, 1, 4.f, 10.f, 3.f}}));
  // Then a ray whose free space alone crosses the column, and one that hits it: both maps go on
  // alike (a scan's free space within a column's free space is added in place).
  for (Map* map : {&given_whole, &given_cut}) {
    map->insertReading({-2.5, 0.5, 6.5}, {3.5, 0.5, 6.5}, ReadingKind::kObstacle);
    map->insertReading({-2.5, 0.5, 3.0}, {0.5, 0.5, 3.0}, ReadingKind::kObstacle);
  }
  EXPECT_TRUE(test::sameVolumes(allVolumes(given_whole), allVolumes(given_cut)));
  // The paper's model does not split: the list is kept whole.
  Map paper(unitConfig());
  paper.setCellVolumes({0, 0}, CellVolumes{{{2, 4, 1}}, {{0, 10, 5}}});
  EXPECT_EQ(paper.cellVolumes({0, 0}).negative.size(), 1u);
}

TEST(Map, SetCellVolumesReplacesAndEmptiesCells) {
  Map map(unitConfig());
  map.setCellVolumes({-3, 4}, CellVolumes{{{0, 1, 2}}, {{-5, -2, 3}, {0, 4, 1}}});
  EXPECT_EQ(allVolumes(map), (std::vector<test::VolumeRecord>{{-3, 4, 0, 0.f, 1.f, 2.f},
                                                              {-3, 4, 1, -5.f, -2.f, 3.f},
                                                              {-3, 4, 1, 0.f, 4.f, 1.f}}));
  map.setCellVolumes({5, 5}, CellVolumes{{{0, 1, 2}}, {}});
  EXPECT_EQ(map.bounds().min, (CellIndex{-3, 4}));
  EXPECT_EQ(map.bounds().max, (CellIndex{5, 5}));
  // Emptying a cell removes it from bounds().
  map.setCellVolumes({-3, 4}, CellVolumes{});
  EXPECT_EQ(allVolumes(map), (std::vector<test::VolumeRecord>{{5, 5, 0, 0.f, 1.f, 2.f}}));
  EXPECT_EQ(map.bounds().min, (CellIndex{5, 5}));
  EXPECT_EQ(map.bounds().max, (CellIndex{5, 5}));
  map.setCellVolumes({5, 5}, CellVolumes{});
  EXPECT_TRUE(map.empty());
  EXPECT_EQ(map.memoryUsage().table_one_bytes, 0u);
}

TEST(Map, SetCellVolumesRefusesACellGivenTwiceChangingNothing) {
  // Every cell must appear once in a call; a refused call changes nothing.
  Map map(unitConfig());
  map.setCellVolumes({2, 3}, CellVolumes{{{0, 1, 1}}, {}});
  const std::uint64_t revision = map.revision();
  const std::vector<test::VolumeRecord> before = allVolumes(map);
  const CellVolumes volumes{{{0, 2, 3}}, {}};
  EXPECT_THROW(map.setCellVolumes({{{5, 5}, volumes}, {{2, 3}, volumes}, {{2, 3}, volumes}}),
               ConfigError);
  EXPECT_THROW(map.setCellVolumes({{{7, 1}, volumes}, {{7, 1}, CellVolumes{}}}), ConfigError);
  EXPECT_EQ(allVolumes(map), before);
  EXPECT_EQ(map.revision(), revision);
}

// ---- memoryUsage() (Table I)
// ---------------------------------------------------------------------

TEST(MemoryUsage, EmptyMap) {
  const MemoryUsage usage = Map().memoryUsage();
  EXPECT_EQ(usage.positive_volumes, 0u);
  EXPECT_EQ(usage.negative_volumes, 0u);
  EXPECT_EQ(usage.cells_with_volumes, 0u);
  EXPECT_EQ(usage.minimal_grid_cells, 0u);
  EXPECT_EQ(usage.table_one_bytes, 0u);
  EXPECT_EQ(usage.tiles, 0u);
}

TEST(MemoryUsage, CountsMatchTheVolumesAndTableOneAccounting) {
  Map map(MapConfig{0.2, 1000.0, ModelRules{}});
  std::mt19937 rng(8);
  std::size_t previous_bytes = map.memoryUsage().bytes_held;
  for (int k = 0; k < 4; ++k) {
    map.insertScan(
        test::randomScan(rng, test::randomPoint(rng, 1.0 + 3.0 * k, 0.5), 800, 200, 4.0 + 4.0 * k));
    const MemoryUsage usage = map.memoryUsage();
    std::size_t positive = 0;
    std::size_t negative = 0;
    map.forEachVolume([&](const CellIndex&, VolumeSign sign, const Volume&) {
      ++(sign == VolumeSign::kPositive ? positive : negative);
    });
    EXPECT_EQ(usage.positive_volumes, positive);
    EXPECT_EQ(usage.negative_volumes, negative);
    EXPECT_EQ(usage.cells_with_volumes, test::observedCells(map).size());
    const CellRange bounds = map.bounds();
    EXPECT_EQ(usage.minimal_grid_cells, static_cast<std::size_t>(bounds.width() * bounds.height()));
    EXPECT_EQ(usage.table_one_bytes, 12 * (positive + negative) + 8 * usage.minimal_grid_cells);
    EXPECT_GE(usage.bytes_held, 12 * (positive + negative));
    EXPECT_GT(usage.bytes_held, previous_bytes);  // each scan reaches further
    previous_bytes = usage.bytes_held;
    std::set<std::pair<int, int>> tiles;
    for (const CellIndex& cell : test::observedCells(map)) {
      const TileIndex tile = Map::tileOf(cell);
      tiles.emplace(tile.x, tile.y);
    }
    EXPECT_EQ(usage.tiles, tiles.size());
  }
}

// ---- Configuration
// ----------------------------------------------------------------------------------

/// `action` throws ConfigError and its message names `field`.
template <class Action>
void expectConfigError(Action&& action, const std::string& field) {
  try {
    action();
    ADD_FAILURE() << "no ConfigError for " << field;
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find(field), std::string::npos)
        << "'" << e.what() << "' does not name " << field;
  }
}

TEST(Config, DefaultsAreValid) {
  EXPECT_NO_THROW(MapConfig{}.validate());
  EXPECT_NO_THROW(InsertionConfig{}.validate());
}

TEST(Config, MapConfigFieldsAreChecked) {
  const std::vector<std::pair<MapConfig, std::string>> bad{
      {{0.0, 100.0, {}}, "resolution"},        {{-0.1, 100.0, {}}, "resolution"},
      {{kNaN, 100.0, {}}, "resolution"},       {{kInf, 100.0, {}}, "resolution"},
      {{0.1, 0.0, {}}, "max_coordinate"},      {{0.1, -5.0, {}}, "max_coordinate"},
      {{0.1, kNaN, {}}, "max_coordinate"},     {{0.1, kInf, {}}, "max_coordinate"},
      {{0.001, 10000.0, {}}, "max_coordinate"}};  // 10^7 cells: heights would not resolve a cell
  for (const auto& [config, field] : bad) {
    expectConfigError([&] { config.validate(); }, field);
    expectConfigError([&] { Map map(config); }, field);
  }
  EXPECT_NO_THROW({ Map map(MapConfig{0.001, 4194.0, ModelRules{}}); });
  // Each field on its own: resolution 0 with a valid max_coordinate is not reported as a
  // max_coordinate error (whose message names the resolution too).
  try {
    MapConfig{0.0, 100.0, {}}.validate();
    ADD_FAILURE() << "no ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()).find("max_coordinate"), std::string::npos) << e.what();
  }
  // At most 4194304 cells: the bound itself is allowed.
  EXPECT_NO_THROW((MapConfig{1.0, 4194304.0, {}}.validate()));
  expectConfigError([] { MapConfig{1.0, 4194305.0, {}}.validate(); }, "max_coordinate");
  // out_of_range_free_length must be > 0 (infinity for no limit).
  for (const double length : {0.0, -1.0, kNaN}) {
    MapConfig config;
    config.rules.out_of_range_free_length = length;
    expectConfigError([&] { config.validate(); }, "out_of_range_free_length");
  }
  MapConfig unlimited;
  unlimited.rules.out_of_range_free_length = kInf;
  EXPECT_NO_THROW(unlimited.validate());
}

TEST(Config, PlanningConfigFieldsAreCheckedAtTheEdgesOfTheirRanges) {
  const auto with = [](auto change) {
    PlanningConfig config;
    change(config);
    return config;
  };
  // The edges of each range: a threshold of 0 (any positive p is occupied), one cell a call,
  // bands of one height, pieces of one voxel, a robot that climbs no step.
  for (const PlanningConfig& good :
       {with([](PlanningConfig& c) { c.occupancy_threshold = 0.0; }),
        with([](PlanningConfig& c) { c.max_query_cells = 1; }),
        with([](PlanningConfig& c) { c.frontier_min_z = c.frontier_max_z = 1.5; }),
        with([](PlanningConfig& c) { c.frontier_min_cells = 1; }),
        with([](PlanningConfig& c) { c.max_step = 0.0; }),
        with([](PlanningConfig& c) { c.traversable_min_z = c.traversable_max_z = 0.0; })}) {
    EXPECT_NO_THROW(good.validate());
  }
  const std::vector<std::pair<PlanningConfig, std::string>> bad{
      {with([](PlanningConfig& c) { c.occupancy_threshold = 1.0; }), "occupancy_threshold"},
      {with([](PlanningConfig& c) { c.occupancy_threshold = -0.1; }), "occupancy_threshold"},
      {with([](PlanningConfig& c) { c.max_query_cells = 0; }), "max_query_cells"},
      {with([](PlanningConfig& c) {
         c.frontier_min_z = 2.0;
         c.frontier_max_z = 1.0;
       }),
       "frontier_min_z"},
      {with([](PlanningConfig& c) { c.frontier_min_cells = 0; }), "frontier_min_cells"},
      {with([](PlanningConfig& c) { c.robot_height = 0.0; }), "robot_height"},
      {with([](PlanningConfig& c) { c.robot_height = kInf; }), "robot_height"},
      {with([](PlanningConfig& c) { c.max_step = -0.1; }), "max_step"},
      {with([](PlanningConfig& c) { c.max_step = kInf; }), "max_step"},
      {with([](PlanningConfig& c) { c.traversable_min_z = kNaN; }), "traversable_min_z"}};
  for (const auto& [config, field] : bad) {
    SCOPED_TRACE(field);
    expectConfigError([&] { config.validate(); }, field);
  }
}

TEST(Config, OnlyFinitePointsWithinMaxCoordinateOnEveryAxisAreWithinBounds) {
  const MapConfig config{0.1, 100.0, {}};
  EXPECT_TRUE(config.withinBounds({0.0, 0.0, 0.0}));
  EXPECT_TRUE(config.withinBounds({100.0, -100.0, 100.0}));  // the bound itself is inside
  for (int axis = 0; axis < 3; ++axis) {
    for (const double value : {100.001, -100.001, kInf, -kInf, kNaN}) {
      Eigen::Vector3d point(1.0, 2.0, 3.0);
      point[axis] = value;
      EXPECT_FALSE(config.withinBounds(point)) << "axis " << axis << " at " << value;
    }
  }
}

TEST(Config, InsertionConfigFieldsAreChecked) {
  const auto with = [](auto change) {
    InsertionConfig config;
    change(config);
    return config;
  };
  const std::vector<std::pair<InsertionConfig, std::string>> bad{
      {with([](InsertionConfig& c) { c.min_range = -1.0; }), "min_range"},
      {with([](InsertionConfig& c) { c.min_range = kNaN; }), "min_range"},
      {with([](InsertionConfig& c) { c.min_range = kInf; }), "min_range"},
      {with([](InsertionConfig& c) { c.max_range = 0.0; }), "max_range"},
      {with([](InsertionConfig& c) { c.max_range = -3.0; }), "max_range"},
      {with([](InsertionConfig& c) { c.max_range = kNaN; }), "max_range"},
      {with([](InsertionConfig& c) { c.max_range = -kInf; }), "max_range"},
      {with([](InsertionConfig& c) {
         c.min_range = 5.0;
         c.max_range = 5.0;
       }),
       "min_range"},
      {with([](InsertionConfig& c) {
         c.min_range = 6.0;
         c.max_range = 5.0;
       }),
       "min_range"},
      {with([](InsertionConfig& c) { c.hit_memory_scans = -1; }), "hit_memory_scans"},
      {with([](InsertionConfig& c) { c.hit_memory_scans = kMaxHitMemoryScans + 1; }),
       "hit_memory_scans"},
      {with([](InsertionConfig& c) { c.hit_memory_scope = static_cast<HitMemoryScope>(2); }),
       "hit_memory_scope"},
      {with([](InsertionConfig& c) { c.insertion_threads = 0; }), "insertion_threads"},
      {with([](InsertionConfig& c) { c.insertion_threads = -2; }), "insertion_threads"},
      {with([](InsertionConfig& c) { c.insertion_threads = 257; }), "insertion_threads"}};
  Map map(unitConfig());
  Scan scan;
  scan.hits = {{1, 1, 1}};
  for (const auto& [config, field] : bad) {
    expectConfigError([&] { config.validate(); }, field);
    expectConfigError(
        [&] {
          map.insertReading({0, 0, 0}, {1, 1, 1}, ReadingKind::kObstacle, config);
        },
        field);
    expectConfigError([&] { map.insertScan(scan, config); }, field);
  }
  EXPECT_TRUE(map.empty());
  EXPECT_NO_THROW(with([](InsertionConfig& c) { c.insertion_threads = 256; }).validate());
  EXPECT_NO_THROW(with([](InsertionConfig& c) { c.min_range = 1e9; }).validate());
}

// ---- Change tracking
// --------------------------------------------------------------------------------

/// The tiles whose cells' volumes differ between two snapshots of allVolumes.
std::vector<std::pair<int, int>> changedTiles(const std::vector<test::VolumeRecord>& before,
                                              const std::vector<test::VolumeRecord>& after) {
  std::map<std::pair<int, int>, std::vector<test::VolumeRecord>> cells_before, cells_after;
  for (const auto& r : before) cells_before[{std::get<0>(r), std::get<1>(r)}].push_back(r);
  for (const auto& r : after) cells_after[{std::get<0>(r), std::get<1>(r)}].push_back(r);
  std::set<std::pair<int, int>> keys;
  for (const auto& [cell, records] : cells_after) {
    if (cells_before[cell] != records) keys.insert(cell);
  }
  std::set<std::pair<int, int>> tiles;
  for (const auto& [x, y] : keys) {
    const TileIndex tile = Map::tileOf({x, y});
    tiles.emplace(tile.y, tile.x);  // tilesModifiedSince lists rows of tiles from the lowest
  }
  std::vector<std::pair<int, int>> ordered;
  for (const auto& [y, x] : tiles) ordered.emplace_back(x, y);
  return ordered;
}

std::vector<std::pair<int, int>> modifiedSince(const Map& map, std::uint64_t revision) {
  std::vector<std::pair<int, int>> tiles;
  for (const TileIndex& t : map.tilesModifiedSince(revision)) tiles.emplace_back(t.x, t.y);
  return tiles;
}

TEST(ChangeTracking, TileGeometry) {
  EXPECT_EQ(Map::kTileSize, 16);
  EXPECT_TRUE((Map::tileOf({0, 0}) == TileIndex{0, 0}));
  EXPECT_TRUE((Map::tileOf({15, 16}) == TileIndex{0, 1}));
  EXPECT_TRUE((Map::tileOf({-1, -16}) == TileIndex{-1, -1}));
  EXPECT_TRUE((Map::tileOf({-17, 31}) == TileIndex{-2, 1}));
  const CellRange cells = Map::tileCells({-1, 2});
  EXPECT_EQ(cells.min, (CellIndex{-16, 32}));
  EXPECT_EQ(cells.max, (CellIndex{-1, 47}));
}

TEST(ChangeTracking, TilesTouchedByAnInsertionAreListed) {
  Map map(unitConfig());
  const std::uint64_t r0 = map.revision();
  map.insertReading({0.5, 0.5, 0}, {5.5, 0.5, 0}, ReadingKind::kObstacle);  // tile (0, 0) only
  EXPECT_GT(map.revision(), r0);
  EXPECT_EQ(modifiedSince(map, r0), (std::vector<std::pair<int, int>>{{0, 0}}));
  const std::uint64_t r1 = map.revision();
  EXPECT_TRUE(modifiedSince(map, r1).empty());
  map.insertReading({33.5, 0.5, 0}, {40.5, 0.5, 0}, ReadingKind::kOutOfRange);  // tile (2, 0) only
  EXPECT_EQ(modifiedSince(map, r1), (std::vector<std::pair<int, int>>{{2, 0}}));
  EXPECT_EQ(modifiedSince(map, r0), (std::vector<std::pair<int, int>>{{0, 0}, {2, 0}}));
  // Queries, rejected readings and readings that store nothing change nothing.
  const std::uint64_t r2 = map.revision();
  map.occupancy({1, 1, 1});
  map.memoryUsage();
  map.insertReading({0, 0, 0}, {kNaN, 0, 0}, ReadingKind::kObstacle);
  EXPECT_EQ(map.revision(), r2);
  EXPECT_TRUE(modifiedSince(map, r2).empty());
  map.setCellVolumes({-20, 70}, CellVolumes{{{0, 1, 1}}, {}});
  EXPECT_EQ(modifiedSince(map, r2), (std::vector<std::pair<int, int>>{{-2, 4}}));
}

TEST(ChangeTracking, ATileARayEntersWithoutCrossingACellIsNotModified) {
  // y = x passes through the corner (16, 16) where tiles (0, 0), (1, 0), (0, 1) and (1, 1) meet:
  // the walk steps from cell (15, 15) into (16, 15) or (15, 16), tile (1, 0) or (0, 1), and on
  // at once to (16, 16), crossing nothing of the tile between
  // (WalkRay.DiagonalThroughCornersSkipsTheCornerCells). A ray starting on x = 16 towards -x
  // starts in cell (16, 5), tile (1, 0), on the wall it leaves through, and crosses nothing there
  // (WalkRay.DiagonalStartingOnACorner). The paper's model and the defaults (a level scan's
  // writer) alike.
  for (const ModelRules& rules : {ModelRules::paper(), ModelRules{}}) {
    SCOPED_TRACE(rules == ModelRules::paper() ? "paper model" : "default rules");
    Map map(unitConfig(10000.0, rules));
    map.insertReading({20.5, 5.5, 0}, {25.5, 5.5, 0}, ReadingKind::kObstacle);  // tile (1, 0)
    map.insertReading({5.5, 20.5, 0}, {5.5, 25.5, 0}, ReadingKind::kObstacle);  // tile (0, 1)
    const auto before = test::allVolumes(map);
    const std::uint64_t revision = map.revision();
    map.insertReading({14.5, 14.5, 0}, {17.5, 17.5, 0}, ReadingKind::kObstacle);
    EXPECT_EQ(modifiedSince(map, revision), (std::vector<std::pair<int, int>>{{0, 0}, {1, 1}}));
    EXPECT_EQ(changedTiles(before, test::allVolumes(map)), modifiedSince(map, revision));
    for (const CellIndex& corner : {CellIndex{16, 15}, CellIndex{15, 16}}) {
      const CellVolumes volumes = map.cellVolumes(corner);
      EXPECT_TRUE(volumes.positive.empty() && volumes.negative.empty());
    }
    const std::uint64_t before_wall = map.revision();
    map.insertReading({16.0, 5.5, 0}, {10.5, 5.5, 0}, ReadingKind::kObstacle);
    EXPECT_EQ(modifiedSince(map, before_wall), (std::vector<std::pair<int, int>>{{0, 0}}));
  }
}

TEST(ChangeTracking, DecayIsAChangeOfNoTile) {
  // Decay changes every mass (what cellVolumes and serializeMap return), so the revision moves;
  // no probability changes, so no tile is listed. A factor of 1 changes nothing.
  Map map(unitConfig());
  map.insertReading({0.5, 0.5, 0}, {5.5, 0.5, 0}, ReadingKind::kObstacle);
  const std::uint64_t r0 = map.revision();
  map.decay(1.0);
  EXPECT_EQ(map.revision(), r0);
  map.decay(0.5);
  EXPECT_GT(map.revision(), r0);
  EXPECT_TRUE(modifiedSince(map, r0).empty());
}

TEST(ChangeTracking, ListsExactlyTheTilesWhoseCellsChanged) {
  // Single readings, and scans with one thread and with three (new and existing tiles alike).
  Map map(unitConfig());
  std::mt19937 rng(9);
  for (int k = 0; k < 45; ++k) {
    const std::vector<test::VolumeRecord> before = allVolumes(map);
    const std::uint64_t revision = map.revision();
    if (k % 3 == 0) {
      InsertionConfig config;
      config.insertion_threads = k % 2 == 0 ? 1 : 3;
      map.insertScan(test::randomScan(rng, test::randomPoint(rng, 40.0, 1.0), 6, 3, 60.0), config);
    } else {
      map.insertReading(test::randomPoint(rng, 60.0, 1.0), test::randomPoint(rng, 60.0, 1.0),
                        k % 2 == 0 ? ReadingKind::kObstacle : ReadingKind::kOutOfRange);
    }
    EXPECT_EQ(modifiedSince(map, revision), changedTiles(before, allVolumes(map)))
        << "insertion " << k;
  }
}

TEST(ChangeTracking, EmptyingCellsThatHoldNothingChangesNoTile) {
  // Only the tiles whose volumes changed are listed: emptying cells that hold nothing, in a tile
  // that exists and in one that does not, changes no tile.
  Map map(unitConfig());
  map.setCellVolumes({3, 4}, CellVolumes{{{0, 1, 2}}, {{-4, -1, 3}}});
  const std::uint64_t revision = map.revision();
  const std::vector<test::VolumeRecord> before = allVolumes(map);
  map.setCellVolumes({{{5, 4}, CellVolumes{}}, {{100, 100}, CellVolumes{}}});
  EXPECT_TRUE(modifiedSince(map, revision).empty());
  EXPECT_EQ(allVolumes(map), before);
}

}  // namespace
}  // namespace mvog
