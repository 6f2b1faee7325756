#include "mvog_ros/conversions.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include <pcl/filters/voxel_grid.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

namespace mvog_ros {
namespace {

constexpr bool kHostIsBigEndian = false;  // every platform Debian's ROS 1 runs on is little-endian

/// Reads one coordinate of a point: float32 or float64, in the cloud's byte order.
double readCoordinate(const std::uint8_t* at, std::uint8_t datatype, bool swap_bytes) {
  std::uint8_t bytes[8];
  const std::size_t size = datatype == sensor_msgs::PointField::FLOAT64 ? 8 : 4;
  std::memcpy(bytes, at, size);
  if (swap_bytes) std::reverse(bytes, bytes + size);
  if (size == 8) {
    double value;
    std::memcpy(&value, bytes, 8);
    return value;
  }
  float value;
  std::memcpy(&value, bytes, 4);
  return value;
}

}  // namespace

mvog::Scan laserScanToScan(const sensor_msgs::LaserScan& scan,
                           const Eigen::Isometry3d& map_from_sensor, double max_free_range,
                           std::size_t max_beams, std::size_t& skipped_beams) {
  if (scan.ranges.empty()) throw InvalidMessage("LaserScan has no beams");
  if (scan.ranges.size() > max_beams) {
    throw InvalidMessage("LaserScan has " + std::to_string(scan.ranges.size()) +
                         " beams, more than ~max_points_per_message");
  }
  if (!std::isfinite(scan.angle_min) || !std::isfinite(scan.angle_increment) ||
      (scan.ranges.size() > 1 && scan.angle_increment == 0.0f)) {
    throw InvalidMessage(
        "LaserScan angle_min and angle_increment must be finite, and the "
        "increment non-zero");
  }
  if (!std::isfinite(scan.range_min) || !std::isfinite(scan.range_max) || scan.range_min < 0.0f ||
      scan.range_max <= scan.range_min) {
    throw InvalidMessage("LaserScan range limits must be finite with 0 <= range_min < range_max");
  }
  const double free_range = std::min<double>(scan.range_max, max_free_range);
  // The sensor's height in float, as its points' heights are: a level laser's points then lie
  // at its height exactly, and the map inserts the scan as a level one (mvog::Scan::origin).
  Eigen::Isometry3d pose = map_from_sensor;
  pose.translation().z() = static_cast<double>(static_cast<float>(pose.translation().z()));
  mvog::Scan readings;
  readings.origin = pose.translation();
  readings.hits.reserve(scan.ranges.size());
  skipped_beams = 0;
  for (std::size_t k = 0; k < scan.ranges.size(); ++k) {
    const double range = scan.ranges[k];
    const double angle = scan.angle_min + static_cast<double>(k) * scan.angle_increment;
    const Eigen::Vector3d direction(std::cos(angle), std::sin(angle), 0.0);
    if (std::isfinite(range) && range >= scan.range_min && range <= scan.range_max) {
      readings.hits.push_back((pose * (range * direction)).cast<float>());
    } else if (range == std::numeric_limits<double>::infinity() || range > scan.range_max) {
      readings.out_of_range.push_back((pose * (free_range * direction)).cast<float>());
    } else {
      ++skipped_beams;
    }
  }
  return readings;
}

mvog::Scan pointCloudToScan(const sensor_msgs::PointCloud2& cloud,
                            const Eigen::Isometry3d& map_from_sensor, std::size_t max_points) {
  const std::uint64_t num_points = std::uint64_t{cloud.width} * cloud.height;
  if (num_points > max_points) {
    throw InvalidMessage("PointCloud2 has " + std::to_string(num_points) +
                         " points, more than ~max_points_per_message");
  }
  const sensor_msgs::PointField* fields[3] = {nullptr, nullptr, nullptr};
  for (const sensor_msgs::PointField& field : cloud.fields) {
    for (int axis = 0; axis < 3; ++axis) {
      if (field.name == std::string(1, static_cast<char>('x' + axis))) fields[axis] = &field;
    }
  }
  for (int axis = 0; axis < 3; ++axis) {
    const std::string name(1, static_cast<char>('x' + axis));
    const sensor_msgs::PointField* field = fields[axis];
    if (field == nullptr) throw InvalidMessage("PointCloud2 has no '" + name + "' field");
    if (field->datatype != sensor_msgs::PointField::FLOAT32 &&
        field->datatype != sensor_msgs::PointField::FLOAT64) {
      throw InvalidMessage("PointCloud2 field '" + name + "' is not float32 or float64");
    }
    const std::uint64_t size = field->datatype == sensor_msgs::PointField::FLOAT64 ? 8 : 4;
    if (std::uint64_t{field->offset} + size > cloud.point_step) {
      throw InvalidMessage("PointCloud2 field '" + name + "' lies beyond point_step");
    }
  }
  if (num_points > 0 && (std::uint64_t{cloud.point_step} * cloud.width > cloud.row_step ||
                         std::uint64_t{cloud.row_step} * cloud.height > cloud.data.size())) {
    throw InvalidMessage("PointCloud2 data (" + std::to_string(cloud.data.size()) +
                         " bytes) is shorter than its width, height, point_step and row_step say");
  }
  const bool swap_bytes = static_cast<bool>(cloud.is_bigendian) != kHostIsBigEndian;
  mvog::Scan readings;
  readings.origin = map_from_sensor.translation();
  // Nothing to read (width or height 0): row pointers into the data would point nowhere.
  if (num_points == 0) return readings;
  readings.hits.reserve(num_points);
  for (std::uint32_t row = 0; row < cloud.height; ++row) {
    const std::uint8_t* point = cloud.data.data() + std::size_t{row} * cloud.row_step;
    for (std::uint32_t column = 0; column < cloud.width; ++column, point += cloud.point_step) {
      Eigen::Vector3d p;
      for (int axis = 0; axis < 3; ++axis) {
        p[axis] = readCoordinate(point + fields[axis]->offset, fields[axis]->datatype, swap_bytes);
      }
      readings.hits.push_back((map_from_sensor * p).cast<float>());
    }
  }
  return readings;
}

mvog::DepthFrame depthFrameOf(const sensor_msgs::Image& image,
                              const sensor_msgs::CameraInfo& camera_info,
                              const Eigen::Isometry3d& map_from_camera,
                              const mvog::DepthImageConfig& config, std::size_t max_points) {
  mvog::DepthImageView view;
  if (image.encoding == "16UC1") {
    view.encoding = mvog::DepthEncoding::kUint16Millimetres;
  } else if (image.encoding == "32FC1") {
    view.encoding = mvog::DepthEncoding::kFloat32Metres;
  } else {
    throw InvalidMessage("depth image encoding '" + image.encoding +
                         "' is neither 16UC1 (millimetres) nor 32FC1 (metres)");
  }
  if (static_cast<bool>(image.is_bigendian) != kHostIsBigEndian) {
    throw InvalidMessage("depth image is big-endian (is_bigendian set): not supported");
  }
  if (camera_info.width != image.width || camera_info.height != image.height) {
    throw InvalidMessage("camera info is for " + std::to_string(camera_info.width) + "x" +
                         std::to_string(camera_info.height) + " pixels, the depth image has " +
                         std::to_string(image.width) + "x" + std::to_string(image.height));
  }
  view.data = image.data.data();
  view.size = image.data.size();
  view.width = image.width;
  view.height = image.height;
  view.step = image.step;
  const mvog::PinholeCamera camera{camera_info.K[0], camera_info.K[4], camera_info.K[2],
                                   camera_info.K[5]};
  try {
    view.validate();
  } catch (const mvog::ConfigError& e) {
    throw InvalidMessage(std::string("depth image ") + e.what());
  }
  try {
    camera.validate();
  } catch (const mvog::ConfigError& e) {
    throw InvalidMessage(std::string("camera info K: ") + e.what());
  }
  const std::size_t pixels = mvog::keptPixels(view, config);
  if (pixels > max_points) {
    throw InvalidMessage("depth image keeps " + std::to_string(pixels) +
                         " pixels, more than ~max_points_per_message");
  }
  return {view, camera, map_from_camera, config};
}

mvog::Scan depthImageToScan(const sensor_msgs::Image& image,
                            const sensor_msgs::CameraInfo& camera_info,
                            const Eigen::Isometry3d& map_from_camera,
                            const mvog::DepthImageConfig& config, std::size_t max_points,
                            std::size_t& skipped_pixels) {
  return mvog::backProjectDepthImage(
      depthFrameOf(image, camera_info, map_from_camera, config, max_points), skipped_pixels);
}

std::size_t readingCount(const SensorReadings& readings) {
  if (const auto* depth = std::get_if<DepthImageReadings>(&readings)) {
    return mvog::keptPixels(depth->frame.image, depth->frame.config);
  }
  const mvog::Scan& scan = std::get<mvog::Scan>(readings);
  return scan.hits.size() + scan.out_of_range.size();
}

Eigen::Vector3d sensorOrigin(const SensorReadings& readings) {
  if (const auto* depth = std::get_if<DepthImageReadings>(&readings)) {
    return depth->frame.map_from_camera.translation();
  }
  return std::get<mvog::Scan>(readings).origin;
}

std::size_t voxelFilter(std::vector<Eigen::Vector3f>& points, double leaf_size) {
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  cloud->reserve(points.size());
  for (const Eigen::Vector3f& p : points) {
    if (p.allFinite()) cloud->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  }
  const std::size_t non_finite = points.size() - cloud->size();
  pcl::VoxelGrid<pcl::PointXYZ> filter;
  filter.setInputCloud(cloud);
  const auto leaf = static_cast<float>(leaf_size);
  filter.setLeafSize(leaf, leaf, leaf);
  pcl::PointCloud<pcl::PointXYZ> filtered;
  filter.filter(filtered);
  points.clear();
  for (const pcl::PointXYZ& p : filtered) points.emplace_back(p.x, p.y, p.z);
  return non_finite;
}

}  // namespace mvog_ros
