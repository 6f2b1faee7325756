// Rasterisation (Sec. III-B.1): walkRay visits the cells the xy-projection of a ray crosses, in
// order, with entry and exit heights.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "mvog/map.h"
#include "mvog/raster.h"
#include "test_util.h"

namespace mvog {
namespace {

struct Step {
  CellIndex cell;
  double z_enter;
  double z_exit;
  bool is_last;
};

std::vector<Step> walk(double x0, double y0, double z0, double x1, double y1, double z1) {
  std::vector<Step> steps;
  walkRay(x0, y0, z0, x1, y1, z1,
          [&](const CellIndex& cell, double z_enter, double z_exit, bool is_last) {
            steps.push_back({cell, z_enter, z_exit, is_last});
          });
  return steps;
}

std::vector<std::pair<int, int>> cellsOf(const std::vector<Step>& steps) {
  std::vector<std::pair<int, int>> cells;
  for (const Step& s : steps) cells.emplace_back(s.cell.x, s.cell.y);
  return cells;
}

using Cells = std::vector<std::pair<int, int>>;

/// Only the last step is marked last, and every entry height is the previous exit height.
void expectChained(const std::vector<Step>& steps, double z_start, double z_end) {
  ASSERT_FALSE(steps.empty());
  EXPECT_EQ(steps.front().z_enter, z_start);
  EXPECT_EQ(steps.back().z_exit, z_end);
  for (std::size_t k = 0; k < steps.size(); ++k) {
    EXPECT_EQ(steps[k].is_last, k + 1 == steps.size()) << "step " << k;
    if (k > 0) {
      EXPECT_EQ(steps[k].z_enter, steps[k - 1].z_exit) << "step " << k;
    }
  }
}

TEST(CellAt, FloorsEveryCoordinateAsStdFloorDoes) {
  // floorToIndex converts without a call to floor: the same cell for integers, non-integers of
  // either sign, -0, values a float-rounding away from an integer, and the grid's bounds.
  const double step = std::nextafter(1.0, 2.0) - 1.0;
  std::vector<double> values = {0.0,    -0.0,       0.5,          -0.5,         1.0,
                                -1.0,   1.0 - step, -1.0 + step,  -1.0 - step,  2.5,
                                -2.5,   4194304.0,  -4194304.0,   4194303.75,   -4194303.75,
                                1e-300, -1e-300,    2147483647.0, -2147483647.0};
  std::mt19937 random(3);
  std::uniform_real_distribution<double> any(-5e6, 5e6);
  for (int k = 0; k < 100000; ++k) values.push_back(any(random));
  for (const double g : values) {
    EXPECT_EQ(floorToIndex(g), static_cast<std::int32_t>(std::floor(g))) << g;
    EXPECT_EQ(cellAt(g, -g), (CellIndex{static_cast<std::int32_t>(std::floor(g)),
                                        static_cast<std::int32_t>(std::floor(-g))}))
        << g;
  }
}

TEST(WalkRay, AlongPlusX) {
  // From x = 0.5 to 3.5 rising 0 -> 3: the walls x = 1, 2, 3 are met at z = 0.5, 1.5, 2.5.
  const std::vector<Step> steps = walk(0.5, 0.5, 0.0, 3.5, 0.5, 3.0);
  EXPECT_EQ(cellsOf(steps), (Cells{{0, 0}, {1, 0}, {2, 0}, {3, 0}}));
  expectChained(steps, 0.0, 3.0);
  EXPECT_DOUBLE_EQ(steps[0].z_exit, 0.5);
  EXPECT_DOUBLE_EQ(steps[1].z_exit, 1.5);
  EXPECT_DOUBLE_EQ(steps[2].z_exit, 2.5);
}

TEST(WalkRay, AlongMinusXWithNegativeCoordinates) {
  // x = -0.5 lies in cell -1; -3.5 in cell -4.
  const std::vector<Step> steps = walk(-0.5, -2.5, 4.0, -3.5, -2.5, 1.0);
  EXPECT_EQ(cellsOf(steps), (Cells{{-1, -3}, {-2, -3}, {-3, -3}, {-4, -3}}));
  expectChained(steps, 4.0, 1.0);
  EXPECT_DOUBLE_EQ(steps[0].z_exit, 3.5);
  EXPECT_DOUBLE_EQ(steps[1].z_exit, 2.5);
  EXPECT_DOUBLE_EQ(steps[2].z_exit, 1.5);
}

TEST(WalkRay, AlongPlusYAndMinusY) {
  EXPECT_EQ(cellsOf(walk(2.5, 0.5, 0.0, 2.5, 2.5, 0.0)), (Cells{{2, 0}, {2, 1}, {2, 2}}));
  const std::vector<Step> down = walk(-2.5, 1.5, 0.0, -2.5, -1.5, 6.0);
  EXPECT_EQ(cellsOf(down), (Cells{{-3, 1}, {-3, 0}, {-3, -1}, {-3, -2}}));
  expectChained(down, 0.0, 6.0);
  EXPECT_DOUBLE_EQ(down[0].z_exit, 1.0);  // y = 1 after 0.5 of 3
  EXPECT_DOUBLE_EQ(down[1].z_exit, 3.0);
  EXPECT_DOUBLE_EQ(down[2].z_exit, 5.0);
}

TEST(WalkRay, WithinOneCell) {
  const std::vector<Step> steps = walk(0.2, 0.3, 1.0, 0.8, 0.9, -1.0);
  EXPECT_EQ(cellsOf(steps), (Cells{{0, 0}}));
  expectChained(steps, 1.0, -1.0);
}

TEST(WalkRay, PurelyVerticalRayVisitsOneCell) {
  // dx = dy = 0: exactly one cell, the last, from the start height to the end height.
  for (const auto& [z0, z1] : {std::pair{0.0, 5.0}, std::pair{5.0, -2.0}, std::pair{1.0, 1.0}}) {
    const std::vector<Step> steps = walk(-3.5, 7.25, z0, -3.5, 7.25, z1);
    EXPECT_EQ(cellsOf(steps), (Cells{{-4, 7}}));
    expectChained(steps, z0, z1);
  }
  // On a wall and a corner too: the point belongs to the cell above and to the right.
  EXPECT_EQ(cellsOf(walk(2.0, -3.0, 0.0, 2.0, -3.0, 1.0)), (Cells{{2, -3}}));
}

TEST(WalkRay, DiagonalThroughCornersSkipsTheCornerCells) {
  // y = x passes through the corners (1, 1), (2, 2), (3, 3): cells (1, 0), (0, 1)... are only
  // touched at one point and are not visited.
  const std::vector<Step> up = walk(0.5, 0.5, 0.0, 3.5, 3.5, 3.0);
  EXPECT_EQ(cellsOf(up), (Cells{{0, 0}, {1, 1}, {2, 2}, {3, 3}}));
  expectChained(up, 0.0, 3.0);
  EXPECT_DOUBLE_EQ(up[0].z_exit, 0.5);
  EXPECT_DOUBLE_EQ(up[1].z_exit, 1.5);
  EXPECT_DOUBLE_EQ(up[2].z_exit, 2.5);
  // The same backwards, and along the other diagonal, with negative coordinates.
  EXPECT_EQ(cellsOf(walk(0.5, 0.5, 0.0, -2.5, -2.5, 3.0)),
            (Cells{{0, 0}, {-1, -1}, {-2, -2}, {-3, -3}}));
  EXPECT_EQ(cellsOf(walk(0.5, -0.5, 0.0, -2.5, 2.5, 3.0)),
            (Cells{{0, -1}, {-1, 0}, {-2, 1}, {-3, 2}}));
  EXPECT_EQ(cellsOf(walk(-1.5, 1.5, 0.0, 1.5, -1.5, 3.0)),
            (Cells{{-2, 1}, {-1, 0}, {0, -1}, {1, -2}}));
}

TEST(WalkRay, DiagonalEndingOnACornerVisitsTheLastCell) {
  // The end (2, 2) lies in cell (2, 2), touched at one point only: visited because it is last,
  // with a zero-length segment at the end height.
  const std::vector<Step> steps = walk(0.5, 0.5, 0.0, 2.0, 2.0, 3.0);
  EXPECT_EQ(cellsOf(steps), (Cells{{0, 0}, {1, 1}, {2, 2}}));
  expectChained(steps, 0.0, 3.0);
  EXPECT_DOUBLE_EQ(steps[2].z_enter, 3.0);
}

TEST(WalkRay, DiagonalStartingOnACorner) {
  // From the corner (1, 1) towards -x -y: the start cell (1, 1) is only touched, not crossed.
  EXPECT_EQ(cellsOf(walk(1.0, 1.0, 0.0, -0.5, -0.5, 3.0)), (Cells{{0, 0}, {-1, -1}}));
  // Towards +x +y it is crossed.
  EXPECT_EQ(cellsOf(walk(1.0, 1.0, 0.0, 2.5, 2.5, 3.0)), (Cells{{1, 1}, {2, 2}}));
}

TEST(WalkRay, StartOnAWall) {
  // Leaving through the wall it starts on: the start cell is not crossed.
  EXPECT_EQ(cellsOf(walk(1.0, 0.5, 0.0, -1.5, 0.5, 0.0)), (Cells{{0, 0}, {-1, 0}, {-2, 0}}));
  EXPECT_EQ(cellsOf(walk(0.5, 1.0, 0.0, 0.5, -0.5, 0.0)), (Cells{{0, 0}, {0, -1}}));
  // Moving away from it: the start cell is crossed.
  EXPECT_EQ(cellsOf(walk(1.0, 0.5, 0.0, 3.5, 0.5, 0.0)), (Cells{{1, 0}, {2, 0}, {3, 0}}));
  EXPECT_EQ(cellsOf(walk(0.5, 1.0, 0.0, 0.5, 2.5, 0.0)), (Cells{{0, 1}, {0, 2}}));
  // The first visited cell starts at the start height even when the start cell is skipped.
  const std::vector<Step> steps = walk(-2.0, 0.5, 2.0, -4.0, 0.5, 0.0);
  EXPECT_EQ(cellsOf(steps), (Cells{{-3, 0}, {-4, 0}}));
  expectChained(steps, 2.0, 0.0);
  EXPECT_DOUBLE_EQ(steps[0].z_exit, 1.0);
}

TEST(WalkRay, EndOnAWall) {
  // x = 2.0 lies in cell 2: moving +x the ray ends on the near wall of cell 2, which is last
  // with a zero-length segment.
  const std::vector<Step> forward = walk(0.5, 0.5, 0.0, 2.0, 0.5, 3.0);
  EXPECT_EQ(cellsOf(forward), (Cells{{0, 0}, {1, 0}, {2, 0}}));
  expectChained(forward, 0.0, 3.0);
  EXPECT_DOUBLE_EQ(forward[1].z_exit, 3.0);
  // Moving -x, the end x = 1.0 is on the far wall of cell 1, crossed up to it.
  const std::vector<Step> backward = walk(2.5, 0.5, 0.0, 1.0, 0.5, 3.0);
  EXPECT_EQ(cellsOf(backward), (Cells{{2, 0}, {1, 0}}));
  EXPECT_DOUBLE_EQ(backward[0].z_exit, 1.0);
  // Along y, both directions.
  EXPECT_EQ(cellsOf(walk(0.5, -1.5, 0.0, 0.5, 0.0, 0.0)), (Cells{{0, -2}, {0, -1}, {0, 0}}));
  EXPECT_EQ(cellsOf(walk(0.5, 0.5, 0.0, 0.5, -1.0, 0.0)), (Cells{{0, 0}, {0, -1}}));
}

TEST(WalkRay, StartAndEndOnWalls) {
  EXPECT_EQ(cellsOf(walk(1.0, 0.5, 0.0, 3.0, 0.5, 1.0)), (Cells{{1, 0}, {2, 0}, {3, 0}}));
  EXPECT_EQ(cellsOf(walk(3.0, 0.5, 0.0, 1.0, 0.5, 1.0)), (Cells{{2, 0}, {1, 0}}));
}

TEST(WalkRay, RayAlongAWallStaysInTheCellsItBelongsTo) {
  // x = 1.0 belongs to cells i = 1.
  EXPECT_EQ(cellsOf(walk(1.0, 0.5, 0.0, 1.0, 2.5, 0.0)), (Cells{{1, 0}, {1, 1}, {1, 2}}));
  EXPECT_EQ(cellsOf(walk(0.5, -1.0, 0.0, -1.5, -1.0, 0.0)), (Cells{{0, -1}, {-1, -1}, {-2, -1}}));
}

TEST(WalkRay, NonUnitSlopeHeights) {
  // (0.25, 0.5) -> (2.25, 1.5), z 0 -> 4: walls x = 1 at t = 0.375, y = 1 at t = 0.5,
  // x = 2 at t = 0.875.
  const std::vector<Step> steps = walk(0.25, 0.5, 0.0, 2.25, 1.5, 4.0);
  EXPECT_EQ(cellsOf(steps), (Cells{{0, 0}, {1, 0}, {1, 1}, {2, 1}}));
  expectChained(steps, 0.0, 4.0);
  EXPECT_DOUBLE_EQ(steps[0].z_exit, 1.5);
  EXPECT_DOUBLE_EQ(steps[1].z_exit, 2.0);
  EXPECT_DOUBLE_EQ(steps[2].z_exit, 3.5);
}

/// Every property a walk must have, for a ray given in grid units.
void checkWalk(double x0, double y0, double z0, double x1, double y1, double z1) {
  SCOPED_TRACE(::testing::Message() << "ray (" << x0 << ", " << y0 << ", " << z0 << ") -> (" << x1
                                    << ", " << y1 << ", " << z1 << ")");
  const std::vector<Step> steps = walk(x0, y0, z0, x1, y1, z1);
  expectChained(steps, z0, z1);
  const CellIndex start = cellAt(x0, y0);
  const CellIndex end = cellAt(x1, y1);
  EXPECT_EQ(steps.back().cell, end);
  // Never more than |di| + |dj| + 1 cells; the first is the start cell or, when the start lies
  // on a wall it leaves through, one of its neighbours.
  EXPECT_LE(steps.size(), std::size_t(std::abs(end.x - start.x) + std::abs(end.y - start.y) + 1));
  EXPECT_LE(std::abs(steps.front().cell.x - start.x), 1);
  EXPECT_LE(std::abs(steps.front().cell.y - start.y), 1);
  std::set<std::pair<int, int>> visited;
  for (std::size_t k = 0; k < steps.size(); ++k) {
    visited.emplace(steps[k].cell.x, steps[k].cell.y);
    // Heights move monotonically from z0 to z1.
    EXPECT_GE(steps[k].z_exit, std::min(z0, z1));
    EXPECT_LE(steps[k].z_exit, std::max(z0, z1));
    EXPECT_TRUE(z1 >= z0 ? steps[k].z_exit >= steps[k].z_enter
                         : steps[k].z_exit <= steps[k].z_enter);
    if (k == 0) continue;
    // Consecutive cells share a wall or (through a corner) a corner, and move towards the end.
    const int ddx = steps[k].cell.x - steps[k - 1].cell.x;
    const int ddy = steps[k].cell.y - steps[k - 1].cell.y;
    EXPECT_TRUE(std::abs(ddx) <= 1 && std::abs(ddy) <= 1 && (ddx != 0 || ddy != 0))
        << "step " << k << " jumps by (" << ddx << ", " << ddy << ")";
    EXPECT_TRUE(ddx == 0 || (ddx > 0) == (x1 > x0));
    EXPECT_TRUE(ddy == 0 || (ddy > 0) == (y1 > y0));
  }
  EXPECT_EQ(visited.size(), steps.size()) << "a cell is visited twice";
  // Every point of the ray lies in a visited cell. The samples avoid the grid corners that the
  // rays of RandomRaysOnTheGrid cross (at t = p / q, q <= 26), where two cells only touch.
  constexpr int kSamples = 2000;
  for (int k = 0; k <= kSamples; ++k) {
    const double t = (k + 0.37) / (kSamples + 1);
    const CellIndex c = cellAt(x0 + t * (x1 - x0), y0 + t * (y1 - y0));
    EXPECT_EQ(visited.count({c.x, c.y}), 1u)
        << "cell (" << c.x << ", " << c.y << ") at t = " << t << " is not visited";
  }
}

TEST(WalkRay, RandomRaysHaveEveryProperty) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> coordinate(-30.0, 30.0);
  for (int k = 0; k < 2000; ++k) {
    const double x0 = coordinate(rng), y0 = coordinate(rng), z0 = coordinate(rng);
    const double x1 = coordinate(rng), y1 = coordinate(rng), z1 = coordinate(rng);
    checkWalk(x0, y0, z0, x1, y1, z1);
    if (::testing::Test::HasFailure()) return;
  }
}

TEST(WalkRay, RandomRaysOnTheGrid) {
  // Starts and ends on grid lines and corners: the cases where ties decide.
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> coordinate(-6, 6);
  std::uniform_int_distribution<int> half(0, 1);
  for (int k = 0; k < 3000; ++k) {
    const double x0 = coordinate(rng) + 0.5 * half(rng), y0 = coordinate(rng) + 0.5 * half(rng);
    const double x1 = coordinate(rng) + 0.5 * half(rng), y1 = coordinate(rng) + 0.5 * half(rng);
    checkWalk(x0, y0, 0.0, x1, y1, 2.0);
    if (::testing::Test::HasFailure()) return;
  }
}

TEST(WalkRay, LongRay) {
  checkWalk(0.3, 0.7, -5.0, 5000.1, -3000.4, 40.0);
  checkWalk(-100000.5, 3.25, 0.0, 100000.5, -2.75, 1.0);
  const std::vector<Step> steps = walk(0.3, 0.7, -5.0, 5000.1, -3000.4, 40.0);
  EXPECT_EQ(steps.size(), 5000u + 3001u + 1u);  // no corner is hit exactly on this ray
}

TEST(Insertion, ZeroLengthReadingsAreDroppedAsTooClose) {
  Map map(test::unitConfig());
  const Eigen::Vector3d p(1.5, -2.5, 0.5);
  for (ReadingKind kind : {ReadingKind::kObstacle, ReadingKind::kOutOfRange}) {
    const InsertionResult result = map.insertReading(p, p, kind);
    EXPECT_EQ(result.rejected_too_close, 1u);
    EXPECT_EQ(result.inserted(), 0u);
  }
  EXPECT_TRUE(map.empty());
  EXPECT_TRUE(test::allVolumes(map).empty());
}

}  // namespace
}  // namespace mvog
