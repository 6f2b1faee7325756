// Surfaces with their clearance, and the traversable map of a ground robot (mvog/surfaces.h).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "mvog/surfaces.h"
#include "planning_scene.h"
#include "test_util.h"

namespace mvog {
namespace {

constexpr double kCell = test::kSceneResolution;

/// The surfaces of the cell holding (x, y), from the lowest.
std::vector<Surface> surfacesAt(const Surfaces& surfaces, double x, double y) {
  std::vector<Surface> result;
  for (const Surface& s : surfaces.surfaces()) {
    if (std::floor(s.x / kCell) == std::floor(x / kCell) &&
        std::floor(s.y / kCell) == std::floor(y / kCell)) {
      result.push_back(s);
    }
  }
  return result;
}

TEST(Surfaces, ADeskGivesTwoSurfacesAndTheFloorUnderItItsClearance) {
  const Map map = test::sceneMap();
  Surfaces surfaces;
  surfaces.update(map);
  // Under and on the desk: the floor (z = 0) up to the board's underside (0.7), the board's top
  // (0.8) up to the ceiling (2.5), and the ceiling's top with unknown space above it.
  const std::vector<Surface> desk = surfacesAt(surfaces, 1.55, 1.05);
  ASSERT_EQ(desk.size(), 3u);
  EXPECT_FLOAT_EQ(desk[0].x, 1.55f);
  EXPECT_FLOAT_EQ(desk[0].y, 1.05f);
  EXPECT_FLOAT_EQ(desk[0].z, 0.0f);
  EXPECT_NEAR(desk[0].clearance, 0.7, 1e-6);
  EXPECT_TRUE(desk[0].capped);
  EXPECT_EQ(desk[0].probability, 1.0f);  // the floor below its top: positive only
  EXPECT_NEAR(desk[1].z, 0.8, 1e-6);
  EXPECT_NEAR(desk[1].clearance, 1.7, 1e-6);
  EXPECT_TRUE(desk[1].capped);
  EXPECT_NEAR(desk[1].probability, 5.0 / 5.1, 1e-6);
  EXPECT_NEAR(desk[2].z, 2.6, 1e-6);
  EXPECT_EQ(desk[2].clearance, 0.0f);
  EXPECT_FALSE(desk[2].capped);
  // Elsewhere in the room: the floor up to the ceiling, and the ceiling.
  const std::vector<Surface> floor = surfacesAt(surfaces, 2.55, 2.55);
  ASSERT_EQ(floor.size(), 2u);
  EXPECT_FLOAT_EQ(floor[0].z, 0.0f);
  EXPECT_NEAR(floor[0].clearance, 2.5, 1e-6);
  // A wall: one top, nothing known above it. Nothing beyond the room.
  ASSERT_EQ(surfacesAt(surfaces, 4.05, 0.55).size(), 1u);
  EXPECT_TRUE(surfacesAt(surfaces, 2.55, 3.55).empty());
  // Every column of the scene has its surfaces: 2 in the room's 1099 cells besides the desk's
  // 100 (3 each) and the pillar, 1 in each of the 94 wall cells and the pillar, 2 in the door's 8.
  EXPECT_EQ(surfaces.surfaces().size(), 1099u * 2u + 100u * 3u + 95u + 8u * 2u);
}

TEST(Surfaces, ATopsProbabilityIsTheOneJustBelowIt) {
  // Resolution 1, cell (0, 0): an obstacle [0, 2] of density 1 and free space [1, 2] of density
  // 1: p = 1 over [0, 1) and 0.5 over (1, 2], both occupied (threshold 0.324). One top at z = 2,
  // its probability eq. (9) just below it: 0.5.
  Map map(test::unitConfig());
  map.setCellVolumes({0, 0}, CellVolumes{{{0.0f, 2.0f, 2.0f}}, {{1.0f, 2.0f, 1.0f}}});
  ASSERT_EQ(*map.occupancy({0.5, 0.5, 1.9}).probability, 0.5f);
  Surfaces surfaces;
  surfaces.update(map);
  ASSERT_EQ(surfaces.surfaces().size(), 1u);
  EXPECT_EQ(surfaces.surfaces()[0].z, 2.0f);
  EXPECT_EQ(surfaces.surfaces()[0].probability, 0.5f);
}

TEST(Surfaces, ClearanceEndsAtUnknownSpaceUncapped) {
  Map map(test::unitConfig(10000.0, ModelRules{}));
  // Floor [0, 1], free up to 4, unknown above; a gap of 2 between free spaces counts as unknown.
  map.setCellVolumes(
      {{{0, 0}, {{test::obstacle(0, 1)}, {test::freeSpace(1, 4)}}},
       {{1, 0}, {{test::obstacle(0, 1)}, {test::freeSpace(1, 4), test::freeSpace(6, 9)}}}});
  Surfaces surfaces;
  surfaces.update(map);
  ASSERT_EQ(surfaces.surfaces().size(), 2u);
  for (const Surface& s : surfaces.surfaces()) {
    EXPECT_EQ(s.z, 1.0f);
    EXPECT_EQ(s.clearance, 3.0f);
    EXPECT_FALSE(s.capped);
  }
}

TEST(Surfaces, InAScannedRoomTheTableGivesTwoSurfaces) {
  const Map map = test::scannedRoomMap();
  Surfaces surfaces;
  surfaces.update(map);
  // In the middle of the table: the floor with the underside 0.7 m above it (within a cell: hits
  // make obstacles one cell high around them), and the table's top.
  const std::vector<Surface> table = surfacesAt(surfaces, 1.05, -1.05);
  ASSERT_GE(table.size(), 2u);
  EXPECT_NEAR(table[0].z, 0.0, kCell);
  EXPECT_NEAR(table[0].clearance, 0.7, 2 * kCell);
  EXPECT_TRUE(table[0].capped);
  EXPECT_NEAR(table[1].z, 0.75, kCell);
  EXPECT_GT(table[1].clearance, 1.0f);
}

TEST(Surfaces, AnUpdateRecomputesTheChangedTilesOnly) {
  Map map = test::sceneMap();
  Surfaces surfaces;
  surfaces.update(map);
  map.setCellVolumes({25, 25}, test::deskColumn());  // tile (1, 1)
  surfaces.update(map);
  EXPECT_EQ(surfaces.tilesRecomputed(), 1u);
  EXPECT_EQ(surfacesAt(surfaces, 2.55, 2.55).size(), 3u);
  Surfaces fresh;
  fresh.update(map);
  EXPECT_TRUE(surfaces.surfaces() == fresh.surfaces());
  // Scans into a random map, and a map that is replaced.
  std::mt19937 rng(8);
  Map random(MapConfig{0.1, 1000.0, ModelRules{}});
  surfaces.clear();
  for (int k = 0; k < 5; ++k) {
    random.insertScan(test::randomScan(rng, test::randomPoint(rng, 2.0, 0.5), 300, 200, 4.0));
    surfaces.update(random);
    Surfaces again;
    again.update(random);
    EXPECT_TRUE(surfaces.surfaces() == again.surfaces()) << "scan " << k;
  }
}

// ---- The traversable map
// ----------------------------------------------------------------------

Traversability traversabilityAt(const TraversableMap& grid, double x, double y) {
  const CellIndex cell = cellAt(x / grid.resolution, y / grid.resolution);
  return grid.at(static_cast<std::size_t>(cell.x - grid.cells.min.x),
                 static_cast<std::size_t>(cell.y - grid.cells.min.y));
}

TEST(TraversableMap, TheFloorIsFreeAndTheDeskBlocksARobotTallerThanItsUnderside) {
  const Map map = test::sceneMap();
  PlanningConfig config;
  config.robot_height = 1.0;  // the desk's underside is 0.7 m above the floor
  const CellRange cells{{-3, -3}, {45, 35}};
  const TraversableMap grid = traversableMap(map, cells, config);
  EXPECT_EQ(grid.cells.min, cells.min);
  EXPECT_EQ(grid.values.size(), static_cast<std::size_t>(49 * 39));
  EXPECT_EQ(traversabilityAt(grid, 2.55, 2.55), Traversability::kTraversable);
  EXPECT_EQ(traversabilityAt(grid, 0.05, 0.05), Traversability::kTraversable);  // by the walls
  EXPECT_EQ(traversabilityAt(grid, 4.05, 1.45), Traversability::kTraversable);  // the door
  EXPECT_EQ(traversabilityAt(grid, 1.55, 1.05), Traversability::kBlocked);      // the desk
  EXPECT_EQ(traversabilityAt(grid, 1.05, 0.55), Traversability::kBlocked);
  EXPECT_EQ(traversabilityAt(grid, 0.95, 0.55), Traversability::kTraversable);  // beside it
  EXPECT_EQ(traversabilityAt(grid, 4.05, 0.55), Traversability::kBlocked);      // a wall
  EXPECT_EQ(traversabilityAt(grid, 3.05, 2.05), Traversability::kBlocked);      // the pillar
  EXPECT_EQ(traversabilityAt(grid, 2.55, 3.05), Traversability::kUnknown);      // unexplored
  EXPECT_EQ(traversabilityAt(grid, 4.25, 1.45), Traversability::kUnknown);      // past the door
  // A robot lower than the desk's underside passes under it.
  config.robot_height = 0.6;
  EXPECT_EQ(traversabilityAt(traversableMap(map, cells, config), 1.55, 1.05),
            Traversability::kTraversable);
  // A band that holds the desk's top: the robot could stand on it too.
  config.robot_height = 1.0;
  config.traversable_max_z = 1.0;
  EXPECT_EQ(traversabilityAt(traversableMap(map, cells, config), 1.55, 1.05),
            Traversability::kTraversable);
}

TEST(TraversableMap, StepsDropsAndUnknownClearance) {
  Map map = test::sceneMap();
  // A platform 0.3 m high over x, y in [2.5, 3.0) x [0.5, 1.0); a drop (its floor 2 m down)
  // over [0.0, 0.5) x [2.0, 2.5); a floor seen only 0.3 m up at (3.55, 0.55).
  std::vector<Map::CellAssignment> cells;
  for (int y = 5; y < 10; ++y) {
    for (int x = 25; x < 30; ++x) {
      cells.push_back(
          {{x, y}, {{test::obstacle(-1, 3), test::obstacle(25, 26)}, {test::freeSpace(3, 25)}}});
    }
  }
  for (int y = 20; y < 25; ++y) {
    for (int x = 0; x < 5; ++x) {
      cells.push_back(
          {{x, y},
           {{test::obstacle(-21, -20), test::obstacle(25, 26)}, {test::freeSpace(-20, 25)}}});
    }
  }
  cells.push_back({{35, 5}, {{test::obstacle(-1, 0)}, {test::freeSpace(0, 3)}}});
  map.setCellVolumes(cells);
  PlanningConfig config;
  config.robot_height = 1.0;
  const TraversableMap grid = traversableMap(map, {{-1, -1}, {40, 29}}, config);
  EXPECT_EQ(traversabilityAt(grid, 2.75, 0.75), Traversability::kTraversable);  // on top
  EXPECT_EQ(traversabilityAt(grid, 2.55, 0.75), Traversability::kBlocked);      // its edge
  EXPECT_EQ(traversabilityAt(grid, 2.45, 0.75), Traversability::kBlocked);      // the step
  EXPECT_EQ(traversabilityAt(grid, 2.35, 0.75), Traversability::kTraversable);
  EXPECT_EQ(traversabilityAt(grid, 0.25, 2.25), Traversability::kBlocked);  // the drop
  EXPECT_EQ(traversabilityAt(grid, 3.55, 0.55), Traversability::kUnknown);
  config.max_step = 0.35;
  EXPECT_EQ(traversabilityAt(traversableMap(map, {{-1, -1}, {40, 29}}, config), 2.45, 0.75),
            Traversability::kTraversable);
}

TEST(TraversableMap, RefusesBadArguments) {
  const Map map = test::sceneMap();
  EXPECT_THROW(traversableMap(map, kNoCells), ConfigError);
  EXPECT_THROW(traversableMap(map, {{0, 0}, {1 << 15, 1 << 15}}), ConfigError);
  PlanningConfig config;
  config.robot_height = 0.0;
  EXPECT_THROW(traversableMap(map, {{0, 0}, {1, 1}}, config), ConfigError);
  config = {};
  config.max_step = -0.1;
  EXPECT_THROW(traversableMap(map, {{0, 0}, {1, 1}}, config), ConfigError);
  config = {};
  config.traversable_min_z = NAN;
  EXPECT_THROW(Surfaces{config}, ConfigError);
}

TEST(TraversableMap, TheBoundsOfBandClearanceAndStepAreIncluded) {
  // Resolution 1; band [0, 2], robot_height 2, max_step 1. Each group of cells lies apart.
  //  (0, 0):  a floor whose top 0 lies on the band's min, free above: traversable.
  //  (10, 0): a top at 0.5 with exactly robot_height = 2 free above it, then a ceiling:
  //           traversable (a clearance of at least robot_height).
  //  (20, 0), (21, 0): tops at 0.5 and 1.5, a step of exactly max_step: both traversable.
  //  (30, 0), (30, 1): tops at 0.5 and 2.0 (on the band's max), a step of 1.5: both blocked,
  //           each by its neighbour along y.
  Map map(test::unitConfig());
  map.setCellVolumes(
      {{{0, 0}, {{test::obstacle(-1, 0)}, {test::freeSpace(0, 5)}}},
       {{10, 0},
        {{test::obstacle(-1, 0.5f), test::obstacle(2.5f, 4)}, {test::freeSpace(0.5f, 2.5f)}}},
       {{20, 0}, {{test::obstacle(-1, 0.5f)}, {test::freeSpace(0.5f, 5)}}},
       {{21, 0}, {{test::obstacle(-1, 1.5f)}, {test::freeSpace(1.5f, 5)}}},
       {{30, 0}, {{test::obstacle(-1, 0.5f)}, {test::freeSpace(0.5f, 5)}}},
       {{30, 1}, {{test::obstacle(-1, 2)}, {test::freeSpace(2, 5)}}}});
  PlanningConfig config;
  config.traversable_min_z = 0.0;
  config.traversable_max_z = 2.0;
  config.robot_height = 2.0;
  config.max_step = 1.0;
  const TraversableMap grid = traversableMap(map, {{-1, -1}, {32, 2}}, config);
  EXPECT_EQ(traversabilityAt(grid, 0.5, 0.5), Traversability::kTraversable);
  EXPECT_EQ(traversabilityAt(grid, 10.5, 0.5), Traversability::kTraversable);
  EXPECT_EQ(traversabilityAt(grid, 20.5, 0.5), Traversability::kTraversable);
  EXPECT_EQ(traversabilityAt(grid, 21.5, 0.5), Traversability::kTraversable);
  EXPECT_EQ(traversabilityAt(grid, 30.5, 0.5), Traversability::kBlocked);
  EXPECT_EQ(traversabilityAt(grid, 30.5, 1.5), Traversability::kBlocked);
}

}  // namespace
}  // namespace mvog
