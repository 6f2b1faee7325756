// Depth images to readings: the pinhole back-projection of REP-118 depth images.
#include "mvog/depth_image.h"

#include <cmath>
#include <cstring>
#include <string>

#include "config_checks.h"

namespace mvog {
namespace {

using detail::invalidField;
using detail::require;

/// Millimetres to metres, in float as depth_image_proc converts them (DepthTraits<uint16_t>).
constexpr float kMetresPerMillimetre = 0.001f;

}  // namespace

void DepthImageView::validate() const {
  const std::size_t row_bytes = std::size_t{width} * bytesPerPixel(encoding);
  if (step < row_bytes) {
    invalidField("step", std::to_string(step) + " bytes is less than width x bytes per pixel (" +
                             std::to_string(row_bytes) + ")");
  }
  // height x step <= size, without overflow.
  if (height != 0 && step > size / height) {
    invalidField("size", std::to_string(size) + " bytes is less than height x step (" +
                             std::to_string(height) + " x " + std::to_string(step) + ")");
  }
  require(data != nullptr || size == 0, "data", "is null");
}

void PinholeCamera::validate() const {
  require(std::isfinite(fx) && fx != 0.0, "fx", "must be finite and non-zero");
  require(std::isfinite(fy) && fy != 0.0, "fy", "must be finite and non-zero");
  require(std::isfinite(cx), "cx", "must be finite");
  require(std::isfinite(cy), "cy", "must be finite");
}

void DepthImageConfig::validate() const {
  require(stride >= 1, "stride", "must be >= 1");
  require(!std::isnan(no_return_length) && no_return_length > 0.0, "no_return_length",
          "must be > 0 (infinity: +Inf pixels are skipped)");
}

std::size_t keptPixels(const DepthImageView& image, const DepthImageConfig& config) {
  const auto stride = static_cast<std::size_t>(config.stride);
  return ((std::size_t{image.width} + stride - 1) / stride) *
         ((std::size_t{image.height} + stride - 1) / stride);
}

Scan backProjectDepthImage(const DepthImageView& image, const PinholeCamera& camera,
                           const Eigen::Isometry3d& map_from_camera, const DepthImageConfig& config,
                           std::size_t& skipped_pixels) {
  image.validate();
  camera.validate();
  config.validate();
  Scan scan;
  scan.origin = map_from_camera.translation();
  skipped_pixels = 0;
  const std::size_t kept = keptPixels(image, config);
  if (kept == 0) return scan;  // no row to point at
  scan.hits.reserve(kept);
  const bool millimetres = image.encoding == DepthEncoding::kUint16Millimetres;
  // The arithmetic of depth_image_proc's convert() (ROS 1): the principal point in float, the
  // unit and the focal length folded into one float factor per axis. A cloud it made of the same
  // image is the same readings, bit for bit, and maps the same.
  const double unit = millimetres ? double{kMetresPerMillimetre} : 1.0;
  const auto center_x = static_cast<float>(camera.cx);
  const auto center_y = static_cast<float>(camera.cy);
  const auto constant_x = static_cast<float>(unit / camera.fx);
  const auto constant_y = static_cast<float>(unit / camera.fy);
  const bool no_return_is_free = std::isfinite(config.no_return_length);
  const auto stride = static_cast<std::size_t>(config.stride);
  const std::size_t pixel_bytes = DepthImageView::bytesPerPixel(image.encoding);
  for (std::size_t v = 0; v < image.height; v += stride) {
    const std::uint8_t* row = image.data + v * image.step;
    for (std::size_t u = 0; u < image.width; u += stride) {
      float depth = 0.0f;  // in the image's unit
      float z = 0.0f;      // in metres
      if (millimetres) {
        std::uint16_t raw = 0;
        std::memcpy(&raw, row + u * pixel_bytes, sizeof raw);
        depth = raw;
        z = depth * kMetresPerMillimetre;
      } else {
        std::memcpy(&depth, row + u * pixel_bytes, sizeof depth);
        z = depth;
      }
      if (std::isfinite(z) && z > 0.0f) {
        const float x = (static_cast<float>(u) - center_x) * depth * constant_x;
        const float y = (static_cast<float>(v) - center_y) * depth * constant_y;
        scan.hits.push_back((map_from_camera * Eigen::Vector3d(x, y, z)).cast<float>());
      } else if (z == std::numeric_limits<float>::infinity() && no_return_is_free) {
        const Eigen::Vector3d ray((static_cast<double>(u) - camera.cx) / camera.fx,
                                  (static_cast<double>(v) - camera.cy) / camera.fy, 1.0);
        scan.out_of_range.push_back(
            (map_from_camera * (ray * (config.no_return_length / ray.norm()))).cast<float>());
      } else {
        ++skipped_pixels;
      }
    }
  }
  return scan;
}

}  // namespace mvog
