// A depth image's readings as its pixels are read (internal to the core): the one statement of
// the back-projection, shared by backProjectDepthImage (a Scan of them) and the insertion
// straight from the image (ScanUpdate::prepare of a DepthFrame).
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>

#include <Eigen/Geometry>

#include "mvog/depth_image.h"

namespace mvog {
namespace detail {

/// Millimetres to metres, in float as depth_image_proc converts them (DepthTraits<uint16_t>).
constexpr float kMetresPerMillimetre = 0.001f;

/// A point as a Scan holds it.
inline Eigen::Vector3f toFloat(const Eigen::Vector3d& p) {
  return {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())};
}

/// Calls hit(p) for each kept pixel of `frame` (validated) with a finite depth > 0, and
/// out_of_range(p) for each +Inf pixel when config.no_return_length is finite, p its reading
/// in the map frame (float, as a Scan holds it), row by row from row `first_row` to `end_row`
/// (those the stride keeps); counts the other kept pixels in `skipped` (REP-118: 0, NaN,
/// negative and -Inf say nothing).
template <class Hit, class OutOfRange>
void forEachDepthReading(const DepthFrame& frame, std::size_t first_row, std::size_t end_row,
                         Hit&& hit, OutOfRange&& out_of_range, std::size_t& skipped) {
  const DepthImageView& image = frame.image;
  const PinholeCamera& camera = frame.camera;
  const bool millimetres = image.encoding == DepthEncoding::kUint16Millimetres;
  // The arithmetic of depth_image_proc's convert() (ROS 1): the principal point in float, the
  // unit and the focal length folded into one float factor per axis. A cloud it made of the same
  // image is the same readings, bit for bit, and maps the same.
  const double unit = millimetres ? double{kMetresPerMillimetre} : 1.0;
  const auto center_x = static_cast<float>(camera.cx);
  const auto center_y = static_cast<float>(camera.cy);
  const auto constant_x = static_cast<float>(unit / camera.fx);
  const auto constant_y = static_cast<float>(unit / camera.fy);
  const bool no_return_is_free = std::isfinite(frame.config.no_return_length);
  const auto stride = static_cast<std::size_t>(frame.config.stride);
  const std::size_t pixel_bytes = DepthImageView::bytesPerPixel(image.encoding);
  const Eigen::Isometry3d& map_from_camera = frame.map_from_camera;
  for (std::size_t v = (first_row + stride - 1) / stride * stride; v < end_row; v += stride) {
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
        hit(toFloat(map_from_camera * Eigen::Vector3d(x, y, z)));
      } else if (z == std::numeric_limits<float>::infinity() && no_return_is_free) {
        const Eigen::Vector3d ray((static_cast<double>(u) - camera.cx) / camera.fx,
                                  (static_cast<double>(v) - camera.cy) / camera.fy, 1.0);
        out_of_range(
            toFloat(map_from_camera * (ray * (frame.config.no_return_length / ray.norm()))));
      } else {
        ++skipped;
      }
    }
  }
}

}  // namespace detail
}  // namespace mvog
