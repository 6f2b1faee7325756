// A map's lifetime: forgetting what decayed, dropping far tiles, clearing a box, and the record
// of the tiles removed.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <random>
#include <set>
#include <vector>

#include "mvog/map.h"
#include "mvog/map_io.h"
#include "test_util.h"

namespace mvog {
namespace {

using Bytes = std::vector<std::uint8_t>;
using test::allVolumes;
using test::coarseRandomMap;
using test::kInf;
using test::kNaN;
using test::VolumeRecord;

/// What forgetting weighs in a list: each volume of a positive list, each run of touching
/// volumes of a negative one, as (bottom, top, mass summed in double).
std::vector<Volume> forgettables(const std::vector<Volume>& list, bool runs) {
  std::vector<Volume> units;
  double mass = 0.0;
  for (std::size_t k = 0; k < list.size(); ++k) {
    if (runs && k > 0 && list[k].bottom == list[k - 1].top) {
      mass += list[k].mass;
      units.back().top = list[k].top;
    } else {
      mass = list[k].mass;
      units.push_back(list[k]);
    }
    units.back().mass = static_cast<float>(mass);
  }
  return units;
}

/// The volumes of the cells of `map` inside or outside `cells`.
std::vector<VolumeRecord> volumesOf(const Map& map, const CellRange& cells, bool inside) {
  std::vector<VolumeRecord> records;
  for (const VolumeRecord& r : allVolumes(map)) {
    if (cells.contains({std::get<0>(r), std::get<1>(r)}) == inside) records.push_back(r);
  }
  return records;
}

Bytes serialized(const Map& map) { return serializeMap(map); }

// ---- Forgetting ---------------------------------------------------------------------------

TEST(Forget, RemovesWhatIsLighterThanTheMassAndKeepsTheRest) {
  for (const ModelRules& rules : {ModelRules{}, ModelRules::paper()}) {
    Map map = test::randomMap(3, 0.2, 5.0, 6, rules);
    map.decay(0.05);
    const std::vector<CellIndex> cells = test::observedCells(map);
    std::map<std::pair<int, int>, CellVolumes> before;
    for (const CellIndex& c : cells) before[{c.x, c.y}] = map.cellVolumes(c);
    const double min_mass = 0.2;
    const ForgetResult result = map.forget(min_mass);
    EXPECT_GT(result.volumes_removed, 0u);
    EXPECT_GT(result.cells_emptied, 0u);
    EXPECT_TRUE(test::mapSatisfiesConstraints(map));
    std::size_t removed = 0;
    std::size_t emptied = 0;
    for (const CellIndex& c : cells) {
      const CellVolumes& old = before[{c.x, c.y}];
      const CellVolumes now = map.cellVolumes(c);
      // Positive volumes: the heavy ones stay, exactly.
      std::vector<Volume> kept;
      for (const Volume& v : old.positive) {
        if (v.mass >= min_mass) kept.push_back(v);
      }
      ASSERT_EQ(now.positive.size(), kept.size());
      for (std::size_t k = 0; k < kept.size(); ++k) {
        EXPECT_TRUE(test::volumeIs(now.positive[k], kept[k].bottom, kept[k].top, kept[k].mass));
      }
      // Negative runs (what touches: the pieces of one free volume) likewise, as runs: where
      // an obstacle between pieces went, they merged into fewer pieces of the same run.
      std::vector<Volume> kept_runs;
      for (const Volume& run : forgettables(old.negative, true)) {
        if (run.mass >= min_mass) kept_runs.push_back(run);
      }
      const std::vector<Volume> now_runs = forgettables(now.negative, true);
      ASSERT_EQ(now_runs.size(), kept_runs.size()) << "cell " << c.x << ", " << c.y;
      for (std::size_t k = 0; k < kept_runs.size(); ++k) {
        EXPECT_EQ(now_runs[k].bottom, kept_runs[k].bottom);
        EXPECT_EQ(now_runs[k].top, kept_runs[k].top);
        EXPECT_NEAR(now_runs[k].mass, kept_runs[k].mass, 1e-5 * kept_runs[k].mass);
      }
      removed +=
          old.positive.size() + old.negative.size() - now.positive.size() - now.negative.size();
      emptied += now.positive.empty() && now.negative.empty();
    }
    EXPECT_EQ(result.cells_emptied, emptied);
    EXPECT_LE(result.volumes_removed, removed);  // and pieces merged: fewer volumes still
  }
}

TEST(Forget, PiecesThatTouchedAtAForgottenObstacleMergeAgain) {
  // Split at obstacles (the default): free space [0, 8] cut at the obstacle [3, 4].
  Map map(test::unitConfig(100.0, ModelRules{}));
  map.setCellVolumes({0, 0}, CellVolumes{{{3, 4, 0.01f}}, {{0, 3, 3}, {3, 4, 0.5f}, {4, 8, 4}}});
  map.forget(0.2);  // the obstacle goes; the piece within it is light, but not its run
  const CellVolumes after = map.cellVolumes({0, 0});
  EXPECT_TRUE(after.positive.empty());
  ASSERT_EQ(after.negative.size(), 1u);
  EXPECT_TRUE(test::volumeIs(after.negative[0], 0, 8, 7.5));
  EXPECT_TRUE(test::mapSatisfiesConstraints(map));

  // A heavy obstacle keeps its pieces, the light one within it included.
  map.setCellVolumes({1, 0}, CellVolumes{{{3, 4, 5}}, {{0, 3, 3}, {3, 4, 0.05f}, {4, 8, 4}}});
  const std::vector<VolumeRecord> before = allVolumes(map);
  EXPECT_EQ(map.forget(0.2).volumes_removed, 0u);
  EXPECT_EQ(allVolumes(map), before);

  // Two obstacles in one run, one forgotten: the pieces merge at it only.
  map.setCellVolumes({2, 0}, CellVolumes{{{3, 4, 0.01f}, {6, 7, 2}},
                                         {{0, 3, 3}, {3, 4, 1}, {4, 6, 2}, {6, 7, 1}, {7, 9, 2}}});
  map.forget(0.2);
  const CellVolumes two = map.cellVolumes({2, 0});
  ASSERT_EQ(two.positive.size(), 1u);
  ASSERT_EQ(two.negative.size(), 3u);
  EXPECT_TRUE(test::volumeIs(two.negative[0], 0, 6, 6));
  EXPECT_TRUE(test::volumeIs(two.negative[1], 6, 7, 1));
  EXPECT_TRUE(test::volumeIs(two.negative[2], 7, 9, 2));
  EXPECT_TRUE(test::mapSatisfiesConstraints(map));
}

TEST(Forget, ALightRunGoesWholeAndLeavesTheObstacle) {
  Map map(test::unitConfig(100.0, ModelRules{}));
  map.setCellVolumes({0, 0},
                     CellVolumes{{{3, 4, 5}}, {{0, 3, 0.05f}, {3, 4, 0.01f}, {4, 8, 0.1f}}});
  const ForgetResult result = map.forget(0.2);
  EXPECT_EQ(result.volumes_removed, 3u);
  const CellVolumes after = map.cellVolumes({0, 0});
  EXPECT_EQ(after.positive.size(), 1u);
  EXPECT_TRUE(after.negative.empty());
  EXPECT_EQ(*map.occupancy({0.5, 0.5, 3.5}).probability, 1.0f);  // unknown free space: p = 1
  EXPECT_FALSE(map.occupancy({0.5, 0.5, 1.0}).known());
}

TEST(Forget, FreesTheTilesOfWhatDecayedAndLeavesTheRestBitForBit) {
  // An old region decayed far below the threshold, a new one seen since.
  Map map = coarseRandomMap(4);
  for (int k = 0; k < 30; ++k) map.decay(0.5);
  std::mt19937 rng(5);
  for (int k = 0; k < 3; ++k)
    map.insertScan(test::randomScan(rng, {40.0, 0.0, 0.0}, 1200, 400, 5.0));
  const CellRange old_region{{-40, -40}, {40, 40}};
  const std::vector<VolumeRecord> new_volumes = volumesOf(map, old_region, false);
  const MemoryUsage before = map.memoryUsage();
  const std::uint64_t revision = map.revision();

  const ForgetResult result = map.forget(1e-3);
  EXPECT_TRUE(volumesOf(map, old_region, true).empty());
  EXPECT_EQ(volumesOf(map, old_region, false), new_volumes);
  const MemoryUsage after = map.memoryUsage();
  EXPECT_EQ(before.tiles - after.tiles, result.tiles_freed);
  EXPECT_GE(result.tiles_freed, 10u);
  EXPECT_LT(after.bytes_held, before.bytes_held / 2);
  EXPECT_EQ(after.cells_with_volumes, before.cells_with_volumes - result.cells_emptied);
  EXPECT_GE(map.bounds().min.x, 170);  // bounds() shrank to the new region (x >= 35 m)
  EXPECT_GT(map.revision(), revision);
  const std::optional<std::vector<TileIndex>> removed = map.tilesRemovedSince(revision);
  ASSERT_TRUE(removed.has_value());
  EXPECT_EQ(removed->size(), result.tiles_freed);

  // Nothing more to forget: no change, no new revision.
  const Bytes bytes = serialized(map);
  const std::uint64_t forgotten = map.revision();
  EXPECT_EQ(map.forget(1e-3).volumes_removed, 0u);
  EXPECT_EQ(map.revision(), forgotten);
  EXPECT_EQ(serialized(map), bytes);
}

TEST(Forget, EveryStepOfALongRunLeavesNothingLight) {
  // Insertion writes tiles in place between the steps: what forget remembers of a tile (its
  // lightest mass) must follow, or a light volume would survive a step.
  Map map = coarseRandomMap(6, 1);
  std::mt19937 rng(7);
  const double min_mass = 0.3;
  for (int step = 0; step < 40; ++step) {
    map.insertScan(test::randomScan(rng, test::randomPoint(rng, 3.0, 0.5), 300, 100, 5.0));
    map.decay(0.8);
    map.forget(min_mass);
    ASSERT_TRUE(test::mapSatisfiesConstraints(map)) << "step " << step;
    for (const CellIndex& c : test::observedCells(map)) {
      const CellVolumes v = map.cellVolumes(c);
      for (const Volume& p : v.positive) ASSERT_GE(p.mass, min_mass) << "step " << step;
      for (const Volume& n : forgettables(v.negative, true)) {
        ASSERT_GE(n.mass, min_mass * (1 - 1e-6)) << "step " << step;
      }
    }
  }
  EXPECT_FALSE(map.empty());
}

TEST(Forget, RefusesBadMassesAndZeroForgetsNothing) {
  Map map = coarseRandomMap(8);
  map.decay(1e-3);
  const Bytes bytes = serialized(map);
  for (double bad : {kNaN, -1.0, kInf, -kInf}) {
    EXPECT_THROW(map.forget(bad), ConfigError) << bad;
  }
  EXPECT_EQ(map.forget(0.0).volumes_removed, 0u);
  EXPECT_EQ(serialized(map), bytes);
  EXPECT_EQ(Map().forget(1.0).volumes_removed, 0u);  // an empty map
}

// ---- Dropping far tiles ------------------------------------------------------------------------

/// The distance from (x, y) to the nearest point of a tile's square (m).
double distanceToTile(const TileIndex& tile, double resolution, double x, double y) {
  const double edge = Map::kTileSize * resolution;
  const double dx = std::max({tile.x * edge - x, 0.0, x - (tile.x + 1) * edge});
  const double dy = std::max({tile.y * edge - y, 0.0, y - (tile.y + 1) * edge});
  return std::hypot(dx, dy);
}

std::set<std::pair<int, int>> tilesOf(const Map& map) {
  std::set<std::pair<int, int>> tiles;
  for (const CellIndex& c : test::observedCells(map)) {
    const TileIndex t = Map::tileOf(c);
    tiles.emplace(t.x, t.y);
  }
  return tiles;
}

TEST(DropTiles, DropsTheTilesWhollyFartherAndReturnsThemExactly) {
  Map map = test::randomMap(9, 0.1, 10.0, 4);
  map.decay(0.3);  // the dropped tiles keep the decayed masses exactly
  const std::vector<VolumeRecord> all = allVolumes(map);
  const std::size_t tiles = map.memoryUsage().tiles;
  const Eigen::Vector2d centre(1.3, -2.1);
  const double radius = 4.0;
  const std::uint64_t revision = map.revision();
  const Map dropped = map.dropTilesFartherThan(centre, radius);
  for (const auto& [x, y] : tilesOf(map)) {
    EXPECT_LE(distanceToTile({x, y}, 0.1, centre.x(), centre.y()), radius);
  }
  for (const auto& [x, y] : tilesOf(dropped)) {
    EXPECT_GT(distanceToTile({x, y}, 0.1, centre.x(), centre.y()), radius);
  }
  EXPECT_FALSE(dropped.empty());
  EXPECT_EQ(map.memoryUsage().tiles + dropped.memoryUsage().tiles, tiles);
  // Together they hold every volume of the map, masses bit for bit.
  std::vector<VolumeRecord> together = allVolumes(map);
  const std::vector<VolumeRecord> dropped_volumes = allVolumes(dropped);
  together.insert(together.end(), dropped_volumes.begin(), dropped_volumes.end());
  std::vector<VolumeRecord> sorted_all = all;
  std::sort(together.begin(), together.end());
  std::sort(sorted_all.begin(), sorted_all.end());
  EXPECT_TRUE(test::sameVolumes(together, sorted_all));
  EXPECT_TRUE(test::mapSatisfiesConstraints(dropped));
  EXPECT_EQ(dropped.config().resolution, 0.1);
  const std::optional<std::vector<TileIndex>> removed = map.tilesRemovedSince(revision);
  ASSERT_TRUE(removed.has_value());
  EXPECT_EQ(removed->size(), tilesOf(dropped).size());
  // The bounds follow: every cell of each map inside its bounds, the bounds no larger.
  for (const Map* m : {static_cast<const Map*>(&map), &dropped}) {
    CellRange tight = kNoCells;
    for (const CellIndex& c : test::observedCells(*m)) tight.extend(c);
    EXPECT_EQ(m->bounds().min, tight.min);
    EXPECT_EQ(m->bounds().max, tight.max);
  }
}

TEST(DropTiles, MergingWhatWasDroppedBackGivesTheMapAgain) {
  Map map = test::randomMap(10, 0.1, 10.0, 4);
  const Bytes whole = serialized(map);
  char directory[] = "/tmp/mvog_drop_XXXXXX";
  ASSERT_NE(::mkdtemp(directory), nullptr);
  const std::string file = std::string(directory) + "/dropped.mvog";
  // Two steps of a window moving away, each saving what it dropped into the same file.
  mergeIntoMapFile(map.dropTilesFartherThan({-6.0, 0.0}, 5.0), file);
  mergeIntoMapFile(map.dropTilesFartherThan({0.0, 0.0}, 3.0), file);
  Map saved = loadMap(file);
  saved.merge(map);
  EXPECT_EQ(serialized(saved), whole);
  std::remove(file.c_str());
  ::rmdir(directory);
}

TEST(DropTiles, RefusesBadInputAndDropsNothingWhenAllIsNear) {
  Map map = coarseRandomMap(11);
  const Bytes bytes = serialized(map);
  EXPECT_THROW(map.dropTilesFartherThan({kNaN, 0.0}, 1.0), ConfigError);
  EXPECT_THROW(map.dropTilesFartherThan({0.0, kInf}, 1.0), ConfigError);
  EXPECT_THROW(map.dropTilesFartherThan({0.0, 0.0}, -1.0), ConfigError);
  EXPECT_THROW(map.dropTilesFartherThan({0.0, 0.0}, kNaN), ConfigError);
  const std::uint64_t revision = map.revision();
  EXPECT_TRUE(map.dropTilesFartherThan({0.0, 0.0}, kInf).empty());
  EXPECT_TRUE(map.dropTilesFartherThan({0.0, 0.0}, 100.0).empty());
  EXPECT_EQ(map.revision(), revision);
  EXPECT_EQ(serialized(map), bytes);
}

// ---- Clearing a box
// ------------------------------------------------------------------------------

/// The cells whose squares meet the footprint [min, max) of a box (m) in a map of `resolution`.
CellRange footprint(const Eigen::Vector3d& min, const Eigen::Vector3d& max, double resolution) {
  return {{static_cast<std::int32_t>(std::floor(min.x() / resolution)),
           static_cast<std::int32_t>(std::floor(min.y() / resolution))},
          {static_cast<std::int32_t>(std::ceil(max.x() / resolution)) - 1,
           static_cast<std::int32_t>(std::ceil(max.y() / resolution)) - 1}};
}

TEST(ClearBox, TheBoxBecomesUnknownTheRestStays) {
  for (const ModelRules& rules : {ModelRules{}, ModelRules::paper()}) {
    Map map = test::randomMap(12, 0.2, 5.0, 4, rules);
    const Map original = deserializeMap(serialized(map).data(), serialized(map).size());
    const Eigen::Vector3d min(-1.13, -0.71, -0.93);
    const Eigen::Vector3d max(2.07, 1.49, 0.58);
    const CellRange cells = footprint(min, max, 0.2);
    const std::vector<VolumeRecord> outside = volumesOf(map, cells, false);
    const std::size_t changed = map.clearBox(min, max);
    EXPECT_TRUE(test::mapSatisfiesConstraints(map));
    EXPECT_EQ(volumesOf(map, cells, false), outside);  // other cells bit for bit
    std::size_t differing = 0;
    std::mt19937 rng(13);
    for (std::int32_t x = cells.min.x; x <= cells.max.x; ++x) {
      for (std::int32_t y = cells.min.y; y <= cells.max.y; ++y) {
        const CellVolumes old = original.cellVolumes({x, y});
        const CellVolumes now = map.cellVolumes({x, y});
        differing +=
            old.positive.size() != now.positive.size() ||
            old.negative.size() != now.negative.size() ||
            !std::equal(old.positive.begin(), old.positive.end(), now.positive.begin(),
                        [](const Volume& a, const Volume& b) {
                          return a.bottom == b.bottom && a.top == b.top && a.mass == b.mass;
                        }) ||
            !std::equal(old.negative.begin(), old.negative.end(), now.negative.begin(),
                        [](const Volume& a, const Volume& b) {
                          return a.bottom == b.bottom && a.top == b.top && a.mass == b.mass;
                        });
        // Every volume left is a part of one before, of the same density (masses in proportion).
        for (const auto& [now_list, old_list] :
             {std::pair{&now.positive, &old.positive}, std::pair{&now.negative, &old.negative}}) {
          for (const Volume& v : *now_list) {
            const auto whole = std::find_if(
                old_list->begin(), old_list->end(),
                [&](const Volume& o) { return o.bottom <= v.bottom && v.top <= o.top; });
            ASSERT_NE(whole, old_list->end());
            EXPECT_NEAR(v.density(), whole->density(), 1e-5 * whole->density());
            EXPECT_TRUE(v.top <= min.z() / 0.2 + 1e-4 || v.bottom >= max.z() / 0.2 - 1e-4)
                << "a volume [" << v.bottom << ", " << v.top << "] reaches into the box";
          }
        }
      }
    }
    EXPECT_EQ(changed, differing);
    EXPECT_GT(changed, 50u);
    // Inside: unknown. Above and below, farther than one cell height from the box: as before.
    for (int k = 0; k < 2000; ++k) {
      std::uniform_real_distribution<double> ux(min.x(), max.x()), uy(min.y(), max.y()),
          uz(min.z(), max.z()), far(-3.0, 3.0);
      EXPECT_FALSE(map.occupancy({ux(rng), uy(rng), uz(rng)}).known());
      const Eigen::Vector3d point(ux(rng), uy(rng), far(rng));
      if (point.z() > min.z() - 0.2 && point.z() < max.z() + 0.2) continue;
      const PointOccupancy was = original.occupancy(point);
      const PointOccupancy is = map.occupancy(point);
      ASSERT_EQ(was.known(), is.known());
      if (was.known()) {
        EXPECT_NEAR(*was.probability, *is.probability, 1e-5);
      }
    }
  }
}

TEST(ClearBox, WholeColumnsGoAndTheirTilesAreFreed) {
  Map map = coarseRandomMap(14);
  const MemoryUsage before = map.memoryUsage();
  const std::uint64_t revision = map.revision();
  // x in [-3.2, 0): tiles of 16 cells of 0.2 m, so tiles -1 and -2 in x wholly.
  const std::size_t changed = map.clearBox({-6.4, -kInf, -kInf}, {0.0, kInf, kInf});
  EXPECT_GT(changed, 0u);
  EXPECT_GE(map.bounds().min.x, 0);
  EXPECT_LT(map.memoryUsage().tiles, before.tiles);
  EXPECT_LT(map.memoryUsage().bytes_held, before.bytes_held);
  EXPECT_EQ(map.memoryUsage().cells_with_volumes, before.cells_with_volumes - changed);
  const std::optional<std::vector<TileIndex>> removed = map.tilesRemovedSince(revision);
  ASSERT_TRUE(removed.has_value());
  EXPECT_EQ(removed->size(), before.tiles - map.memoryUsage().tiles);
  for (const TileIndex& tile : *removed) EXPECT_LT(tile.x, 0);
}

TEST(ClearBox, CutsSplitPiecesAtTheBoxAndKeepsMassesInProportion) {
  Map map(test::unitConfig(100.0, ModelRules{}));
  map.setCellVolumes({0, 0}, CellVolumes{{{3, 5, 4}}, {{0, 3, 3}, {3, 5, 1}, {5, 9, 8}}});
  EXPECT_EQ(map.clearBox({0.0, 0.0, 4.2}, {1.0, 1.0, 6.0}), 1u);
  const CellVolumes after = map.cellVolumes({0, 0});
  ASSERT_EQ(after.positive.size(), 1u);
  EXPECT_TRUE(test::volumeIs(after.positive[0], 3, 4.2, 4 * 1.2 / 2));
  ASSERT_EQ(after.negative.size(), 3u);
  EXPECT_TRUE(test::volumeIs(after.negative[0], 0, 3, 3));
  EXPECT_TRUE(test::volumeIs(after.negative[1], 3, 4.2, 1 * 1.2 / 2));
  EXPECT_TRUE(test::volumeIs(after.negative[2], 6, 9, 8 * 3.0 / 4));
  EXPECT_TRUE(test::mapSatisfiesConstraints(map));
  // A part lower than 1 goes: [3, 4.2] cut at 3.5 leaves [3, 3.5].
  EXPECT_EQ(map.clearBox({0.0, 0.0, 3.5}, {1.0, 1.0, 5.0}), 1u);
  const CellVolumes cut = map.cellVolumes({0, 0});
  EXPECT_TRUE(cut.positive.empty());
  ASSERT_EQ(cut.negative.size(), 2u);
  EXPECT_TRUE(test::volumeIs(cut.negative[0], 0, 3, 3));
  EXPECT_TRUE(test::mapSatisfiesConstraints(map));
  // Nothing there: nothing changes.
  const std::uint64_t revision = map.revision();
  EXPECT_EQ(map.clearBox({5.0, 5.0, 0.0}, {6.0, 6.0, 1.0}), 0u);
  EXPECT_EQ(map.revision(), revision);
}

TEST(ClearBox, AThinBoxClearsALittleMoreThanACellHigh) {
  // A box 0.1 high, and one exactly 1 high: cut there, the parts would lie 1 or less apart, which
  // Sec. III-A forbids (gaps > 1): each is widened around its centre.
  for (const double top : {5.1, 6.0}) {
    SCOPED_TRACE(top);
    Map map(test::unitConfig(100.0, ModelRules::paper()));
    map.setCellVolumes({0, 0}, CellVolumes{{{0, 10, 10}}, {}});
    EXPECT_EQ(map.clearBox({0.0, 0.0, 5.0}, {1.0, 1.0, top}), 1u);
    const CellVolumes after = map.cellVolumes({0, 0});
    ASSERT_EQ(after.positive.size(), 2u);
    EXPECT_GT(after.positive[1].bottom - after.positive[0].top, 1.0f);  // a gap over 1
    EXPECT_LT(after.positive[1].bottom - after.positive[0].top, 1.0001f);
    EXPECT_FLOAT_EQ(0.5f * (after.positive[0].top + after.positive[1].bottom),
                    static_cast<float>(0.5 * (5.0 + top)));
    EXPECT_TRUE(test::mapSatisfiesConstraints(map));
  }
}

TEST(ClearBox, PartsExactlyOneHighStayAndVolumesTouchingTheBoxAreNotChanged) {
  // Resolution 1. Cell (0, 0): a volume [0, 10], cleared over [1, 5]: the part below, [0, 1], is
  // exactly 1 high, not lower: it stays, with the mass in proportion (1 of 10).
  Map map(test::unitConfig(100.0, ModelRules::paper()));
  map.setCellVolumes({0, 0}, CellVolumes{{{0, 10, 10}}, {}});
  EXPECT_EQ(map.clearBox({0.0, 0.0, 1.0}, {1.0, 1.0, 5.0}), 1u);
  const CellVolumes after = map.cellVolumes({0, 0});
  ASSERT_EQ(after.positive.size(), 2u);
  EXPECT_TRUE(test::volumeIs(after.positive[0], 0.0, 1.0, 1.0));
  EXPECT_TRUE(test::volumeIs(after.positive[1], 5.0, 10.0, 5.0));
  // Cell (5, 0): volumes [0, 2] and [6, 8] only touch a box over [2, 6]: nothing of them lies
  // within it, no cell changes.
  map.setCellVolumes({5, 0}, CellVolumes{{{0, 2, 2}, {6, 8, 2}}, {}});
  const std::uint64_t revision = map.revision();
  EXPECT_EQ(map.clearBox({5.0, 0.0, 2.0}, {6.0, 1.0, 6.0}), 0u);
  EXPECT_EQ(map.revision(), revision);
  EXPECT_EQ(map.cellVolumes({5, 0}).positive.size(), 2u);
}

TEST(ClearBox, RefusesNaNEmptyAndInvertedBoxesChangingNothing) {
  Map map = coarseRandomMap(15);
  const Bytes bytes = serialized(map);
  const std::uint64_t revision = map.revision();
  const Eigen::Vector3d low(-1.0, -1.0, -1.0);
  const Eigen::Vector3d high(1.0, 1.0, 1.0);
  for (int axis = 0; axis < 3; ++axis) {
    Eigen::Vector3d nan_corner = low;
    nan_corner[axis] = kNaN;
    EXPECT_THROW(map.clearBox(nan_corner, high), ConfigError);
    EXPECT_THROW(map.clearBox(low, nan_corner), ConfigError);
    Eigen::Vector3d flat = high;
    flat[axis] = low[axis];
    EXPECT_THROW(map.clearBox(low, flat), ConfigError);  // empty
    Eigen::Vector3d inverted = high;
    inverted[axis] = -2.0;
    EXPECT_THROW(map.clearBox(low, inverted), ConfigError);
    Eigen::Vector3d infinite = low;
    infinite[axis] = kInf;
    EXPECT_THROW(map.clearBox(infinite, high), ConfigError);  // inverted too
  }
  EXPECT_EQ(map.revision(), revision);
  EXPECT_EQ(serialized(map), bytes);
  EXPECT_EQ(map.clearBox({-1.0, -1.0, 1e300}, {1.0, 1.0, 1e301}), 0u);  // above everything
  EXPECT_EQ(map.clearBox({-1.0, -1.0, 1e300}, {1.0, 1.0, kInf}), 0u);
  EXPECT_EQ(serialized(map), bytes);
  EXPECT_GT(map.clearBox({-kInf, -kInf, -kInf}, {kInf, kInf, kInf}), 0u);  // everything
  EXPECT_TRUE(map.empty());
  EXPECT_EQ(map.memoryUsage().tiles, 0u);
}

// ---- The record of removed tiles
// -------------------------------------------------------------------

TEST(TileRemovals, AreListedSinceARevisionUntilTheMapNoLongerKnows) {
  Map map(test::unitConfig(1e6));
  const std::uint64_t start = map.revision();
  for (int k = 0; k < 4; ++k) map.setCellVolumes({16 * k, 0}, CellVolumes{{{0, 1, 1}}, {}});
  const std::uint64_t filled = map.revision();
  map.setCellVolumes({16, 0}, CellVolumes{});
  const std::uint64_t one_gone = map.revision();
  map.setCellVolumes({48, 0}, CellVolumes{});
  map.setCellVolumes({16, 0}, CellVolumes{{{0, 1, 1}}, {}});  // back again: not listed
  auto listed = [&](std::uint64_t revision) {
    std::vector<std::pair<int, int>> tiles;
    const std::optional<std::vector<TileIndex>> removed = map.tilesRemovedSince(revision);
    for (const TileIndex& t : removed.value()) tiles.emplace_back(t.x, t.y);
    return tiles;
  };
  EXPECT_EQ(listed(start), (std::vector<std::pair<int, int>>{{3, 0}}));
  EXPECT_EQ(listed(filled), (std::vector<std::pair<int, int>>{{3, 0}}));
  EXPECT_EQ(listed(one_gone), (std::vector<std::pair<int, int>>{{3, 0}}));
  EXPECT_TRUE(listed(map.revision()).empty());
  // clear() removes every tile without listing them: older revisions are no longer answered.
  map.clear();
  EXPECT_FALSE(map.tilesRemovedSince(one_gone).has_value());
  EXPECT_TRUE(map.tilesRemovedSince(map.revision()).has_value());
}

TEST(TileRemovals, TheRecordIsBoundedAndSaysWhenItForgot) {
  // Tiles created and removed again and again (a person walking, forgotten): the record keeps a
  // bounded number of removals, and says it no longer knows about the oldest.
  Map map(test::unitConfig(1e6));
  const std::uint64_t start = map.revision();
  std::size_t most_bytes = 0;
  for (int k = 0; k < 150000; ++k) {
    map.setCellVolumes({16 * (k % 7), 0}, CellVolumes{{{0, 1, 1}}, {}});
    map.setCellVolumes({16 * (k % 7), 0}, CellVolumes{});
    if (k % 1000 == 0) most_bytes = std::max(most_bytes, map.memoryUsage().bytes_held);
  }
  EXPECT_LE(most_bytes, std::size_t{2} << 20);
  EXPECT_FALSE(map.tilesRemovedSince(start).has_value());
  const std::optional<std::vector<TileIndex>> recent = map.tilesRemovedSince(map.revision() - 20);
  ASSERT_TRUE(recent.has_value());
  EXPECT_EQ(recent->size(), 7u);
}

TEST(DropTiles, ATileAtExactlyTheRadiusStays) {
  // Resolution 1: cell (5, 5) in tile (0, 0), cell (20, 5) in tile (1, 0) (x in [16, 32)). From
  // (5.5, 5.5), tile (0, 0) lies at 0 and tile (1, 0) at 10.5: neither is wholly farther than a
  // radius of 10.5, and only tile (1, 0) is wholly farther than a radius of 0.
  Map map(test::unitConfig());
  map.setCellVolumes({{{5, 5}, {{{0, 1, 1}}, {}}}, {{20, 5}, {{{0, 1, 1}}, {}}}});
  EXPECT_TRUE(map.dropTilesFartherThan({5.5, 5.5}, 10.5).empty());
  const Map dropped = map.dropTilesFartherThan({5.5, 5.5}, 0.0);
  EXPECT_EQ(tilesOf(map), (std::set<std::pair<int, int>>{{0, 0}}));
  EXPECT_EQ(tilesOf(dropped), (std::set<std::pair<int, int>>{{1, 0}}));
  // The dropped map's tiles are changes since a new map's revision (Map::tilesModifiedSince).
  const std::vector<TileIndex> modified =
      dropped.tilesModifiedSince(Map(dropped.config()).revision());
  ASSERT_EQ(modified.size(), 1u);
  EXPECT_EQ(modified[0], (TileIndex{1, 0}));
}

TEST(TileRemovals, ARemovalIsNotListedSinceTheRevisionItMade) {
  // tilesRemovedSince(r) lists the tiles removed after r: not one removed by the change that
  // made r (as tilesModifiedSince(r) does not list the tiles that change modified).
  Map map(test::unitConfig());
  map.setCellVolumes({{{0, 0}, {{{0, 1, 1}}, {}}}, {{16, 0}, {{{0, 1, 1}}, {}}}});
  const std::uint64_t before = map.revision();
  EXPECT_EQ(map.clearBox({16.0, 0.0, -10.0}, {17.0, 1.0, 10.0}), 1u);
  const std::optional<std::vector<TileIndex>> since_before = map.tilesRemovedSince(before);
  ASSERT_TRUE(since_before.has_value());
  EXPECT_EQ(since_before->size(), 1u);
  const std::optional<std::vector<TileIndex>> since_now = map.tilesRemovedSince(map.revision());
  ASSERT_TRUE(since_now.has_value());
  EXPECT_TRUE(since_now->empty());
}

}  // namespace
}  // namespace mvog
