#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <variant>

#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/PointCloud2.h>
#include <Eigen/Geometry>

#include "mvog/depth_image.h"
#include "mvog/map.h"

namespace mvog_ros {

/// A sensor message that cannot be turned into readings; the message says why.
class InvalidMessage : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A LaserScan as an mvog::Scan: its readings in the map frame given the sensor's pose
/// `map_from_sensor` at the scan's stamp (the pose is taken as constant over the sweep), from the
/// sensor frame's origin. REP-117: a finite range within [range_min, range_max] is an obstacle
/// reading; +Inf and ranges above range_max are out-of-range readings, free up to
/// min(range_max, max_free_range); NaN, -Inf and ranges below range_min say nothing about free
/// space (an object may be too close) and are skipped.
/// Throws InvalidMessage for a malformed scan (bad angles, range limits, or beam count).
mvog::Scan laserScanToScan(const sensor_msgs::LaserScan& scan,
                           const Eigen::Isometry3d& map_from_sensor, double max_free_range,
                           std::size_t max_beams, std::size_t& skipped_beams);

/// A PointCloud2 as an mvog::Scan: the points of a cloud of any layout (float32 or float64 x, y, z
/// at any offsets, organized or not, either byte order) as obstacle readings in the map frame,
/// from the sensor frame's origin. Non-finite points are passed on for the map to count and reject.
/// Throws InvalidMessage for a malformed cloud (missing or integer x/y/z fields, fields beyond
/// point_step, data shorter than its dimensions, more than max_points points).
mvog::Scan pointCloudToScan(const sensor_msgs::PointCloud2& cloud,
                            const Eigen::Isometry3d& map_from_sensor, std::size_t max_points);

/// A depth image with its camera info as an mvog::DepthFrame viewing `image`'s data (the camera
/// info's K: the image rectified, as depth drivers publish it), the camera at `map_from_camera`.
/// REP-118: encoding "16UC1" (millimetres) or "32FC1" (metres).
/// Throws InvalidMessage for another encoding, big-endian data, a step or data too short for the
/// image, a camera info of another size than the image or whose K is zero or non-finite, or more
/// than max_points pixels kept.
mvog::DepthFrame depthFrameOf(const sensor_msgs::Image& image,
                              const sensor_msgs::CameraInfo& camera_info,
                              const Eigen::Isometry3d& map_from_camera,
                              const mvog::DepthImageConfig& config, std::size_t max_points);

/// depthFrameOf's frame as an mvog::Scan (mvog::backProjectDepthImage), from the optical frame's
/// origin: 0, NaN and -Inf say nothing (counted in `skipped_pixels`), +Inf is an out-of-range
/// reading. Throws InvalidMessage as depthFrameOf.
mvog::Scan depthImageToScan(const sensor_msgs::Image& image,
                            const sensor_msgs::CameraInfo& camera_info,
                            const Eigen::Isometry3d& map_from_camera,
                            const mvog::DepthImageConfig& config, std::size_t max_points,
                            std::size_t& skipped_pixels);

/// A depth image inserted straight from its pixels (mvog::Map::insertDepthImage): the frame views
/// the image message, kept alive with it.
struct DepthImageReadings {
  sensor_msgs::ImageConstPtr image;
  mvog::DepthFrame frame;
};

/// What a sensor message becomes for the insertion: a Scan, or a depth image.
using SensorReadings = std::variant<mvog::Scan, DepthImageReadings>;

/// The readings `readings` holds (a depth image's kept pixels), and where they were taken from.
std::size_t readingCount(const SensorReadings& readings);
Eigen::Vector3d sensorOrigin(const SensorReadings& readings);

/// Keeps one point per voxel of edge `leaf_size` (the centroid of its points), with PCL.
/// Non-finite points are dropped: returns how many.
std::size_t voxelFilter(std::vector<Eigen::Vector3f>& points, double leaf_size);

}  // namespace mvog_ros
