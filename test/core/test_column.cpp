// columnProfile (mvog/column.h): eq. (9) along a whole column as segments of constant
// probability, the way the occupied-space markers and mvog_export draw it.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "mvog/column.h"
#include "mvog/map.h"
#include "test_util.h"

namespace mvog {
namespace {

::testing::AssertionResult segmentIs(const ColumnSegment& segment, float bottom, float top,
                                     float probability) {
  if (segment.bottom == bottom && segment.top == top &&
      std::fabs(segment.probability - probability) < 1e-6f) {
    return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure()
         << "segment [" << segment.bottom << ", " << segment.top << "] p = " << segment.probability
         << ", expected [" << bottom << ", " << top << "] p = " << probability;
}

TEST(ColumnProfile, AnUnobservedColumnHasNoSegment) {
  EXPECT_TRUE(columnProfile(CellVolumes{}).empty());
}

TEST(ColumnProfile, OneVolumeIsOneSegmentCertainlyOccupiedOrFree) {
  CellVolumes positive;
  positive.positive = {{1.0f, 3.0f, 2.0f}};
  const std::vector<ColumnSegment> occupied = columnProfile(positive);
  ASSERT_EQ(occupied.size(), 1u);
  EXPECT_TRUE(segmentIs(occupied[0], 1.0f, 3.0f, 1.0f));

  CellVolumes negative;
  negative.negative = {{-2.0f, 4.0f, 0.5f}};
  const std::vector<ColumnSegment> free = columnProfile(negative);
  ASSERT_EQ(free.size(), 1u);
  EXPECT_TRUE(segmentIs(free[0], -2.0f, 4.0f, 0.0f));
}

TEST(ColumnProfile, OverlappingVolumesCutTheColumnWhereEitherBeginsOrEnds) {
  // rho+ = 1 over [0, 2], rho- = 3 over [1, 3]: p = 1, then 1 / (1 + 3), then 0 (eq. 9).
  CellVolumes volumes;
  volumes.positive = {{0.0f, 2.0f, 2.0f}};
  volumes.negative = {{1.0f, 3.0f, 6.0f}};
  const std::vector<ColumnSegment> segments = columnProfile(volumes);
  ASSERT_EQ(segments.size(), 3u);
  EXPECT_TRUE(segmentIs(segments[0], 0.0f, 1.0f, 1.0f));
  EXPECT_TRUE(segmentIs(segments[1], 1.0f, 2.0f, 0.25f));
  EXPECT_TRUE(segmentIs(segments[2], 2.0f, 3.0f, 0.0f));
}

TEST(ColumnProfile, GapsBetweenVolumesAreUnknownAndLeftOut) {
  CellVolumes volumes;
  volumes.positive = {{0.0f, 1.0f, 1.0f}, {4.0f, 5.0f, 1.0f}};
  volumes.negative = {{1.0f, 2.0f, 1.0f}};
  const std::vector<ColumnSegment> segments = columnProfile(volumes);
  ASSERT_EQ(segments.size(), 3u);  // nothing over [2, 4]
  EXPECT_TRUE(segmentIs(segments[0], 0.0f, 1.0f, 1.0f));
  EXPECT_TRUE(segmentIs(segments[1], 1.0f, 2.0f, 0.0f));
  EXPECT_TRUE(segmentIs(segments[2], 4.0f, 5.0f, 1.0f));
}

TEST(ColumnProfile, AdjacentStretchesOfEqualProbabilityAreJoined) {
  // Two negative volumes meeting at 2 under one positive volume, all of density 1: p = 0.5 on
  // both sides of 2, one segment.
  CellVolumes volumes;
  volumes.positive = {{0.0f, 4.0f, 4.0f}};
  volumes.negative = {{0.0f, 2.0f, 2.0f}, {2.0f, 4.0f, 2.0f}};
  const std::vector<ColumnSegment> segments = columnProfile(volumes);
  ASSERT_EQ(segments.size(), 1u);
  EXPECT_TRUE(segmentIs(segments[0], 0.0f, 4.0f, 0.5f));
}

TEST(ColumnProfile, AgreesWithThePointQueriesOfAMappedColumn) {
  // Rays at many heights and slopes into one cell: inside every segment the map answers the
  // segment's probability, outside all of them it answers unknown.
  Map map(test::unitConfig());
  for (int k = 0; k < 40; ++k) {
    const double z = 0.3 * k;
    const Eigen::Vector3d origin(-6.0, 0.5, 5.0);
    map.insertReading(origin, {0.5, 0.5, z},
                      k % 3 == 0 ? ReadingKind::kOutOfRange : ReadingKind::kObstacle);
  }
  const std::vector<ColumnSegment> segments = columnProfile(map.cellVolumes({0, 0}));
  ASSERT_FALSE(segments.empty());
  float below = segments.front().bottom - 1.0f;
  for (const ColumnSegment& segment : segments) {
    ASSERT_LT(segment.bottom, segment.top);
    ASSERT_LE(below, segment.bottom);  // bottom to top, no overlap
    if (below < segment.bottom) {
      EXPECT_FALSE(map.occupancy({0.5, 0.5, 0.5 * (below + segment.bottom)}).known())
          << "between " << below << " and " << segment.bottom;
    }
    const PointOccupancy middle = map.occupancy({0.5, 0.5, 0.5 * (segment.bottom + segment.top)});
    ASSERT_TRUE(middle.known());
    EXPECT_NEAR(*middle.probability, segment.probability, 1e-6);
    below = segment.top;
  }
}

}  // namespace
}  // namespace mvog
