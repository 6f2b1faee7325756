#include "mvog_ros/planning_messages.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>

#include "mvog/height_colour.h"
#include "mvog_ros/visualization.h"

namespace mvog_ros {
namespace {

/// An unorganized, dense cloud of `size` points whose fields, in this order, are 4 bytes each:
/// (name, sensor_msgs::PointField datatype).
sensor_msgs::PointCloud2 cloudOf(std::size_t size,
                                 const std::vector<std::pair<const char*, std::uint8_t>>& fields,
                                 const std::string& frame_id, const ros::Time& stamp) {
  sensor_msgs::PointCloud2 cloud;
  cloud.header.frame_id = frame_id;
  cloud.header.stamp = stamp;
  for (const auto& [name, datatype] : fields) {
    sensor_msgs::PointField field;
    field.name = name;
    field.offset = static_cast<std::uint32_t>(4 * cloud.fields.size());
    field.datatype = datatype;
    field.count = 1;
    cloud.fields.push_back(field);
  }
  cloud.height = 1;
  cloud.width = static_cast<std::uint32_t>(size);
  cloud.point_step = static_cast<std::uint32_t>(4 * fields.size());
  cloud.row_step = cloud.point_step * cloud.width;
  cloud.is_bigendian = __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__;  // put() writes the host's order
  cloud.is_dense = true;
  cloud.data.resize(std::size_t{cloud.row_step});
  return cloud;
}

/// Writes field `field` (4 bytes) of point `point`.
template <class Value>
void put(sensor_msgs::PointCloud2& cloud, std::size_t point, std::size_t field, Value value) {
  static_assert(sizeof(Value) == 4, "the clouds' fields are 4 bytes");
  std::memcpy(&cloud.data[point * cloud.point_step + 4 * field], &value, sizeof(Value));
}

}  // namespace

sensor_msgs::PointCloud2 frontierCloud(const std::vector<mvog::FrontierPoint>& points,
                                       const std::string& frame_id, const ros::Time& stamp) {
  using sensor_msgs::PointField;
  sensor_msgs::PointCloud2 cloud = cloudOf(points.size(),
                                           {{"x", PointField::FLOAT32},
                                            {"y", PointField::FLOAT32},
                                            {"z", PointField::FLOAT32},
                                            {"cluster", PointField::UINT32}},
                                           frame_id, stamp);
  for (std::size_t k = 0; k < points.size(); ++k) {
    put(cloud, k, 0, points[k].x);
    put(cloud, k, 1, points[k].y);
    put(cloud, k, 2, points[k].z);
    put(cloud, k, 3, points[k].cluster);
  }
  return cloud;
}

visualization_msgs::MarkerArray frontierMarkers(const std::vector<mvog::FrontierPoint>& points,
                                                std::uint32_t num_clusters, double resolution,
                                                const std::string& frame_id,
                                                const ros::Time& stamp) {
  visualization_msgs::MarkerArray markers;
  markers.markers.push_back(deleteAllMarker(frame_id, stamp));
  for (std::uint32_t k = 0; k < num_clusters; ++k) {
    visualization_msgs::Marker cluster = markers.markers.front();
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
  using sensor_msgs::PointField;
  sensor_msgs::PointCloud2 cloud = cloudOf(surfaces.size(),
                                           {{"x", PointField::FLOAT32},
                                            {"y", PointField::FLOAT32},
                                            {"z", PointField::FLOAT32},
                                            {"clearance", PointField::FLOAT32},
                                            {"probability", PointField::FLOAT32}},
                                           frame_id, stamp);
  for (std::size_t k = 0; k < surfaces.size(); ++k) {
    put(cloud, k, 0, surfaces[k].x);
    put(cloud, k, 1, surfaces[k].y);
    put(cloud, k, 2, surfaces[k].z);
    put(cloud, k, 3, surfaces[k].clearance);
    put(cloud, k, 4, surfaces[k].probability);
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
