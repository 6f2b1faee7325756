// The map as messages (mvog_ros/visualization.h): the volume and occupied-space markers of a
// tile, the marker that clears a topic, grid values and occupancy grids.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "mvog/height_colour.h"
#include "mvog/map.h"
#include "mvog_ros/visualization.h"

namespace mvog_ros {
namespace {

constexpr double kMapResolution = 0.1;
const ros::Time kMarkerStamp(12.5);

/// One obstacle reading along x at z = 1 m: free space in cells 0..9 of row 0, and a hit in cell
/// (10, 0), whose positive volume spans [9.5, 10.5] grid units (eq. 6), i.e. [0.95, 1.05] m.
mvog::Map oneReadingMap() {
  mvog::MapConfig config;
  config.resolution = kMapResolution;
  mvog::Map map(config);
  map.insertReading({0.05, 0.05, 1.0}, {1.05, 0.05, 1.0}, mvog::ReadingKind::kObstacle);
  return map;
}

/// Markers of namespace `ns` in `markers`.
std::vector<visualization_msgs::Marker> markersOf(const visualization_msgs::MarkerArray& markers,
                                                  const std::string& ns) {
  std::vector<visualization_msgs::Marker> found;
  std::copy_if(markers.markers.begin(), markers.markers.end(), std::back_inserter(found),
               [&](const visualization_msgs::Marker& marker) { return marker.ns == ns; });
  return found;
}

/// The smallest box holding every point of a marker.
struct Extent {
  double min[3] = {INFINITY, INFINITY, INFINITY};
  double max[3] = {-INFINITY, -INFINITY, -INFINITY};
};
Extent extentOf(const std::vector<geometry_msgs::Point>& points) {
  Extent extent;
  for (const geometry_msgs::Point& p : points) {
    const double coordinates[3] = {p.x, p.y, p.z};
    for (int axis = 0; axis < 3; ++axis) {
      extent.min[axis] = std::min(extent.min[axis], coordinates[axis]);
      extent.max[axis] = std::max(extent.max[axis], coordinates[axis]);
    }
  }
  return extent;
}

std::size_t volumesIn(const mvog::Map& map, const mvog::TileIndex& tile, mvog::VolumeSign sign) {
  std::size_t count = 0;
  map.forEachVolumeIn(mvog::Map::tileCells(tile), [&](const mvog::CellIndex&, mvog::VolumeSign s,
                                                      const mvog::Volume&) { count += s == sign; });
  return count;
}

TEST(VolumeMarkers, OneTriangleListPerSignWithTwelveTrianglesPerVolume) {
  const mvog::Map map = oneReadingMap();
  visualization_msgs::MarkerArray markers;
  appendVolumeMarkers(map, {0, 0}, "map", kMarkerStamp, markers);
  ASSERT_EQ(markers.markers.size(), 2u);
  for (const char* ns : {"positive", "negative"}) {
    const std::vector<visualization_msgs::Marker> found = markersOf(markers, ns);
    ASSERT_EQ(found.size(), 1u) << ns;
    const visualization_msgs::Marker& marker = found[0];
    EXPECT_EQ(marker.header.frame_id, "map");
    EXPECT_EQ(marker.header.stamp, kMarkerStamp);
    EXPECT_EQ(marker.id, tileMarkerId({0, 0}));
    EXPECT_EQ(marker.type, visualization_msgs::Marker::TRIANGLE_LIST);
    EXPECT_EQ(marker.action, visualization_msgs::Marker::ADD);
    EXPECT_EQ(marker.pose.orientation.w, 1.0);
    const mvog::VolumeSign sign =
        std::string(ns) == "positive" ? mvog::VolumeSign::kPositive : mvog::VolumeSign::kNegative;
    EXPECT_EQ(marker.points.size(), 36 * volumesIn(map, {0, 0}, sign)) << ns;
    EXPECT_TRUE(marker.colors.empty()) << ns << ": one colour per namespace";
  }
  EXPECT_GT(markersOf(markers, "positive")[0].color.r, 0.5f);  // red
  EXPECT_GT(markersOf(markers, "negative")[0].color.b, 0.5f);  // blue
}

TEST(VolumeMarkers, TheHitIsABoxOverItsCellAtTheHeightsOfItsVolume) {
  const mvog::Map map = oneReadingMap();
  visualization_msgs::MarkerArray markers;
  appendVolumeMarkers(map, {0, 0}, "map", kMarkerStamp, markers);
  const visualization_msgs::Marker positive = markersOf(markers, "positive").at(0);
  ASSERT_EQ(positive.points.size(), 36u);
  const Extent box = extentOf(positive.points);
  EXPECT_NEAR(box.min[0], 1.0, 1e-9);
  EXPECT_NEAR(box.max[0], 1.1, 1e-9);
  EXPECT_NEAR(box.min[1], 0.0, 1e-9);
  EXPECT_NEAR(box.max[1], 0.1, 1e-9);
  EXPECT_NEAR(box.min[2], 0.95, 1e-6);
  EXPECT_NEAR(box.max[2], 1.05, 1e-6);
  // Every corner of the box is used, by three faces of two triangles.
  std::set<std::tuple<double, double, double>> corners;
  for (const geometry_msgs::Point& p : positive.points) corners.insert({p.x, p.y, p.z});
  EXPECT_EQ(corners.size(), 8u);
}

TEST(VolumeMarkers, ATileWithoutVolumesDeletesItsMarkers) {
  const mvog::Map map = oneReadingMap();
  visualization_msgs::MarkerArray markers;
  appendVolumeMarkers(map, {5, -7}, "map", kMarkerStamp, markers);
  ASSERT_EQ(markers.markers.size(), 2u);
  for (const visualization_msgs::Marker& marker : markers.markers) {
    EXPECT_EQ(marker.action, visualization_msgs::Marker::DELETE) << marker.ns;
    EXPECT_EQ(marker.id, tileMarkerId({5, -7}));
    EXPECT_TRUE(marker.points.empty());
  }
}

TEST(OccupiedMarkers, BoxesWhereTheProbabilityExceedsTheThresholdColouredByHeight) {
  const mvog::Map map = oneReadingMap();
  visualization_msgs::MarkerArray markers;
  appendOccupiedMarkers(map, {0, 0}, 0.5, "map", kMarkerStamp, markers);
  ASSERT_EQ(markers.markers.size(), 1u);
  const visualization_msgs::Marker& occupied = markers.markers[0];
  EXPECT_EQ(occupied.ns, "occupied");
  EXPECT_EQ(occupied.action, visualization_msgs::Marker::ADD);
  ASSERT_EQ(occupied.points.size(), 36u);  // the hit only: free space is not occupied
  ASSERT_EQ(occupied.colors.size(), occupied.points.size());
  const Extent box = extentOf(occupied.points);
  EXPECT_NEAR(box.min[0], 1.0, 1e-9);
  EXPECT_NEAR(box.min[2], 0.95, 1e-6);
  EXPECT_NEAR(box.max[2], 1.05, 1e-6);
  const mvog::Rgb expected = mvog::heightColour(1.0 / 3.0);  // its middle, red at 3 m
  for (const std_msgs::ColorRGBA& colour : occupied.colors) {
    EXPECT_NEAR(colour.r, expected.r, 1e-6);
    EXPECT_NEAR(colour.g, expected.g, 1e-6);
    EXPECT_NEAR(colour.b, expected.b, 1e-6);
    EXPECT_EQ(colour.a, 1.0f);
  }
}

TEST(OccupiedMarkers, NothingAboveACertainThresholdIsADelete) {
  visualization_msgs::MarkerArray markers;
  appendOccupiedMarkers(oneReadingMap(), {0, 0}, 0.9999999, "map", kMarkerStamp, markers);
  ASSERT_EQ(markers.markers.size(), 1u);
  EXPECT_EQ(markers.markers[0].action, visualization_msgs::Marker::ADD);  // p = 1 at the hit
  markers.markers.clear();
  appendOccupiedMarkers(oneReadingMap(), {1, 0}, 0.5, "map", kMarkerStamp, markers);
  ASSERT_EQ(markers.markers.size(), 1u);
  EXPECT_EQ(markers.markers[0].action, visualization_msgs::Marker::DELETE);
}

TEST(TileMarkerId, NeighbouringAndNegativeTilesHaveDistinctIds) {
  std::set<int> ids;
  for (std::int32_t x = -3; x <= 3; ++x) {
    for (std::int32_t y = -3; y <= 3; ++y) ids.insert(tileMarkerId({x, y}));
  }
  EXPECT_EQ(ids.size(), 49u);
  EXPECT_NE(tileMarkerId({32767, -32768}), tileMarkerId({-32768, 32767}));
}

TEST(DeleteAllMarker, ClearsTheTopicInTheMapFrame) {
  const visualization_msgs::Marker marker = deleteAllMarker("world", kMarkerStamp);
  EXPECT_EQ(marker.action, visualization_msgs::Marker::DELETEALL);
  EXPECT_EQ(marker.header.frame_id, "world");
  EXPECT_EQ(marker.header.stamp, kMarkerStamp);
  EXPECT_EQ(marker.pose.orientation.w, 1.0);
}

TEST(GridValue, ProbabilitiesBecomePercentUnknownMinusOne) {
  EXPECT_EQ(gridValue(std::numeric_limits<float>::quiet_NaN()), -1);
  EXPECT_EQ(gridValue(0.0f), 0);
  EXPECT_EQ(gridValue(0.5f), 50);
  EXPECT_EQ(gridValue(0.996f), 100);
  EXPECT_EQ(gridValue(1.0f), 100);
  EXPECT_EQ(gridValue(-0.5f), 0);  // clamped
  EXPECT_EQ(gridValue(mvog::OccupancyState::kOccupied), 100);
  EXPECT_EQ(gridValue(mvog::OccupancyState::kFree), 0);
  EXPECT_EQ(gridValue(mvog::OccupancyState::kUnknown), -1);
}

TEST(ToOccupancyGrid, KeepsTheGridsCellsOriginAndHeight) {
  const mvog::Map map = oneReadingMap();
  const mvog::CellRange cells{{-2, -1}, {12, 1}};
  const mvog::CrossSection section = map.crossSection(1.0, cells);
  const nav_msgs::OccupancyGrid grid = toOccupancyGrid(section, 1.0, "map", kMarkerStamp);
  EXPECT_EQ(grid.header.frame_id, "map");
  EXPECT_EQ(grid.header.stamp, kMarkerStamp);
  EXPECT_EQ(grid.info.width, 15u);
  EXPECT_EQ(grid.info.height, 3u);
  EXPECT_FLOAT_EQ(grid.info.resolution, static_cast<float>(kMapResolution));
  EXPECT_NEAR(grid.info.origin.position.x, -0.2, 1e-9);
  EXPECT_NEAR(grid.info.origin.position.y, -0.1, 1e-9);
  EXPECT_EQ(grid.info.origin.position.z, 1.0);
  ASSERT_EQ(grid.data.size(), section.values.size());
  for (std::size_t k = 0; k < grid.data.size(); ++k) {
    EXPECT_EQ(grid.data[k], gridValue(section.values[k])) << k;
  }
  // Row 1 is y = 0: free along the reading, occupied at the hit, unknown elsewhere.
  const auto at = [&](std::int32_t x, std::int32_t y) {
    return grid.data[static_cast<std::size_t>((y + 1) * 15 + (x + 2))];
  };
  EXPECT_EQ(at(5, 0), 0);
  EXPECT_EQ(at(10, 0), 100);
  EXPECT_EQ(at(-2, 0), -1);
  EXPECT_EQ(at(5, 1), -1);
}

}  // namespace
}  // namespace mvog_ros
