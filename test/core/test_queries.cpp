// Queries (Sec. III-C): eq. (9) at a point, cell volume lists, cross-sections, projections over
// a height band, rectangles of cells, and the volume visitors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "mvog/map.h"
#include "test_util.h"

namespace mvog {
namespace {

using test::kInf;
using test::kNaN;
using test::unitConfig;

// ---- occupancy(): eq. (9)
// ------------------------------------------------------------------------

/// Resolution 0.5 (s = 2) with one hand-made cell (2, -3), i.e. x in [1, 1.5), y in [-1.5, -1).
/// Heights below are in grid units; world z = grid z / 2.
///   positive: [0, 2] mass 6 (rho+ = 3), [6, 8] mass 2 (rho+ = 1)
///   negative: [1, 5] mass 4 (rho- = 1), [7.5, 9] mass 0 (rho- = 0)
Map handMadeMap() {
  Map map(MapConfig{0.5, 1000.0, ModelRules::paper()});
  CellVolumes volumes;
  volumes.positive = {{0.0f, 2.0f, 6.0f}, {6.0f, 8.0f, 2.0f}};
  volumes.negative = {{1.0f, 5.0f, 4.0f}, {7.5f, 9.0f, 0.0f}};
  map.setCellVolumes({2, -3}, volumes);
  return map;
}

PointOccupancy at(const Map& map, double grid_z) {
  return map.occupancy({1.25, -1.25, grid_z / 2});
}

TEST(Occupancy, ProbabilityIsPositiveOverTotalDensity) {
  const Map map = handMadeMap();
  // rho+ = 3, rho- = 1: p = 3 / (3 + 1).
  PointOccupancy p = at(map, 1.5);
  EXPECT_DOUBLE_EQ(p.positive_density, 3.0);
  EXPECT_DOUBLE_EQ(p.negative_density, 1.0);
  ASSERT_TRUE(p.known());
  EXPECT_FLOAT_EQ(*p.probability, 0.75f);
  // Positive only: rho- = 0, p = 1.
  p = at(map, 0.5);
  EXPECT_DOUBLE_EQ(p.positive_density, 3.0);
  EXPECT_DOUBLE_EQ(p.negative_density, 0.0);
  EXPECT_FLOAT_EQ(p.probability.value(), 1.0f);
  // Negative only: p = 0.
  p = at(map, 3.0);
  EXPECT_DOUBLE_EQ(p.positive_density, 0.0);
  EXPECT_DOUBLE_EQ(p.negative_density, 1.0);
  EXPECT_FLOAT_EQ(p.probability.value(), 0.0f);
  // rho+ = 1 against a negative volume of mass 0: p = 1 / (1 + 0).
  p = at(map, 7.75);
  EXPECT_DOUBLE_EQ(p.positive_density, 1.0);
  EXPECT_DOUBLE_EQ(p.negative_density, 0.0);
  EXPECT_FLOAT_EQ(p.probability.value(), 1.0f);
}

TEST(Occupancy, FacesBelongToTheVolume) {
  const Map map = handMadeMap();
  EXPECT_FLOAT_EQ(at(map, 0.0).probability.value(), 1.0f);   // bottom of [0, 2]
  EXPECT_FLOAT_EQ(at(map, 2.0).probability.value(), 0.75f);  // top of [0, 2], inside [1, 5]
  EXPECT_FLOAT_EQ(at(map, 1.0).probability.value(), 0.75f);  // bottom of [1, 5]
  EXPECT_FLOAT_EQ(at(map, 5.0).probability.value(), 0.0f);   // top of [1, 5]
}

TEST(Occupancy, UnknownWhereBothDensitiesAreZero) {
  const Map map = handMadeMap();
  // Between volumes, below and above everything.
  for (double z : {5.5, -0.5, 9.5, 100.0}) {
    const PointOccupancy p = at(map, z);
    EXPECT_FALSE(p.known()) << "z = " << z;
    EXPECT_EQ(p.positive_density, 0.0);
    EXPECT_EQ(p.negative_density, 0.0);
    EXPECT_EQ(p.state(0.5), OccupancyState::kUnknown);
  }
  // Inside a negative volume of mass 0 only: rho+ + rho- = 0, unknown although a volume is there.
  EXPECT_FALSE(at(map, 8.5).known());
  // Another cell, never observed.
  EXPECT_FALSE(map.occupancy({0.25, 0.25, 0.5}).known());
  EXPECT_FALSE(map.occupancy({-100.0, 3.0, 0.5}).known());
}

TEST(Occupancy, NonFiniteOrFarPointsAreUnknown) {
  const Map map = handMadeMap();
  for (const Eigen::Vector3d& point :
       {Eigen::Vector3d(kNaN, -1.25, 0.5), Eigen::Vector3d(1.25, kNaN, 0.5),
        Eigen::Vector3d(1.25, -1.25, kNaN), Eigen::Vector3d(kInf, -1.25, 0.5),
        Eigen::Vector3d(1.25, -kInf, 0.5), Eigen::Vector3d(1.25, -1.25, kInf),
        Eigen::Vector3d(1.25, -1.25, -kInf), Eigen::Vector3d(1e300, 0.0, 0.0)}) {
    const PointOccupancy p = map.occupancy(point);
    EXPECT_FALSE(p.known()) << point.transpose();
    EXPECT_EQ(p.positive_density, 0.0);
    EXPECT_EQ(p.negative_density, 0.0);
  }
}

TEST(Occupancy, StateUsesTheThreshold) {
  const Map map = handMadeMap();
  const PointOccupancy p = at(map, 1.5);  // p = 0.75
  EXPECT_EQ(p.state(0.5), OccupancyState::kOccupied);
  EXPECT_EQ(p.state(0.74), OccupancyState::kOccupied);
  EXPECT_EQ(p.state(0.75), OccupancyState::kFree);  // occupied only where p > threshold
  EXPECT_EQ(p.state(0.9), OccupancyState::kFree);
  EXPECT_EQ(at(map, 3.0).state(0.0), OccupancyState::kFree);  // p = 0 is never occupied
}

TEST(Occupancy, DensitiesGrowWithRepeatedReadings) {
  // The same vertical hit three times (s = 1): V = [4.5, 5.5] and V' = [0, 4.5] each time, so
  // rho+ = 3 / 1 and rho- = 3 * 4.5 / 4.5 = 3.
  Map map(unitConfig());
  for (int k = 0; k < 3; ++k)
    map.insertReading({0.5, 0.5, 0}, {0.5, 0.5, 5}, ReadingKind::kObstacle);
  PointOccupancy p = map.occupancy({0.5, 0.5, 5.0});
  EXPECT_DOUBLE_EQ(p.positive_density, 3.0);
  EXPECT_DOUBLE_EQ(p.negative_density, 0.0);
  EXPECT_FLOAT_EQ(p.probability.value(), 1.0f);
  p = map.occupancy({0.5, 0.5, 4.5});  // where V and V' touch: 3 / (3 + 3)
  EXPECT_DOUBLE_EQ(p.positive_density, 3.0);
  EXPECT_DOUBLE_EQ(p.negative_density, 3.0);
  EXPECT_FLOAT_EQ(p.probability.value(), 0.5f);
  // A free reading through the obstacle: rho- over [0, 6] is (13.5 + 6) / 6 = 3.25 where the
  // old free space was, and the obstacle's p drops to 3 / (3 + 3.25).
  map.insertReading({0.5, 0.5, 0}, {0.5, 0.5, 6}, ReadingKind::kOutOfRange);
  p = map.occupancy({0.5, 0.5, 5.0});
  EXPECT_DOUBLE_EQ(p.negative_density, 3.25);
  EXPECT_FLOAT_EQ(p.probability.value(), static_cast<float>(3.0 / 6.25));
}

// ---- cellVolumes()
// ---------------------------------------------------------------------------------

TEST(CellVolumes, ReturnsBothListsAsStored) {
  const Map map = handMadeMap();
  const CellVolumes cell = map.cellVolumes({2, -3});
  ASSERT_EQ(cell.positive.size(), 2u);
  ASSERT_EQ(cell.negative.size(), 2u);
  EXPECT_TRUE(test::volumeIs(cell.positive[0], 0.0, 2.0, 6.0));
  EXPECT_TRUE(test::volumeIs(cell.positive[1], 6.0, 8.0, 2.0));
  EXPECT_TRUE(test::volumeIs(cell.negative[0], 1.0, 5.0, 4.0));
  EXPECT_TRUE(test::volumeIs(cell.negative[1], 7.5, 9.0, 0.0));
  for (const CellIndex& other : {CellIndex{2, -2}, CellIndex{3, -3}, CellIndex{-1000, 5}}) {
    const CellVolumes empty = map.cellVolumes(other);
    EXPECT_TRUE(empty.positive.empty());
    EXPECT_TRUE(empty.negative.empty());
  }
}

// ---- Cells and rectangles
// -------------------------------------------------------------------------

TEST(Cells, PointsProjectOntoCellsByFloor) {
  const Map map;  // resolution 0.1
  EXPECT_EQ(map.cellAtPoint(0.0, 0.0), (CellIndex{0, 0}));
  EXPECT_EQ(map.cellAtPoint(0.05, 0.15), (CellIndex{0, 1}));
  EXPECT_EQ(map.cellAtPoint(-0.0001, -0.25), (CellIndex{-1, -3}));
  EXPECT_EQ(map.cellAtPoint(1.0, -1.0), (CellIndex{10, -10}));
}

TEST(Cells, RectangleHoldsTheCellsOfItsCorners) {
  const Map map;  // resolution 0.1
  const CellRange cells = map.cellsInRectangle(-0.35, 0.05, 0.42, 0.31);
  EXPECT_EQ(cells.min, (CellIndex{-4, 0}));
  EXPECT_EQ(cells.max, (CellIndex{4, 3}));
  EXPECT_EQ(cells.width(), 9);
  EXPECT_EQ(cells.height(), 4);
  EXPECT_TRUE(cells.contains({-4, 3}));
  EXPECT_FALSE(cells.contains({5, 0}));
  EXPECT_TRUE(map.cellsInRectangle(1.0, 1.0, 0.5, 2.0).empty());  // min_x > max_x
  const CellRange point = map.cellsInRectangle(0.25, 0.25, 0.25, 0.25);
  EXPECT_EQ(point.width() * point.height(), 1);
}

// ---- crossSection()
// -------------------------------------------------------------------------------

/// A map at resolution 0.1 (the default) from random scans around the origin.
Map fineRandomMap(unsigned seed) { return test::randomMap(seed, 0.1, 3.0); }

TEST(CrossSection, EqualsOccupancyAtCellCentres) {
  const Map map = fineRandomMap(1);
  // The bounds and a margin of never-observed cells around them.
  const CellRange cells{{map.bounds().min.x - 3, map.bounds().min.y - 2},
                        {map.bounds().max.x + 2, map.bounds().max.y + 3}};
  for (double z : {-0.5, 0.0, 0.37, 1.2}) {
    const CrossSection section = map.crossSection(z, cells);
    EXPECT_EQ(section.resolution, 0.1);
    EXPECT_EQ(section.cells.min, cells.min);
    EXPECT_EQ(section.cells.max, cells.max);
    ASSERT_EQ(section.width(), static_cast<std::size_t>(cells.width()));
    ASSERT_EQ(section.height(), static_cast<std::size_t>(cells.height()));
    ASSERT_EQ(section.values.size(), section.width() * section.height());
    EXPECT_DOUBLE_EQ(section.originX(), cells.min.x * 0.1);
    EXPECT_DOUBLE_EQ(section.originY(), cells.min.y * 0.1);
    std::size_t known = 0;
    for (std::size_t y = 0; y < section.height(); ++y) {
      for (std::size_t x = 0; x < section.width(); ++x) {
        const double cx = (cells.min.x + static_cast<double>(x) + 0.5) * 0.1;
        const double cy = (cells.min.y + static_cast<double>(y) + 0.5) * 0.1;
        const PointOccupancy p = map.occupancy({cx, cy, z});
        const float value = section.at(x, y);
        if (p.known()) {
          ++known;
          ASSERT_EQ(value, *p.probability) << "cell " << x << ", " << y << " at z " << z;
        } else {
          ASSERT_TRUE(std::isnan(value)) << "cell " << x << ", " << y << " at z " << z;
        }
      }
    }
    EXPECT_GT(known, 0u);
    EXPECT_TRUE(std::isnan(section.at(0, 0)));  // the margin is unknown
  }
}

TEST(CrossSection, HandMadeCell) {
  const Map map = handMadeMap();
  const CrossSection section = map.crossSection(0.75, {{1, -4}, {3, -3}});  // grid z = 1.5
  ASSERT_EQ(section.width(), 3u);
  ASSERT_EQ(section.height(), 2u);
  EXPECT_DOUBLE_EQ(section.originX(), 0.5);
  EXPECT_DOUBLE_EQ(section.originY(), -2.0);
  // Rows run along +x from the lowest y: cell (2, -3) is x = 1, y = 1.
  EXPECT_FLOAT_EQ(section.at(1, 1), 0.75f);
  for (std::size_t k = 0; k < 6; ++k) {
    if (k != 4) {
      EXPECT_TRUE(std::isnan(section.values[k])) << k;
    }
  }
}

TEST(CrossSection, RefusesBadArguments) {
  const Map map = handMadeMap();
  EXPECT_THROW(map.crossSection(0.0, {{1, 1}, {0, 0}}), ConfigError);
  EXPECT_THROW(map.crossSection(kNaN, {{0, 0}, {1, 1}}), ConfigError);
  EXPECT_THROW(map.crossSection(0.0, {{-100000, -100000}, {100000, 100000}}), ConfigError);
}

// ---- projection()
// ---------------------------------------------------------------------------------

/// Cells along y = 0 at s = 1, each a case of Map::projection's doc:
///  0: positive [0, 1] only                      1: negative [0, 3] only
///  2: positive [0, 1] rho+ 1 in negative [-1, 3] rho- 3 (p = 0.25)
///  3: positive [0, 4] rho+ 1, negative [0, 2] rho- 3 (p = 0.25 below 2, 1 above)
///  4: positive [10, 11] far above                5: nothing
///  6: negative [0, 2] of mass 0                  7: positive [0.5, 1.5]
///  8: positive [0, 1] of mass 0 in negative [0, 1]
Map projectionMap() {
  Map map(unitConfig());
  const auto set = [&](int x, std::vector<Volume> positive, std::vector<Volume> negative) {
    map.setCellVolumes({x, 0}, CellVolumes{std::move(positive), std::move(negative)});
  };
  set(0, {{0, 1, 1}}, {});
  set(1, {}, {{0, 3, 3}});
  set(2, {{0, 1, 1}}, {{-1, 3, 12}});
  set(3, {{0, 4, 4}}, {{0, 2, 6}});
  set(4, {{10, 11, 1}}, {});
  set(6, {}, {{0, 2, 0}});
  set(7, {{0.5f, 1.5f, 1}}, {});
  set(8, {{0, 1, 0}}, {{0, 1, 1}});
  return map;
}

std::vector<OccupancyState> projectRow(const Map& map, double z_min, double z_max,
                                       double threshold) {
  const Projection projection = map.projection(z_min, z_max, threshold, {{0, 0}, {8, 0}});
  EXPECT_EQ(projection.width(), 9u);
  EXPECT_EQ(projection.height(), 1u);
  EXPECT_EQ(projection.resolution, 1.0);
  return projection.values;
}

constexpr OccupancyState kOcc = OccupancyState::kOccupied;
constexpr OccupancyState kFree = OccupancyState::kFree;
constexpr OccupancyState kUnk = OccupancyState::kUnknown;

TEST(Projection, OccupiedFreeOrUnknownPerCell) {
  const Map map = projectionMap();
  // Band [0, 4]: cell 3's positive is uncovered above 2 (p = 1) so it is occupied.
  EXPECT_EQ(projectRow(map, 0.0, 4.0, 0.5),
            (std::vector<OccupancyState>{kOcc, kFree, kFree, kOcc, kUnk, kUnk, kUnk, kOcc, kFree}));
  // Band [0, 1.5]: cell 3's positive is all under the negative there: p = 0.25, free.
  EXPECT_EQ(
      projectRow(map, 0.0, 1.5, 0.5),
      (std::vector<OccupancyState>{kOcc, kFree, kFree, kFree, kUnk, kUnk, kUnk, kOcc, kFree}));
  // Occupied only where p > threshold: p = 0.25 at a threshold of 0.25 is free.
  EXPECT_EQ(projectRow(map, 0.0, 1.5, 0.25)[2], kFree);
  // A lower threshold: p = 0.25 > 0.2 is occupied.
  EXPECT_EQ(projectRow(map, 0.0, 1.5, 0.2),
            (std::vector<OccupancyState>{kOcc, kFree, kOcc, kOcc, kUnk, kUnk, kUnk, kOcc, kFree}));
}

TEST(Projection, BandFacesAreClosed) {
  const Map map = projectionMap();
  // [-1, 0.5] touches cell 7's positive [0.5, 1.5] at its bottom face only.
  EXPECT_EQ(projectRow(map, -1.0, 0.5, 0.5)[7], kOcc);
  EXPECT_EQ(projectRow(map, -1.0, 0.49, 0.5)[7], kUnk);
  // [3, 3] (a plane) touches the top of cell 1's negative.
  EXPECT_EQ(projectRow(map, 3.0, 3.0, 0.5)[1], kFree);
}

TEST(Projection, InfiniteBand) {
  const Map map = projectionMap();
  EXPECT_EQ(projectRow(map, -kInf, kInf, 0.5),
            (std::vector<OccupancyState>{kOcc, kFree, kFree, kOcc, kOcc, kUnk, kUnk, kOcc, kFree}));
  EXPECT_EQ(projectRow(map, 5.0, kInf, 0.5)[4], kOcc);
  EXPECT_EQ(projectRow(map, -kInf, -2.0, 0.5), (std::vector<OccupancyState>(9, kUnk)));
}

TEST(Projection, AgreesWithOccupancySampledOverTheBand) {
  // Where a sample of the band is occupied the projection says occupied; where one is known it
  // is not unknown; where it says unknown every sample is unknown.
  const Map map = fineRandomMap(2);
  const CellRange cells = map.bounds();
  const double z_min = -0.3;
  const double z_max = 0.4;
  const Projection projection = map.projection(z_min, z_max, 0.5, cells);
  ASSERT_EQ(projection.values.size(), static_cast<std::size_t>(cells.width() * cells.height()));
  std::size_t counts[3] = {0, 0, 0};
  for (std::size_t y = 0; y < projection.height(); ++y) {
    for (std::size_t x = 0; x < projection.width(); ++x) {
      const OccupancyState state = projection.at(x, y);
      ++counts[static_cast<int>(state)];
      bool any_known = false;
      bool any_occupied = false;
      for (double z = z_min; z <= z_max + 1e-9; z += 0.005) {
        const PointOccupancy p =
            map.occupancy({(cells.min.x + static_cast<double>(x) + 0.5) * 0.1,
                           (cells.min.y + static_cast<double>(y) + 0.5) * 0.1, z});
        any_known = any_known || p.known();
        any_occupied = any_occupied || p.state(0.5) == OccupancyState::kOccupied;
      }
      if (any_occupied) {
        ASSERT_EQ(state, kOcc) << x << ", " << y;
      }
      if (any_known) {
        ASSERT_NE(state, kUnk) << x << ", " << y;
      }
    }
  }
  EXPECT_GT(counts[static_cast<int>(kOcc)], 0u);
  EXPECT_GT(counts[static_cast<int>(kFree)], 0u);
  EXPECT_GT(counts[static_cast<int>(kUnk)], 0u);
}

TEST(Projection, RefusesBadArguments) {
  const Map map = projectionMap();
  const CellRange cells{{0, 0}, {8, 0}};
  EXPECT_THROW(map.projection(1.0, 0.0, 0.5, cells), ConfigError);
  EXPECT_THROW(map.projection(kNaN, 1.0, 0.5, cells), ConfigError);
  EXPECT_THROW(map.projection(0.0, kNaN, 0.5, cells), ConfigError);
  EXPECT_THROW(map.projection(0.0, 1.0, 1.0, cells), ConfigError);
  EXPECT_THROW(map.projection(0.0, 1.0, -0.1, cells), ConfigError);
  EXPECT_THROW(map.projection(0.0, 1.0, kNaN, cells), ConfigError);
  EXPECT_THROW(map.projection(0.0, 1.0, 0.5, {{1, 0}, {0, 0}}), ConfigError);
}

// ---- forEachVolume / forEachVolumeIn
// ---------------------------------------------------------------

/// Every volume of `cells` read through cellVolumes, sorted.
std::vector<test::VolumeRecord> volumesByCell(const Map& map, const CellRange& cells) {
  std::vector<test::VolumeRecord> records;
  for (std::int32_t y = cells.min.y; y <= cells.max.y; ++y) {
    for (std::int32_t x = cells.min.x; x <= cells.max.x; ++x) {
      const CellVolumes volumes = map.cellVolumes({x, y});
      for (const Volume& v : volumes.positive)
        records.emplace_back(x, y, 0, v.bottom, v.top, v.mass);
      for (const Volume& v : volumes.negative)
        records.emplace_back(x, y, 1, v.bottom, v.top, v.mass);
    }
  }
  std::sort(records.begin(), records.end());
  return records;
}

std::vector<test::VolumeRecord> visitedIn(const Map& map, const CellRange& cells) {
  std::vector<test::VolumeRecord> records;
  map.forEachVolumeIn(cells, [&](const CellIndex& cell, VolumeSign sign, const Volume& v) {
    records.emplace_back(cell.x, cell.y, static_cast<int>(sign), v.bottom, v.top, v.mass);
  });
  std::sort(records.begin(), records.end());
  return records;
}

TEST(ForEachVolume, VisitsExactlyEveryVolume) {
  const Map map = fineRandomMap(3);
  std::vector<test::VolumeRecord> visited = test::allVolumes(map);
  std::sort(visited.begin(), visited.end());
  EXPECT_TRUE(test::sameVolumes(visited, volumesByCell(map, map.bounds())));
  const MemoryUsage usage = map.memoryUsage();
  EXPECT_EQ(visited.size(), usage.positive_volumes + usage.negative_volumes);
  EXPECT_EQ(test::observedCells(map).size(), usage.cells_with_volumes);
}

TEST(ForEachVolume, RegionRestrictsTheVisit) {
  const Map map = fineRandomMap(4);
  // Rectangles straddling tiles and the axes, one beyond the data, one empty.
  for (const CellRange& cells :
       {CellRange{{-7, -20}, {13, 2}}, CellRange{{-1, -1}, {0, 0}}, CellRange{{5, 5}, {5, 5}},
        CellRange{{-40, 17}, {-17, 40}}, CellRange{{1000, 1000}, {1010, 1010}}}) {
    SCOPED_TRACE(::testing::Message() << "cells (" << cells.min.x << ", " << cells.min.y << ") - ("
                                      << cells.max.x << ", " << cells.max.y << ")");
    EXPECT_TRUE(test::sameVolumes(visitedIn(map, cells), volumesByCell(map, cells)));
  }
  EXPECT_FALSE(visitedIn(map, {{-7, -20}, {13, 2}}).empty());
  EXPECT_TRUE(visitedIn(map, {{1, 1}, {0, 0}}).empty());
}

}  // namespace
}  // namespace mvog

namespace mvog {
namespace {

TEST(Column, ViewsTheListsCellVolumesCopies) {
  // The view holds the lists as stored: the same heights, masses in the tile's unit (after a
  // decay step, a fixed multiple of the real masses), the same probabilities.
  Map map = test::randomMap(3, 0.25, 6.0);
  map.decay(0.5);
  std::size_t cells = 0;
  for (const CellIndex& cell : test::observedCells(map)) {
    const ColumnView view = map.column(cell);
    const CellVolumes copy = map.cellVolumes(cell);
    ASSERT_EQ(view.num_positive, copy.positive.size());
    ASSERT_EQ(view.num_negative, copy.negative.size());
    for (std::uint32_t k = 0; k < view.num_negative; ++k) {
      EXPECT_EQ(view.negative[k].bottom, copy.negative[k].bottom);
      EXPECT_EQ(view.negative[k].top, copy.negative[k].top);
      EXPECT_FLOAT_EQ(view.negative[k].mass * 0.5f, copy.negative[k].mass);
    }
    ++cells;
  }
  EXPECT_GT(cells, 100u);
  EXPECT_TRUE(map.column({100000, 0}).empty());
}

TEST(Projection, Equation9WhereFreePiecesCoverAnObstacleExactly) {
  // Split free space (ModelRules::split_free_space_at_obstacles), resolution 1. Cell (0, 0): an
  // obstacle [3, 7] (rho+ = 1) under free pieces [0, 3] (rho- = 0.01) and [3, 7] (rho- = 10);
  // at height 3 eq. (9) takes the lower piece: p = 1 / 1.01, occupied (occupancy() says so).
  // Cell (1, 0): the same obstacle with only the piece [3, 7] (rho- = 10): p = 1 / 11 over all
  // of it, free.
  Map map(unitConfig(10000.0, ModelRules{}));
  map.setCellVolumes({{{0, 0}, {{{3.0f, 7.0f, 4.0f}}, {{0.0f, 3.0f, 0.03f}, {3.0f, 7.0f, 40.0f}}}},
                      {{1, 0}, {{{3.0f, 7.0f, 4.0f}}, {{3.0f, 7.0f, 40.0f}}}}});
  ASSERT_EQ(map.occupancy({0.5, 0.5, 3.0}).state(0.5), OccupancyState::kOccupied);
  ASSERT_EQ(map.occupancy({1.5, 0.5, 3.0}).state(0.5), OccupancyState::kFree);
  ASSERT_EQ(map.occupancy({1.5, 0.5, 7.0}).state(0.5), OccupancyState::kFree);
  const Projection projection = map.projection(0.0, 10.0, 0.5, {{0, 0}, {1, 0}});
  EXPECT_EQ(projection.at(0, 0), OccupancyState::kOccupied);
  EXPECT_EQ(projection.at(1, 0), OccupancyState::kFree);
}

TEST(Occupancy, PointsBeyondMaxCoordinateAreUnknownEvenInACellWithVolumes) {
  // max_coordinate 10 at resolution 1: cell (10, 0) spans x in [10, 11) and may hold volumes
  // (setCellVolumes allows |i| <= 11), but only its points with x <= 10 are within bounds.
  Map map(unitConfig(10.0));
  map.setCellVolumes({10, 0}, CellVolumes{{{0.0f, 2.0f, 2.0f}}, {}});
  EXPECT_TRUE(map.occupancy({10.0, 0.5, 1.0}).known());
  const PointOccupancy beyond = map.occupancy({10.5, 0.5, 1.0});
  EXPECT_FALSE(beyond.known());
  EXPECT_EQ(beyond.positive_density, 0.0);
}

}  // namespace
}  // namespace mvog
