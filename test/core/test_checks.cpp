// Segment and box checks (mvog/checks.h) on the room of planning_scene.h, and the column profile
// they are built on.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "mvog/checks.h"
#include "mvog/column.h"
#include "planning_scene.h"
#include "test_util.h"

namespace mvog {
namespace {

SegmentCheck checkOne(const Map& map, const Eigen::Vector3d& start, const Eigen::Vector3d& end,
                      double radius) {
  return checkSegments(map, {{start, end}}, radius).at(0);
}

BoxCheck checkOne(const Map& map, const Eigen::Vector3d& min, const Eigen::Vector3d& max) {
  return checkBoxes(map, {{min, max}}).at(0);
}

// ---- The column profile over a stored column
// -------------------------------------------------

TEST(ColumnProfile, FromTheStoredColumnEqualsTheCopiedOneAndEquation9) {
  const Map map = test::randomMap(5, 0.1, 3.0);
  std::vector<ColumnSegment> stored;
  std::size_t columns = 0;
  for (const CellIndex& cell : test::observedCells(map)) {
    columnProfile(map.column(cell), stored);
    const std::vector<ColumnSegment> copied = columnProfile(map.cellVolumes(cell));
    ASSERT_EQ(stored.size(), copied.size());
    for (std::size_t k = 0; k < stored.size(); ++k) {
      EXPECT_EQ(stored[k].bottom, copied[k].bottom);
      EXPECT_EQ(stored[k].top, copied[k].top);
      EXPECT_EQ(stored[k].probability, copied[k].probability);
      // Eq. (9) at the middle of each segment, through the map's own point query.
      const double middle = 0.5 * (stored[k].bottom + stored[k].top) * 0.1;
      const PointOccupancy p = map.occupancy({(cell.x + 0.5) * 0.1, (cell.y + 0.5) * 0.1, middle});
      ASSERT_TRUE(p.known());
      EXPECT_FLOAT_EQ(*p.probability, stored[k].probability);
    }
    ++columns;
  }
  EXPECT_GT(columns, 1000u);
}

// ---- Segments
// ---------------------------------------------------------------------------------

TEST(SegmentChecks, ThroughAWallIsOccupiedAtTheWallsDistance) {
  const Map map = test::sceneMap();
  // The wall x = 4.0 lies 2.0 m from the start.
  const SegmentCheck check = checkOne(map, {2.0, 0.55, 1.0}, {4.5, 0.55, 1.0}, 0.0);
  EXPECT_EQ(check.state, OccupancyState::kOccupied);
  EXPECT_NEAR(check.blocked_at, 2.0, 1e-9);
  // Slanted, and downwards into the floor: 1 m along x, falling 1 m, meets z = 0 at sqrt(2).
  const SegmentCheck floor = checkOne(map, {0.5, 2.25, 1.0}, {1.5, 2.25, 0.0}, 0.0);
  EXPECT_EQ(floor.state, OccupancyState::kOccupied);
  EXPECT_NEAR(floor.blocked_at, std::sqrt(2.0), 1e-9);
}

TEST(SegmentChecks, ThroughTheOpenRoomIsFree) {
  const Map map = test::sceneMap();
  for (double radius : {0.0, 0.1, 0.3}) {
    // Diagonal over the desk (its top is 0.8 m), below the ceiling (2.5 m), clear of the pillar.
    const SegmentCheck check = checkOne(map, {0.5, 0.4, 1.2}, {3.5, 1.5, 1.5}, radius);
    EXPECT_EQ(check.state, OccupancyState::kFree) << "radius " << radius;
    EXPECT_TRUE(std::isnan(check.blocked_at));
  }
  // A segment of one point.
  EXPECT_EQ(checkOne(map, {2.5, 2.5, 1.0}, {2.5, 2.5, 1.0}, 0.0).state, OccupancyState::kFree);
  EXPECT_EQ(checkOne(map, {2.5, 2.5, 1.0}, {2.5, 2.5, 1.0}, 0.2).state, OccupancyState::kFree);
}

TEST(SegmentChecks, IntoNeverSeenSpaceIsUnknown) {
  const Map map = test::sceneMap();
  // Beyond y = 3.0 nothing was observed.
  SegmentCheck check = checkOne(map, {2.5, 2.5, 1.0}, {2.5, 3.5, 1.0}, 0.0);
  EXPECT_EQ(check.state, OccupancyState::kUnknown);
  EXPECT_NEAR(check.blocked_at, 0.5, 1e-9);
  // Through the door: free in the door's cells, unknown from x = 4.1 on.
  check = checkOne(map, {3.5, 1.45, 1.0}, {4.5, 1.45, 1.0}, 0.0);
  EXPECT_EQ(check.state, OccupancyState::kUnknown);
  EXPECT_NEAR(check.blocked_at, 0.6, 1e-9);
  // Up through the ceiling into the unknown above it: occupied wins over unknown, and the
  // first blocked point is the ceiling's bottom.
  check = checkOne(map, {2.5, 2.5, 1.0}, {2.5, 2.5, 3.0}, 0.0);
  EXPECT_EQ(check.state, OccupancyState::kOccupied);
  EXPECT_NEAR(check.blocked_at, 1.5, 1e-9);
}

TEST(SegmentChecks, AGrazedFaceIsOccupied) {
  // At exactly the floor's top the segment touches the obstacle's face: the height belongs to
  // both the floor and the free space above it.
  const Map map = test::sceneMap();
  EXPECT_EQ(checkOne(map, {0.5, 2.5, 0.0}, {3.5, 2.5, 0.0}, 0.0).state, OccupancyState::kOccupied);
  EXPECT_EQ(checkOne(map, {0.5, 2.5, 0.01}, {3.5, 2.5, 0.01}, 0.0).state, OccupancyState::kFree);
}

TEST(SegmentChecks, ARadiusCatchesAWallTheBareSegmentMisses) {
  const Map map = test::sceneMap();
  // Towards the wall x = 4.0, stopping 0.15 m before it.
  const Eigen::Vector3d start(3.0, 0.55, 1.0);
  const Eigen::Vector3d end(3.85, 0.55, 1.0);
  EXPECT_EQ(checkOne(map, start, end, 0.0).state, OccupancyState::kFree);
  EXPECT_EQ(checkOne(map, start, end, 0.14).state, OccupancyState::kFree);
  const SegmentCheck check = checkOne(map, start, end, 0.2);
  EXPECT_EQ(check.state, OccupancyState::kOccupied);
  EXPECT_NEAR(check.blocked_at, 0.8, 1e-9);  // the sphere's centre at x = 3.8
  // Over the floor: the sphere reaches down to the floor's top.
  EXPECT_EQ(checkOne(map, {0.5, 2.5, 0.35}, {1.5, 2.5, 0.35}, 0.3).state, OccupancyState::kFree);
  const SegmentCheck low = checkOne(map, {0.5, 2.5, 0.35}, {1.5, 2.5, 0.25}, 0.3);
  EXPECT_EQ(low.state, OccupancyState::kOccupied);
  EXPECT_NEAR(low.blocked_at, 0.5 * std::hypot(1.0, 0.1), 1e-9);  // where z = 0.3
}

TEST(SegmentChecks, TheSweptSphereIsRoundAtAnObstaclesEdge) {
  // Along y = 1.8, passing the pillar's face y = 2.0 at 0.2 m: with a radius of 0.21 the sphere
  // first meets its edge at x = 3.0 when (3.0 - x)^2 + 0.2^2 = 0.21^2.
  const Map map = test::sceneMap();
  const Eigen::Vector3d start(2.0, 1.8, 1.0);
  const Eigen::Vector3d end(3.5, 1.8, 1.0);
  EXPECT_EQ(checkOne(map, start, end, 0.19).state, OccupancyState::kFree);
  const SegmentCheck check = checkOne(map, start, end, 0.21);
  EXPECT_EQ(check.state, OccupancyState::kOccupied);
  EXPECT_NEAR(check.blocked_at, 1.0 - std::sqrt(0.21 * 0.21 - 0.2 * 0.2), 1e-9);
  // Along y = 0.3 at z = 1.0, beside and above the desk's board (y from 0.5, top at 0.8): the
  // sphere first meets the board's corner (1.0, 0.5, 0.8) when (1.0 - x)^2 + 0.2^2 + 0.2^2 =
  // r^2, and misses it below r = sqrt(0.08).
  EXPECT_EQ(checkOne(map, {0.5, 0.3, 1.0}, {1.5, 0.3, 1.0}, 0.28).state, OccupancyState::kFree);
  const SegmentCheck corner = checkOne(map, {0.5, 0.3, 1.0}, {1.5, 0.3, 1.0}, 0.29);
  EXPECT_EQ(corner.state, OccupancyState::kOccupied);
  EXPECT_NEAR(corner.blocked_at, 0.5 - std::sqrt(0.29 * 0.29 - 0.08), 1e-9);
}

TEST(SegmentChecks, InAScannedRoom) {
  const Map map = test::scannedRoomMap();
  // Through the wall x = -3 (hits on its face make its cell occupied: x in [-3.0, -2.9)).
  const SegmentCheck wall = checkOne(map, {0.0, 0.2, 1.2}, {-4.0, 0.2, 1.2}, 0.0);
  EXPECT_EQ(wall.state, OccupancyState::kOccupied);
  EXPECT_NEAR(wall.blocked_at, 3.0, test::kSceneResolution + 1e-9);  // 2.9: that cell entered
  // From one pose to another.
  EXPECT_EQ(checkOne(map, {-1.5, 0.0, 1.2}, {1.5, 0.8, 1.2}, 0.0).state, OccupancyState::kFree);
  // Up beyond the door, where the rays through it did not reach.
  EXPECT_EQ(checkOne(map, {4.0, 0.0, 1.0}, {4.0, 0.0, 3.5}, 0.0).state, OccupancyState::kUnknown);
  // Along the wall y = -2, 0.2 m from it: a radius of 0.25 m meets it.
  EXPECT_EQ(checkOne(map, {-1.0, -1.8, 1.2}, {-0.5, -1.8, 1.2}, 0.0).state, OccupancyState::kFree);
  EXPECT_EQ(checkOne(map, {-1.0, -1.8, 1.2}, {-0.5, -1.8, 1.2}, 0.25).state,
            OccupancyState::kOccupied);
}

TEST(SegmentChecks, BoundsTheWorkAndRefusesBadInput) {
  const Map map = test::sceneMap();
  PlanningConfig config;
  config.max_query_cells = 100;
  // 41 cells along x.
  EXPECT_NO_THROW(checkSegments(map, {{{0.05, 0.5, 1.0}, {4.05, 0.5, 1.0}}}, 0.0, config));
  EXPECT_NO_THROW(checkSegments(
      map, {{{0.05, 0.5, 1.0}, {4.05, 0.5, 1.0}}, {{0.05, 0.5, 1.0}, {4.05, 0.5, 1.0}}}, 0.0,
      config));
  try {
    checkSegments(map, std::vector<Segment>(3, Segment{{0.05, 0.5, 1.0}, {4.05, 0.5, 1.0}}), 0.0,
                  config);
    FAIL() << "not refused";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("max_query_cells"), std::string::npos) << e.what();
  }
  // With a radius the footprint is wider: 41 x 5 cells and more.
  EXPECT_THROW(checkSegments(map, {{{0.05, 0.5, 1.0}, {4.05, 0.5, 1.0}}}, 0.2, config),
               ConfigError);
  EXPECT_THROW(checkSegments(map, {{{0, 0, 0}, {1, 1, 1}}}, -0.1), ConfigError);
  EXPECT_THROW(checkSegments(map, {{{0, 0, 0}, {1, 1, 1}}}, NAN), ConfigError);
  // A radius beyond max_coordinate (10 km) is refused, however large: at 2^31 cells, a radius of
  // 1.08e8 m at 0.1 m once overflowed the swept rows' indices and the check answered free.
  for (double radius : {1.0e4 + 1.0, 1.08e8, 1.0e300}) {
    EXPECT_THROW(checkSegments(map, {{{0, 0, 0}, {1, 1, 1}}}, radius), ConfigError) << radius;
  }
  try {  // at max_coordinate: its cells are counted, and too many
    checkSegments(map, {{{0, 0, 0}, {1, 1, 1}}}, 1.0e4);
    FAIL() << "not refused";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("max_query_cells"), std::string::npos) << e.what();
  }
  EXPECT_THROW(checkSegments(map, {{{0, NAN, 0}, {1, 1, 1}}}, 0.0), ConfigError);
  EXPECT_THROW(checkSegments(map, {{{0, 0, 0}, {1e5, 1, 1}}}, 0.0), ConfigError);
  PlanningConfig bad;
  bad.occupancy_threshold = 1.0;
  EXPECT_THROW(checkSegments(map, {}, 0.0, bad), ConfigError);
  EXPECT_TRUE(checkSegments(map, {}, 0.0).empty());
}

TEST(SegmentChecks, ACheckerKeptAcrossChangesOfTheMapAnswersAsAFreshCheck) {
  Map map = test::sceneMap();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> x(0.2, 3.8);
  std::uniform_real_distribution<double> y(0.2, 2.8);
  std::uniform_real_distribution<double> z(0.3, 2.2);
  std::vector<Segment> segments;
  for (int k = 0; k < 300; ++k)
    segments.push_back({{x(rng), y(rng), z(rng)}, {x(rng), y(rng), z(rng)}});
  auto same = [&](SegmentChecker& checker, double radius) {
    const std::vector<SegmentCheck> kept = checker.check(map, segments, radius);
    const std::vector<SegmentCheck> fresh = checkSegments(map, segments, radius);
    std::size_t free = 0;
    for (std::size_t k = 0; k < segments.size(); ++k) {
      if (kept[k].state != fresh[k].state ||
          !(kept[k].blocked_at == fresh[k].blocked_at ||
            (std::isnan(kept[k].blocked_at) && std::isnan(fresh[k].blocked_at)))) {
        return ::testing::AssertionFailure() << "segment " << k << " differs";
      }
      free += fresh[k].state == OccupancyState::kFree;
    }
    if (free == 0 || free == segments.size()) {
      return ::testing::AssertionFailure() << free << " free: the test shows nothing";
    }
    return ::testing::AssertionSuccess();
  };
  for (double radius : {0.0, 0.2}) {
    SegmentChecker checker;
    EXPECT_TRUE(same(checker, radius));
    // An obstacle in open space: a column of the room occupied from floor to ceiling.
    std::vector<Map::CellAssignment> pillars;
    for (int cell_y = 2; cell_y < 28; cell_y += 3)
      pillars.push_back({{25, cell_y}, test::wallColumn()});
    map.setCellVolumes(pillars);
    EXPECT_TRUE(same(checker, radius));
    // A whole tile emptied (the map removes it): unknown space where the checker saw free space.
    std::vector<Map::CellAssignment> emptied;
    for (int cell_y = 16; cell_y < 30; ++cell_y) {
      for (int cell_x = 0; cell_x < 16; ++cell_x) emptied.push_back({{cell_x, cell_y}, {}});
    }
    map.setCellVolumes(emptied);
    EXPECT_TRUE(same(checker, radius));
    // Scans, which change many tiles; then another map altogether.
    map.insertScan(test::randomScan(rng, {2.0, 1.5, 1.0}, 200, 100, 2.0));
    EXPECT_TRUE(same(checker, radius));
    map = test::sceneMap();
    checker.clear();
    EXPECT_TRUE(same(checker, radius));
  }
}

// ---- Boxes
// ------------------------------------------------------------------------------------

/// The box check found `state`, and known_fraction and max_probability within 1e-6 (NaN: NaN).
::testing::AssertionResult boxIs(const BoxCheck& check, OccupancyState state, double known_fraction,
                                 double max_probability) {
  auto near = [](double a, double b) {
    return std::isnan(a) ? std::isnan(b) : std::abs(a - b) <= 1e-6;
  };
  if (check.state == state && near(check.known_fraction, known_fraction) &&
      near(check.max_probability, max_probability)) {
    return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure()
         << "state " << int(check.state) << ", known_fraction " << check.known_fraction
         << ", max_probability " << check.max_probability;
}

TEST(BoxChecks, ABoxOnTheDeskIsOccupied) {
  const Map map = test::sceneMap();
  // The board: rho+ 5, rho- 0.1.
  EXPECT_TRUE(boxIs(checkOne(map, {1.2, 0.7, 0.75}, {1.5, 1.0, 1.0}), OccupancyState::kOccupied,
                    1.0, 5.0 / 5.1));
}

TEST(BoxChecks, ABoxInTheAirIsFree) {
  const Map map = test::sceneMap();
  EXPECT_TRUE(
      boxIs(checkOne(map, {2.5, 2.0, 1.0}, {2.9, 2.5, 1.5}), OccupancyState::kFree, 1.0, 0.0));
}

TEST(BoxChecks, AHalfSeenBoxIsHalfKnown) {
  const Map map = test::sceneMap();
  // y in [2.8, 3.2]: known up to y = 3.0.
  EXPECT_TRUE(
      boxIs(checkOne(map, {1.0, 2.8, 1.0}, {1.5, 3.2, 1.5}), OccupancyState::kUnknown, 0.5, 0.0));
  // Nothing known at all.
  EXPECT_TRUE(
      boxIs(checkOne(map, {1.0, 5.0, 1.0}, {1.5, 5.5, 1.5}), OccupancyState::kUnknown, 0.0, NAN));
  // Through the ceiling into the unknown above it: occupied wins; known over [2.4, 2.6] of
  // [2.4, 2.8].
  EXPECT_TRUE(
      boxIs(checkOne(map, {1.0, 2.0, 2.4}, {1.5, 2.5, 2.8}), OccupancyState::kOccupied, 0.5, 1.0));
}

TEST(BoxChecks, AFlatBoxHasNoKnownFractionAndTheLimitHolds) {
  const Map map = test::sceneMap();
  const BoxCheck flat = checkOne(map, {1.2, 0.7, 0.75}, {1.5, 1.0, 0.75});
  EXPECT_EQ(flat.state, OccupancyState::kOccupied);
  EXPECT_TRUE(std::isnan(flat.known_fraction));
  PlanningConfig config;
  config.max_query_cells = 10;
  EXPECT_THROW(checkBoxes(map, {{{0, 0, 0}, {1, 1, 1}}}, config), ConfigError);
  EXPECT_THROW(checkBoxes(map, {{{0, 0, 0}, {-1, 1, 1}}}), ConfigError);
  EXPECT_THROW(checkBoxes(map, {{{0, 0, 0}, {INFINITY, 1, 1}}}), ConfigError);
}

TEST(SegmentChecks, TheLimitOfCellsIsInclusive) {
  // A segment along x over cells 0..40 (radius 0) visits 41 cells: at most 41 is allowed.
  const Map map = test::sceneMap();
  PlanningConfig config;
  config.max_query_cells = 41;
  EXPECT_NO_THROW(checkSegments(map, {{{0.05, 0.5, 1.0}, {4.05, 0.5, 1.0}}}, 0.0, config));
  config.max_query_cells = 40;
  EXPECT_THROW(checkSegments(map, {{{0.05, 0.5, 1.0}, {4.05, 0.5, 1.0}}}, 0.0, config),
               ConfigError);
  // One cell: one segment within it visits 1 cell, two visit 2.
  config.max_query_cells = 1;
  EXPECT_NO_THROW(checkSegments(map, {{{0.05, 0.5, 1.0}, {0.06, 0.5, 1.0}}}, 0.0, config));
  EXPECT_THROW(
      checkSegments(map, std::vector<Segment>(2, Segment{{0.05, 0.5, 1.0}, {0.06, 0.5, 1.0}}), 0.0,
                    config),
      ConfigError);
}

TEST(SegmentChecks, ASweptSphereTouchingAnObstaclesFaceExactlyMeetsIt) {
  // Resolution 1: one obstacle fills cell (3, 1), the square [3, 4) x [1, 2), over heights
  // [0, 1]. A segment along y = 0.5, z = 0.5 with a radius of 0.5 reaches y = 1 exactly: the
  // sphere touches the obstacle's face y = 1 (touching a face counts), whose points lie in the
  // cell: occupied.
  Map map(test::unitConfig());
  map.setCellVolumes({3, 1}, CellVolumes{{{0.0f, 1.0f, 1.0f}}, {}});
  EXPECT_EQ(checkOne(map, {0.5, 0.5, 0.5}, {5.5, 0.5, 0.5}, 0.5).state, OccupancyState::kOccupied);
  EXPECT_EQ(checkOne(map, {0.5, 0.5, 0.5}, {5.5, 0.5, 0.5}, 0.4).state, OccupancyState::kUnknown);
}

TEST(SegmentChecks, ASweptSphereRunningAlongAnObstaclesFaceAtTheRadiusMeetsIt) {
  // Resolution 1: one obstacle fills cell (3, 1) over heights [0, 1]. A segment along y = 0.5,
  // z = 0.5, wholly over x in [3, 4], keeps the distance 0.5 from the face y = 1: with a radius
  // of 0.5 the sphere touches it all along (touching a face counts), from the start.
  Map map(test::unitConfig());
  map.setCellVolumes({3, 1}, CellVolumes{{{0.0f, 1.0f, 1.0f}}, {}});
  const SegmentCheck check = checkOne(map, {3.2, 0.5, 0.5}, {3.8, 0.5, 0.5}, 0.5);
  EXPECT_EQ(check.state, OccupancyState::kOccupied);
  EXPECT_EQ(check.blocked_at, 0.0);
}

TEST(SegmentChecks, APointWhosePEqualsTheThresholdIsFree) {
  // Resolution 1: in cell (0, 0) a positive and a negative volume over [0, 1], each of mass 1:
  // p = 0.5 (eq. 9), free for a threshold of 0.5 (occupied only where p > threshold).
  Map map(test::unitConfig());
  map.setCellVolumes({0, 0}, CellVolumes{{{0.0f, 1.0f, 1.0f}}, {{0.0f, 1.0f, 1.0f}}});
  ASSERT_EQ(*map.occupancy({0.5, 0.5, 0.5}).probability, 0.5f);
  PlanningConfig config;
  config.occupancy_threshold = 0.5;
  EXPECT_EQ(checkSegments(map, {{{0.2, 0.5, 0.5}, {0.8, 0.5, 0.5}}}, 0.0, config).at(0).state,
            OccupancyState::kFree);
  const BoxCheck box = checkBoxes(map, {{{0.2, 0.2, 0.2}, {0.8, 0.8, 0.8}}}, config).at(0);
  EXPECT_EQ(box.state, OccupancyState::kFree);
  EXPECT_EQ(box.max_probability, 0.5);
}

TEST(SegmentChecks, FreeSpaceOfMassZeroIsUnknown) {
  // Resolution 1: cell (0, 0) holds only a negative volume [0, 1] of mass 0 (decayed away):
  // rho+ + rho- = 0 there, unknown (eq. 9), as occupancy() says.
  Map map(test::unitConfig());
  map.setCellVolumes({0, 0}, CellVolumes{{}, {{0.0f, 1.0f, 0.0f}}});
  ASSERT_FALSE(map.occupancy({0.5, 0.5, 0.5}).known());
  EXPECT_EQ(checkOne(map, {0.2, 0.5, 0.5}, {0.8, 0.5, 0.5}, 0.0).state, OccupancyState::kUnknown);
}

TEST(BoxChecks, TheStateIsTheWorstOverEveryCell) {
  // Resolution 1: cell (0, 0) occupied over [0, 2], cell (1, 0) free over [0, 2]. A box over both
  // is occupied, whichever cell comes last.
  Map map(test::unitConfig());
  map.setCellVolumes({{{0, 0}, {{{0.0f, 2.0f, 2.0f}}, {}}}, {{1, 0}, {{}, {{0.0f, 2.0f, 2.0f}}}}});
  EXPECT_EQ(checkOne(map, {0.5, 0.2, 0.5}, {1.5, 0.8, 1.5}).state, OccupancyState::kOccupied);
  EXPECT_EQ(checkOne(map, {1.2, 0.2, 0.5}, {1.5, 0.8, 1.5}).state, OccupancyState::kFree);
}

TEST(BoxChecks, ABoxTouchingAnObstaclesBottomHoldsItsProbability) {
  // Resolution 1: cell (0, 0) holds only an obstacle [5, 7]. The box's top face z = 5 (corners
  // included) holds points of it, where p = 1 (occupancy() says so): occupied, highest p 1.
  Map map(test::unitConfig());
  map.setCellVolumes({0, 0}, CellVolumes{{{5.0f, 7.0f, 2.0f}}, {}});
  ASSERT_EQ(*map.occupancy({0.5, 0.5, 5.0}).probability, 1.0f);
  const BoxCheck check = checkOne(map, {0.2, 0.2, 3.0}, {0.8, 0.8, 5.0});
  EXPECT_EQ(check.state, OccupancyState::kOccupied);
  EXPECT_EQ(check.max_probability, 1.0);
}

}  // namespace
}  // namespace mvog
