// Depth images to readings: the pinhole back-projection of REP-118 depth images.
#include "mvog/depth_image.h"

#include <cmath>
#include <string>

#include "config_checks.h"
#include "depth_readings.h"

namespace mvog {
namespace {

using detail::invalidField;
using detail::require;

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

void DepthFrame::validate() const {
  image.validate();
  camera.validate();
  config.validate();
}

Scan backProjectDepthImage(const DepthImageView& image, const PinholeCamera& camera,
                           const Eigen::Isometry3d& map_from_camera, const DepthImageConfig& config,
                           std::size_t& skipped_pixels) {
  return backProjectDepthImage(DepthFrame{image, camera, map_from_camera, config}, skipped_pixels);
}

Scan backProjectDepthImage(const DepthFrame& frame, std::size_t& skipped_pixels) {
  frame.validate();
  Scan scan;
  scan.origin = frame.map_from_camera.translation();
  skipped_pixels = 0;
  scan.hits.reserve(keptPixels(frame.image, frame.config));
  detail::forEachDepthReading(
      frame, 0, frame.image.height, [&](const Eigen::Vector3f& p) { scan.hits.push_back(p); },
      [&](const Eigen::Vector3f& p) { scan.out_of_range.push_back(p); }, skipped_pixels);
  return scan;
}

}  // namespace mvog
