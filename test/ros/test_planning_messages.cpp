// What planners and explorers are published as messages (mvog_ros/planning_messages.h): the
// frontier and surface clouds, the frontier markers, and the traversable map's grid values, kept
// up to date tile by tile as GridPublication keeps them; on the room of test/core's
// planning_scene.h.
#include <gtest/gtest.h>

#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include <sensor_msgs/point_cloud2_iterator.h>

#include "../core/planning_scene.h"
#include "mvog/frontiers.h"
#include "mvog/surfaces.h"
#include "mvog/tile_changes.h"
#include "mvog_ros/planning_messages.h"
#include "mvog_ros/visualization.h"

namespace mvog_ros {
namespace {

const ros::Time kMessageStamp(7.25);

/// The fields of a cloud as (name, offset, datatype, count).
std::vector<std::string> fieldsOf(const sensor_msgs::PointCloud2& cloud) {
  std::vector<std::string> fields;
  for (const sensor_msgs::PointField& field : cloud.fields) {
    fields.push_back(field.name + " " + std::to_string(field.offset) + " " +
                     std::to_string(field.datatype) + " " + std::to_string(field.count));
  }
  return fields;
}

/// A well-formed unorganized cloud of `points` points in the map frame at kMessageStamp.
::testing::AssertionResult isUnorganizedCloud(const sensor_msgs::PointCloud2& cloud,
                                              std::size_t points) {
  if (cloud.header.frame_id != "map" || cloud.header.stamp != kMessageStamp || cloud.height != 1 ||
      cloud.width != points || cloud.row_step != cloud.width * cloud.point_step ||
      cloud.data.size() != cloud.row_step || !cloud.is_dense || cloud.is_bigendian) {
    return ::testing::AssertionFailure() << "header or layout: " << cloud.width << " x "
                                         << cloud.height << ", " << cloud.data.size() << " bytes";
  }
  return ::testing::AssertionSuccess();
}

TEST(FrontierCloud, OnePointPerVoxelWithItsCluster) {
  const mvog::Map map = mvog::test::sceneMap();
  mvog::Frontiers frontiers;
  frontiers.update(map);
  ASSERT_EQ(frontiers.numClusters(), 2u);  // the door and the unexplored edge
  const sensor_msgs::PointCloud2 cloud = frontierCloud(frontiers.points(), "map", kMessageStamp);
  EXPECT_TRUE(isUnorganizedCloud(cloud, frontiers.points().size()));
  EXPECT_EQ(fieldsOf(cloud), (std::vector<std::string>{"x 0 7 1", "y 4 7 1", "z 8 7 1",
                                                       "cluster 12 6 1"}));  // FLOAT32, UINT32
  EXPECT_EQ(cloud.point_step, 16u);
  sensor_msgs::PointCloud2ConstIterator<float> x(cloud, "x");
  sensor_msgs::PointCloud2ConstIterator<float> y(cloud, "y");
  sensor_msgs::PointCloud2ConstIterator<float> z(cloud, "z");
  sensor_msgs::PointCloud2ConstIterator<std::uint32_t> cluster(cloud, "cluster");
  for (const mvog::FrontierPoint& point : frontiers.points()) {
    ASSERT_EQ(*x, point.x);
    ASSERT_EQ(*y, point.y);
    ASSERT_EQ(*z, point.z);
    ASSERT_EQ(*cluster, point.cluster);
    ++x, ++y, ++z, ++cluster;
  }
  const sensor_msgs::PointCloud2 none = frontierCloud({}, "map", kMessageStamp);
  EXPECT_TRUE(isUnorganizedCloud(none, 0));
  EXPECT_EQ(none.fields.size(), 4u);
}

TEST(FrontierMarkers, ADeleteAllThenACubeListPerClusterInAColourOfItsOwn) {
  const mvog::Map map = mvog::test::sceneMap();
  mvog::Frontiers frontiers;
  frontiers.update(map);
  const visualization_msgs::MarkerArray markers = frontierMarkers(
      frontiers.points(), frontiers.numClusters(), map.resolution(), "map", kMessageStamp);
  ASSERT_EQ(markers.markers.size(), 1u + frontiers.numClusters());
  EXPECT_EQ(markers.markers[0].action, visualization_msgs::Marker::DELETEALL);
  std::size_t points = 0;
  std::set<std::vector<float>> colours;
  auto inCluster = [&](std::uint32_t cluster) {
    std::multiset<std::vector<double>> in;
    for (const mvog::FrontierPoint& p : frontiers.points()) {
      if (p.cluster == cluster) in.insert({p.x, p.y, p.z});
    }
    return in;
  };
  for (std::uint32_t k = 0; k < frontiers.numClusters(); ++k) {
    const visualization_msgs::Marker& marker = markers.markers[k + 1];
    EXPECT_EQ(marker.header.frame_id, "map");
    EXPECT_EQ(marker.header.stamp, kMessageStamp);
    EXPECT_EQ(marker.ns, "frontiers");
    EXPECT_EQ(marker.id, static_cast<int>(k));
    EXPECT_EQ(marker.type, visualization_msgs::Marker::CUBE_LIST);
    EXPECT_EQ(marker.action, visualization_msgs::Marker::ADD);
    EXPECT_EQ(marker.scale.x, map.resolution());
    EXPECT_EQ(marker.scale.z, map.resolution());
    EXPECT_EQ(marker.pose.orientation.w, 1.0);
    EXPECT_EQ(marker.color.a, 1.0f);
    colours.insert({marker.color.r, marker.color.g, marker.color.b});
    std::multiset<std::vector<double>> in_marker;
    for (const geometry_msgs::Point& p : marker.points) in_marker.insert({p.x, p.y, p.z});
    EXPECT_EQ(in_marker, inCluster(k)) << "cluster " << k;
    points += marker.points.size();
  }
  EXPECT_EQ(points, frontiers.points().size());
  EXPECT_EQ(colours.size(), frontiers.numClusters());
  // Without frontiers: the DELETEALL alone.
  EXPECT_EQ(frontierMarkers({}, 0, map.resolution(), "map", kMessageStamp).markers.size(), 1u);
}

TEST(SurfaceCloud, OnePointPerSurfaceWithItsClearanceAndProbability) {
  const mvog::Map map = mvog::test::sceneMap();
  mvog::Surfaces surfaces;
  surfaces.update(map);
  const sensor_msgs::PointCloud2 cloud = surfaceCloud(surfaces.surfaces(), "map", kMessageStamp);
  EXPECT_TRUE(isUnorganizedCloud(cloud, surfaces.surfaces().size()));
  EXPECT_EQ(fieldsOf(cloud), (std::vector<std::string>{"x 0 7 1", "y 4 7 1", "z 8 7 1",
                                                       "clearance 12 7 1", "probability 16 7 1"}));
  sensor_msgs::PointCloud2ConstIterator<float> x(cloud, "x");
  sensor_msgs::PointCloud2ConstIterator<float> z(cloud, "z");
  sensor_msgs::PointCloud2ConstIterator<float> clearance(cloud, "clearance");
  sensor_msgs::PointCloud2ConstIterator<float> probability(cloud, "probability");
  for (const mvog::Surface& surface : surfaces.surfaces()) {
    ASSERT_EQ(*x, surface.x);
    ASSERT_EQ(*z, surface.z);
    ASSERT_EQ(*clearance, surface.clearance);
    ASSERT_EQ(*probability, surface.probability);
    ++x, ++z, ++clearance, ++probability;
  }
  EXPECT_TRUE(isUnorganizedCloud(surfaceCloud({}, "map", kMessageStamp), 0));
}

mvog::PlanningConfig tallRobot() {
  mvog::PlanningConfig config;
  config.robot_height = 1.0;  // taller than the desk's underside (0.7 m)
  return config;
}

TEST(TraversableGridData, RowsOfTilesAtATimeGiveTheWholeMap) {
  const mvog::Map map = mvog::test::sceneMap();
  // Three tile rows and a part of one, from a row that starts no tile.
  const mvog::CellRange cells{{-3, -3}, {45, 35}};
  EXPECT_EQ(
      traversableGridData(map, cells, tallRobot()),
      toOccupancyGrid(mvog::traversableMap(map, cells, tallRobot()), 0.0, "", ros::Time()).data);
}

TEST(TraversableGridData, KeptTileByTileWithTheNeighboursOfTheTilesChanged) {
  mvog::Map map = mvog::test::sceneMap();
  const mvog::PlanningConfig config = tallRobot();
  auto traversable = [&config](const mvog::Map& m, const mvog::CellRange& c) {
    return traversableGridData(m, c, config);
  };
  IncrementalGrid with_neighbours(0.0, 1 << 20, traversable);
  IncrementalGrid without_neighbours(0.0, 1 << 20, traversable);
  bool relaid_out = false;
  with_neighbours.update(map, map.tilesModifiedSince(0), relaid_out);
  without_neighbours.update(map, map.tilesModifiedSince(0), relaid_out);
  const std::uint64_t revision = map.revision();
  // A platform 0.3 m high in cell (16, 20), the first of tile (1, 1): too high a step from the
  // floor of cell (15, 20) in tile (0, 1), which is blocked now.
  map.setCellVolumes({16, 20}, {{mvog::test::obstacle(-1, 3), mvog::test::obstacle(25, 26)},
                                {mvog::test::freeSpace(3, 25)}});
  const std::vector<mvog::TileIndex> changed = map.tilesModifiedSince(revision);
  ASSERT_EQ(changed.size(), 1u);
  with_neighbours.update(map, mvog::withNeighbourTiles(changed), relaid_out);
  without_neighbours.update(map, changed, relaid_out);
  const nav_msgs::OccupancyGrid::_data_type fresh = traversable(map, with_neighbours.cells());
  EXPECT_EQ(with_neighbours.grid().data, fresh);
  EXPECT_NE(without_neighbours.grid().data, fresh);
}

}  // namespace
}  // namespace mvog_ros
