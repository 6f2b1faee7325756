// Frontiers (mvog/frontiers.h) and the tile-by-tile bookkeeping they are kept with
// (mvog/tile_changes.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <set>
#include <tuple>
#include <vector>

#include "mvog/frontiers.h"
#include "mvog/tile_changes.h"
#include "planning_scene.h"
#include "test_util.h"

namespace mvog {
namespace {

using Tiles = std::vector<std::pair<int, int>>;

Tiles tilesOf(const std::vector<TileIndex>& tiles) {
  Tiles result;
  for (const TileIndex& t : tiles) result.emplace_back(t.x, t.y);
  return result;
}

// ---- TileChanges
// ------------------------------------------------------------------------------

TEST(TileChanges, ListsModifiedAndRemovedTiles) {
  Map map(test::unitConfig());
  map.setCellVolumes({{{1, 1}, {{{0, 1, 1}}, {}}}, {{20, 1}, {{{0, 1, 1}}, {}}}});
  TileChanges changes;
  EXPECT_EQ(tilesOf(changes.update(map)), (Tiles{{0, 0}, {1, 0}}));
  EXPECT_TRUE(changes.update(map).empty());
  map.insertReading({0.5, 0.5, 0}, {5.5, 0.5, 0}, ReadingKind::kObstacle);
  EXPECT_EQ(tilesOf(changes.update(map)), (Tiles{{0, 0}}));
  // Emptying the only cell of tile (1, 0) removes the tile: tilesModifiedSince cannot list it.
  const std::uint64_t revision = map.revision();
  map.setCellVolumes({20, 1}, CellVolumes{});
  EXPECT_TRUE(map.tilesModifiedSince(revision).empty());
  EXPECT_EQ(tilesOf(changes.update(map)), (Tiles{{1, 0}}));
  // A tile that came and went between two calls changed nothing that a call saw.
  map.setCellVolumes({-1, -40}, CellVolumes{{{0, 1, 1}}, {}});
  map.clear();
  EXPECT_EQ(tilesOf(changes.update(map)), (Tiles{{0, 0}}));
  EXPECT_TRUE(changes.update(map).empty());
}

TEST(TileChanges, AfterAResetOrAnOlderMapEverythingChanged) {
  Map map(test::unitConfig());
  map.setCellVolumes({{{1, 1}, {{{0, 1, 1}}, {}}}, {{20, 1}, {{{0, 1, 1}}, {}}}});
  map.setCellVolumes({40, 1}, CellVolumes{{{0, 1, 1}}, {}});
  TileChanges changes;
  changes.update(map);
  // A new map (its revisions start again) holding other tiles: those gone and those there.
  Map other(test::unitConfig());
  other.setCellVolumes({-5, 1}, CellVolumes{{{0, 1, 1}}, {}});
  EXPECT_EQ(tilesOf(changes.update(other)), (Tiles{{-1, 0}, {0, 0}, {1, 0}, {2, 0}}));
  changes.reset();
  EXPECT_EQ(tilesOf(changes.update(other)), (Tiles{{-1, 0}}));
}

TEST(TileChanges, ATileWhoseFirstCellIsEmptiedIsListedOnceAndThenOnlyWhenItChanges) {
  Map map(test::unitConfig());
  map.setCellVolumes({{{1, 1}, {{{0, 1, 1}}, {}}}, {{5, 9}, {{{0, 1, 1}}, {}}}});
  TileChanges changes;
  EXPECT_EQ(tilesOf(changes.update(map)), (Tiles{{0, 0}}));
  // Tile (0, 0) loses a cell but keeps another: it changed, and is still there.
  map.setCellVolumes({1, 1}, CellVolumes{});
  EXPECT_EQ(tilesOf(changes.update(map)), (Tiles{{0, 0}}));
  // Then only tile (1, 0) changes: tile (0, 0) did not.
  map.setCellVolumes({20, 1}, CellVolumes{{{0, 1, 1}}, {}});
  EXPECT_EQ(tilesOf(changes.update(map)), (Tiles{{1, 0}}));
  EXPECT_TRUE(changes.update(map).empty());
  // Emptying its last cell removes tile (0, 0).
  map.setCellVolumes({5, 9}, CellVolumes{});
  EXPECT_EQ(tilesOf(changes.update(map)), (Tiles{{0, 0}}));
}

TEST(TileChanges, NeighbourTiles) {
  EXPECT_EQ(tilesOf(withNeighbourTiles({{0, 0}, {1, 0}})),
            (Tiles{{0, -1}, {1, -1}, {-1, 0}, {0, 0}, {1, 0}, {2, 0}, {0, 1}, {1, 1}}));
  EXPECT_TRUE(withNeighbourTiles({}).empty());
}

// ---- Frontiers
// --------------------------------------------------------------------------------

/// The frontier voxels as (cell x, cell y, voxel z) of the scene (resolution 0.1).
using Voxel = std::tuple<int, int, int>;
std::set<Voxel> voxelsOf(const Frontiers& frontiers) {
  std::set<Voxel> voxels;
  for (const FrontierPoint& p : frontiers.points()) {
    voxels.emplace(static_cast<int>(std::floor(p.x / test::kSceneResolution)),
                   static_cast<int>(std::floor(p.y / test::kSceneResolution)),
                   static_cast<int>(std::floor(p.z / test::kSceneResolution)));
  }
  return voxels;
}

TEST(Frontiers, AtTheDoorAndTheUnexploredEdgeAndNowhereElse) {
  const Map map = test::sceneMap();
  Frontiers frontiers;
  frontiers.update(map);
  std::set<Voxel> expected;
  for (int y = 10; y < 18; ++y) {  // the door's cells, free up to 2.0 m, unknown beyond
    for (int z = 0; z < 20; ++z) expected.emplace(40, y, z);
  }
  for (int x = 0; x < 40; ++x) {  // the cells along y = 3.0, unknown beyond, free up to 2.5 m
    for (int z = 0; z < 25; ++z) expected.emplace(x, 29, z);
  }
  EXPECT_EQ(voxelsOf(frontiers), expected);
  EXPECT_EQ(frontiers.points().size(), expected.size());
  EXPECT_EQ(frontiers.numClusters(), 2u);
  // The door's voxels form one cluster, the edge's the other.
  std::set<std::uint32_t> door;
  std::set<std::uint32_t> edge;
  for (const FrontierPoint& p : frontiers.points()) (p.x > 4.0f ? door : edge).insert(p.cluster);
  EXPECT_EQ(door.size(), 1u);
  EXPECT_EQ(edge.size(), 1u);
  EXPECT_NE(*door.begin(), *edge.begin());
}

TEST(Frontiers, WithinTheBandOnly) {
  const Map map = test::sceneMap();
  PlanningConfig config;
  config.frontier_min_z = 0.5;
  config.frontier_max_z = 1.5;
  Frontiers frontiers(config);
  frontiers.update(map);
  EXPECT_EQ(frontiers.points().size(), 8u * 10u + 40u * 10u);
  for (const FrontierPoint& p : frontiers.points()) {
    EXPECT_GT(p.z, 0.5f);
    EXPECT_LT(p.z, 1.5f);
  }
}

TEST(Frontiers, TheTopAndBottomOfFreeSpaceMeetingUnknownAndSmallPiecesDropped) {
  // One cell, free over [1, 4] (grid units, resolution 1), unknown around: its voxels 1..3 touch
  // unknown neighbours, its top and bottom meet unknown space. Another, free over [1, 40].
  Map map(test::unitConfig(10000.0, ModelRules{}));
  map.setCellVolumes(
      {{{5, 5}, {{}, {test::freeSpace(1, 4)}}}, {{50, 50}, {{}, {test::freeSpace(1, 40)}}}});
  PlanningConfig config;
  config.frontier_min_cells = 3;
  Frontiers frontiers(config);
  frontiers.update(map);
  EXPECT_EQ(frontiers.numClusters(), 2u);
  config.frontier_min_cells = 4;
  Frontiers fewer(config);
  fewer.update(map);
  EXPECT_EQ(fewer.numClusters(), 1u);
  ASSERT_EQ(fewer.points().size(), 39u);
  EXPECT_EQ(fewer.points().front().z, 1.5f);
  EXPECT_EQ(fewer.points().back().z, 39.5f);
  // Free space capped by an obstacle has no frontier at its top.
  map.setCellVolumes({50, 50}, {{{40, 41, 2}}, {test::freeSpace(1, 40)}});
  fewer.update(map);
  EXPECT_EQ(fewer.points().size(), 39u);
  map.setCellVolumes({50, 50}, {{{0, 1, 2}, {40, 41, 2}}, {test::freeSpace(1, 40)}});
  fewer.update(map);
  EXPECT_EQ(fewer.points().size(), 39u);  // the lateral ones only, all of them
}

/// `a` holds the same frontiers as `b`.
::testing::AssertionResult sameFrontiers(const Frontiers& a, const Frontiers& b) {
  if (a.numClusters() == b.numClusters() && a.points() == b.points()) {
    return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure()
         << a.numClusters() << " and " << b.numClusters() << " clusters, " << a.points().size()
         << " and " << b.points().size() << " points";
}

TEST(Frontiers, AnUpdateRecomputesTheChangedTilesAndTheirNeighboursOnly) {
  Map map = test::sceneMap();
  Frontiers frontiers;
  frontiers.update(map);
  // Close the door: its tiles (2, 0) and (2, 1) and their six neighbours are recomputed.
  std::vector<Map::CellAssignment> door;
  for (int y = 10; y < 18; ++y) door.push_back({{40, y}, test::wallColumn()});
  map.setCellVolumes(door);
  frontiers.update(map);
  EXPECT_EQ(frontiers.tilesRecomputed(), 8u);
  EXPECT_EQ(frontiers.numClusters(), 1u);
  Frontiers fresh;
  fresh.update(map);
  EXPECT_TRUE(sameFrontiers(frontiers, fresh));
  frontiers.update(map);
  EXPECT_EQ(frontiers.tilesRecomputed(), 0u);
  // Empty a whole tile (the map removes it): its neighbours see unknown space there.
  std::vector<Map::CellAssignment> emptied;
  for (int y = 0; y < 16; ++y) {
    for (int x = 16; x < 32; ++x) emptied.push_back({{x, y}, {}});
  }
  map.setCellVolumes(emptied);
  frontiers.update(map);
  Frontiers fresh_again;
  fresh_again.update(map);
  EXPECT_TRUE(sameFrontiers(frontiers, fresh_again));
  EXPECT_GT(frontiers.points().size(), fresh.points().size());
  // Clearing the map leaves no frontier.
  map.clear();
  frontiers.update(map);
  EXPECT_TRUE(frontiers.points().empty());
  EXPECT_EQ(frontiers.numClusters(), 0u);
}

TEST(Frontiers, IncrementalEqualsFromScratchWhileAMapIsBuilt) {
  Map map(MapConfig{0.1, 1000.0, ModelRules{}});
  std::mt19937 rng(4);
  Frontiers incremental;
  for (int k = 0; k < 6; ++k) {
    map.insertScan(test::randomScan(rng, test::randomPoint(rng, 2.0, 0.5), 300, 200, 4.0));
    incremental.update(map);
    Frontiers fresh;
    fresh.update(map);
    EXPECT_TRUE(sameFrontiers(incremental, fresh)) << "scan " << k;
    EXPECT_GT(fresh.points().size(), 0u);
  }
  // A replaced map: clear() forgets everything.
  map = test::sceneMap();
  incremental.clear();
  incremental.update(map);
  Frontiers fresh;
  fresh.update(map);
  EXPECT_TRUE(sameFrontiers(incremental, fresh));
}

TEST(Frontiers, InAScannedRoomBeyondTheDoorNotInTheMiddle) {
  const Map map = test::scannedRoomMap();
  Frontiers frontiers;
  frontiers.update(map);
  std::size_t beyond_door = 0;
  for (const FrontierPoint& p : frontiers.points()) {
    beyond_door += p.x > 3.2f && p.x < 5.0f && std::abs(p.y) < 2.0f;
    // Around the poses, away from the objects, the map is known.
    EXPECT_FALSE(std::abs(p.x) < 1.0f && p.y > -0.2f && p.y < 1.0f && p.z > 0.3f && p.z < 2.2f)
        << p.x << " " << p.y << " " << p.z;
  }
  EXPECT_GT(beyond_door, 100u);
}

TEST(Frontiers, RefusesAnInvalidConfig) {
  PlanningConfig config;
  config.frontier_min_cells = 0;
  EXPECT_THROW(Frontiers{config}, ConfigError);
  config = {};
  config.frontier_min_z = 2.0;
  config.frontier_max_z = 1.0;
  EXPECT_THROW(Frontiers{config}, ConfigError);
}

/// The heights (m) of the frontier voxels of cell (x, y) at resolution 1, from the lowest.
std::vector<float> frontierHeightsAt(const Frontiers& frontiers, int x, int y) {
  std::vector<float> heights;
  for (const FrontierPoint& p : frontiers.points()) {
    if (p.x == static_cast<float>(x) + 0.5f && p.y == static_cast<float>(y) + 0.5f)
      heights.push_back(p.z);
  }
  return heights;
}

TEST(Frontiers, TopsAndBottomsOnTheBandsEdgesAndFacesMeetingUnknownAtOneHeight) {
  // Resolution 1. Cell (5, 5) and its four neighbours are free over [0, 5], unknown above and
  // below: the centre's free interval meets its neighbours' unknown space only at the heights 0
  // and 5 (no positive length: no lateral frontier); its top 5 has unknown space above (voxel 4)
  // and its bottom 0 unknown space below (voxel 0), each a frontier where it lies in the band,
  // the band's bounds included.
  // Cell (20, 20) is free over [0, 10.5] under an obstacle [10.5, 12], its four neighbours free
  // over [0, 10.5] only: their unknown space above meets its free space at 10.5 alone: only its
  // bottom (voxel 0) is a frontier.
  Map map(test::unitConfig());
  std::vector<Map::CellAssignment> cells;
  for (const CellIndex& c :
       {CellIndex{5, 5}, CellIndex{4, 5}, CellIndex{6, 5}, CellIndex{5, 4}, CellIndex{5, 6}}) {
    cells.push_back({c, {{}, {test::freeSpace(0, 5)}}});
  }
  cells.push_back({{20, 20}, {{test::obstacle(10.5f, 12)}, {test::freeSpace(0, 10.5f)}}});
  for (const CellIndex& c :
       {CellIndex{19, 20}, CellIndex{21, 20}, CellIndex{20, 19}, CellIndex{20, 21}}) {
    cells.push_back({c, {{}, {test::freeSpace(0, 10.5f)}}});
  }
  map.setCellVolumes(cells);
  const auto heights = [&](double min_z, double max_z, int x, int y) {
    PlanningConfig config;
    config.frontier_min_z = min_z;
    config.frontier_max_z = max_z;
    config.frontier_min_cells = 1;
    Frontiers frontiers(config);
    frontiers.update(map);
    return frontierHeightsAt(frontiers, x, y);
  };
  const double inf = test::kInf;
  EXPECT_EQ(heights(-inf, inf, 5, 5), (std::vector<float>{0.5f, 4.5f}));
  EXPECT_EQ(heights(5.0, inf, 5, 5), (std::vector<float>{4.5f}));  // the top on the band's min
  EXPECT_EQ(heights(-inf, 5.0, 5, 5), (std::vector<float>{0.5f, 4.5f}));  // ... on its max
  EXPECT_EQ(heights(0.0, inf, 5, 5), (std::vector<float>{0.5f, 4.5f}));   // the bottom on its min
  EXPECT_EQ(heights(-inf, 0.0, 5, 5), (std::vector<float>{0.5f}));        // ... on its max
  EXPECT_EQ(heights(-inf, inf, 20, 20), (std::vector<float>{0.5f}));
}

TEST(Frontiers, PiecesAre26Connected) {
  // Resolution 1, frontier_min_cells 1.
  //  - Cell (30, 30), free over [0, 5] with unknown space above and below; its neighbour (31, 30)
  //    is occupied over [0, 2] and [4, 6], the others over [-1, 6]: its frontier voxels are 0
  //    (bottom), 2 and 3 (beside the unknown [2, 4]) and 4 (top): 2, 3, 4 are one piece.
  //  - Cells (40, 40) and (41, 40), free over [4, 5] and [5, 6]: voxels 4 and 5, touching at an
  //    edge: one piece.
  //  - Cells (50, 50) and (49, 51), free over [4, 5]: voxels 4 and 4, touching at a vertical edge
  //    (diagonal neighbours): one piece.
  Map map(test::unitConfig());
  std::vector<Map::CellAssignment> cells{
      {{30, 30}, {{}, {test::freeSpace(0, 5)}}},
      {{31, 30}, {{test::obstacle(0, 2), test::obstacle(4, 6)}, {}}},
      {{40, 40}, {{}, {test::freeSpace(4, 5)}}},
      {{41, 40}, {{}, {test::freeSpace(5, 6)}}},
      {{50, 50}, {{}, {test::freeSpace(4, 5)}}},
      {{49, 51}, {{}, {test::freeSpace(4, 5)}}}};
  for (const CellIndex& c : {CellIndex{29, 30}, CellIndex{30, 29}, CellIndex{30, 31}}) {
    cells.push_back({c, {{test::obstacle(-1, 6)}, {}}});
  }
  map.setCellVolumes(cells);
  PlanningConfig config;
  config.frontier_min_cells = 1;
  Frontiers frontiers(config);
  frontiers.update(map);
  std::map<std::tuple<float, float, float>, std::uint32_t> cluster;
  for (const FrontierPoint& p : frontiers.points()) cluster[{p.x, p.y, p.z}] = p.cluster;
  ASSERT_EQ(frontierHeightsAt(frontiers, 30, 30), (std::vector<float>{0.5f, 2.5f, 3.5f, 4.5f}));
  EXPECT_NE(cluster.at({30.5f, 30.5f, 0.5f}), cluster.at({30.5f, 30.5f, 2.5f}));
  EXPECT_EQ(cluster.at({30.5f, 30.5f, 2.5f}), cluster.at({30.5f, 30.5f, 3.5f}));
  EXPECT_EQ(cluster.at({30.5f, 30.5f, 3.5f}), cluster.at({30.5f, 30.5f, 4.5f}));
  EXPECT_EQ(cluster.at({40.5f, 40.5f, 4.5f}), cluster.at({41.5f, 40.5f, 5.5f}));
  EXPECT_EQ(cluster.at({50.5f, 50.5f, 4.5f}), cluster.at({49.5f, 51.5f, 4.5f}));
  EXPECT_EQ(frontiers.numClusters(), 4u);
}

}  // namespace
}  // namespace mvog
