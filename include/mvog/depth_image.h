#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>

#include <Eigen/Geometry>

#include "mvog/map.h"

namespace mvog {

/// How a depth image stores a pixel's depth along the camera's optical axis (REP-118).
enum class DepthEncoding : std::uint8_t {
  kUint16Millimetres,  ///< ROS "16UC1": unsigned millimetres; 0 is no measurement
  kFloat32Metres,      ///< ROS "32FC1": metres; 0 and NaN no measurement, +Inf no return,
                       ///< -Inf too close
};

/// A depth image in memory, not owned: `height` rows of `width` pixels, rows `step` bytes apart,
/// each pixel in the host's byte order.
struct DepthImageView {
  const std::uint8_t* data = nullptr;
  std::size_t size = 0;  ///< bytes at data
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  std::size_t step = 0;
  DepthEncoding encoding = DepthEncoding::kFloat32Metres;

  static std::size_t bytesPerPixel(DepthEncoding encoding) {
    return encoding == DepthEncoding::kUint16Millimetres ? 2 : 4;
  }
  /// Throws ConfigError naming the field unless every row lies within the data (step >= width
  /// x bytes per pixel, height x step <= size).
  void validate() const;
};

/// The pinhole camera of a rectified image (the K of a ROS CameraInfo, REP-104): the pixel
/// (u, v) at depth z is the point ((u - cx) z / fx, (v - cy) z / fy, z) of the camera's optical
/// frame (x right, y down, z forward).
struct PinholeCamera {
  double fx = 0.0;
  double fy = 0.0;
  double cx = 0.0;
  double cy = 0.0;

  /// Throws ConfigError naming the field unless fx and fy are finite and non-zero and cx and cy
  /// finite.
  void validate() const;
};

/// How a depth image becomes readings.
struct DepthImageConfig {
  /// Every stride-th pixel in both directions is kept, from pixel (0, 0).
  int stride = 1;
  /// A +Inf pixel (no return) is an out-of-range reading this far along its ray (m); infinite:
  /// such pixels say nothing (the core needs an end to walk to) and are skipped.
  double no_return_length = std::numeric_limits<double>::infinity();

  /// Throws ConfigError naming the first invalid field.
  void validate() const;
};

/// A depth image with the camera that took it and where: what inserting it straight from its
/// pixels needs (Map::insertDepthImage, ScanUpdate::prepare). Views the image, does not own it.
struct DepthFrame {
  DepthImageView image;
  PinholeCamera camera;
  Eigen::Isometry3d map_from_camera = Eigen::Isometry3d::Identity();
  DepthImageConfig config;

  /// Throws ConfigError naming the first invalid field of the image, the camera or the config.
  void validate() const;
};

/// The number of pixels `config` keeps of `image`.
std::size_t keptPixels(const DepthImageView& image, const DepthImageConfig& config);

/// The readings of a depth image taken by `camera` at `map_from_camera`, in one pass over the
/// kept pixels and without an allocation per pixel, from the optical frame's origin. REP-118: a
/// finite depth > 0 is an obstacle reading at its back-projected point; +Inf an out-of-range
/// reading (see DepthImageConfig::no_return_length); 0, NaN, negative depths and -Inf say
/// nothing and are skipped, counted in `skipped_pixels`. min_range and max_range apply to the
/// readings as to any (InsertionConfig). Throws ConfigError for an invalid image, camera or
/// config.
Scan backProjectDepthImage(const DepthImageView& image, const PinholeCamera& camera,
                           const Eigen::Isometry3d& map_from_camera, const DepthImageConfig& config,
                           std::size_t& skipped_pixels);
/// backProjectDepthImage of a DepthFrame.
Scan backProjectDepthImage(const DepthFrame& frame, std::size_t& skipped_pixels);

}  // namespace mvog
