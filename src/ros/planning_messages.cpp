#include "mvog_ros/planning_messages.h"

#include <algorithm>
#include <cmath>

#include <sensor_msgs/point_cloud2_iterator.h>

#include "mvog/height_colour.h"
#include "mvog_ros/visualization.h"

namespace mvog_ros {
namespace {

/// A cloud without fields yet; dense: none of its points will be NaN.
sensor_msgs::PointCloud2 emptyCloud(const std::string& frame_id, const ros::Time& stamp) {
  sensor_msgs::PointCloud2 cloud;
  cloud.header.frame_id = frame_id;
  cloud.header.stamp = stamp;
  cloud.is_dense = true;
  return cloud;
}

}  // namespace

sensor_msgs::PointCloud2 frontierCloud(const std::vector<mvog::FrontierPoint>& points,
                                       const std::string& frame_id, const ros::Time& stamp) {
  sensor_msgs::PointCloud2 cloud = emptyCloud(frame_id, stamp);
  sensor_msgs::PointCloud2Modifier modifier(cloud);
  modifier.setPointCloud2Fields(
      4, "x", 1, sensor_msgs::PointField::FLOAT32, "y", 1, sensor_msgs::PointField::FLOAT32, "z", 1,
      sensor_msgs::PointField::FLOAT32, "cluster", 1, sensor_msgs::PointField::UINT32);
  modifier.resize(points.size());
  sensor_msgs::PointCloud2Iterator<float> x(cloud, "x");
  sensor_msgs::PointCloud2Iterator<float> y(cloud, "y");
  sensor_msgs::PointCloud2Iterator<float> z(cloud, "z");
  sensor_msgs::PointCloud2Iterator<std::uint32_t> cluster(cloud, "cluster");
  for (const mvog::FrontierPoint& point : points) {
    *x = point.x;
    *y = point.y;
    *z = point.z;
    *cluster = point.cluster;
    ++x, ++y, ++z, ++cluster;
  }
  return cloud;
}

visualization_msgs::MarkerArray frontierMarkers(const std::vector<mvog::FrontierPoint>& points,
                                                std::uint32_t num_clusters, double resolution,
                                                const std::string& frame_id,
                                                const ros::Time& stamp) {
  visualization_msgs::MarkerArray markers;
  visualization_msgs::Marker clear;
  clear.header.frame_id = frame_id;
  clear.header.stamp = stamp;
  clear.action = visualization_msgs::Marker::DELETEALL;
  clear.pose.orientation.w = 1.0;
  markers.markers.push_back(clear);
  for (std::uint32_t k = 0; k < num_clusters; ++k) {
    visualization_msgs::Marker cluster = clear;
    cluster.action = visualization_msgs::Marker::ADD;
    cluster.ns = "frontiers";
    cluster.id = static_cast<int>(k);
    cluster.type = visualization_msgs::Marker::CUBE_LIST;
    cluster.scale.x = cluster.scale.y = cluster.scale.z = resolution;
    // The golden ratio's fraction spreads consecutive clusters over the colour map.
    const mvog::Rgb rgb = mvog::heightColour(std::fmod(k * 0.6180339887, 1.0));
    cluster.color.r = rgb.r;
    cluster.color.g = rgb.g;
    cluster.color.b = rgb.b;
    cluster.color.a = 1.0f;
    markers.markers.push_back(cluster);
  }
  for (const mvog::FrontierPoint& point : points) {
    geometry_msgs::Point centre;
    centre.x = point.x;
    centre.y = point.y;
    centre.z = point.z;
    markers.markers[point.cluster + 1].points.push_back(centre);
  }
  return markers;
}

sensor_msgs::PointCloud2 surfaceCloud(const std::vector<mvog::Surface>& surfaces,
                                      const std::string& frame_id, const ros::Time& stamp) {
  sensor_msgs::PointCloud2 cloud = emptyCloud(frame_id, stamp);
  sensor_msgs::PointCloud2Modifier modifier(cloud);
  modifier.setPointCloud2Fields(
      5, "x", 1, sensor_msgs::PointField::FLOAT32, "y", 1, sensor_msgs::PointField::FLOAT32, "z", 1,
      sensor_msgs::PointField::FLOAT32, "clearance", 1, sensor_msgs::PointField::FLOAT32,
      "probability", 1, sensor_msgs::PointField::FLOAT32);
  modifier.resize(surfaces.size());
  sensor_msgs::PointCloud2Iterator<float> x(cloud, "x");
  sensor_msgs::PointCloud2Iterator<float> y(cloud, "y");
  sensor_msgs::PointCloud2Iterator<float> z(cloud, "z");
  sensor_msgs::PointCloud2Iterator<float> clearance(cloud, "clearance");
  sensor_msgs::PointCloud2Iterator<float> probability(cloud, "probability");
  for (const mvog::Surface& surface : surfaces) {
    *x = surface.x;
    *y = surface.y;
    *z = surface.z;
    *clearance = surface.clearance;
    *probability = surface.probability;
    ++x, ++y, ++z, ++clearance, ++probability;
  }
  return cloud;
}

nav_msgs::OccupancyGrid::_data_type traversableGridData(const mvog::Map& map,
                                                        const mvog::CellRange& cells,
                                                        const mvog::PlanningConfig& planning) {
  nav_msgs::OccupancyGrid::_data_type data;
  data.reserve(static_cast<std::size_t>(cells.width() * cells.height()));
  for (std::int32_t y = cells.min.y; y <= cells.max.y; y += mvog::Map::kTileSize) {
    const mvog::CellRange rows{{cells.min.x, y},
                               {cells.max.x, std::min(y + mvog::Map::kTileSize - 1, cells.max.y)}};
    const nav_msgs::OccupancyGrid::_data_type part =
        toOccupancyGrid(mvog::traversableMap(map, rows, planning), 0.0, "", ros::Time()).data;
    data.insert(data.end(), part.begin(), part.end());
  }
  return data;
}

}  // namespace mvog_ros
