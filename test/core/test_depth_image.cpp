// Depth images to readings (mvog/depth_image.h): the pinhole back-projection, REP-118's special
// depths, millimetres, the stride, row padding, and the refusal of inconsistent images, cameras
// and configs.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "mvog/depth_image.h"
#include "test_util.h"

namespace mvog {
namespace {

using test::kFloatInf;
using test::kFloatNaN;

/// fx = 2, fy = 4, cx = 1.5, cy = 0.5: binary fractions, so that 32FC1 points are exact.
const PinholeCamera kCamera{2.0, 4.0, 1.5, 0.5};

/// Pixels of one type, row after row, each row padded with `padding` bytes of 0xAB.
template <class Pixel>
struct Image {
  std::vector<std::uint8_t> bytes;
  DepthImageView view;

  Image(std::uint32_t width, const std::vector<Pixel>& pixels, std::size_t padding = 0) {
    view.width = width;
    view.height = width == 0 ? 0 : static_cast<std::uint32_t>(pixels.size() / width);
    view.step = width * sizeof(Pixel) + padding;
    view.encoding =
        sizeof(Pixel) == 2 ? DepthEncoding::kUint16Millimetres : DepthEncoding::kFloat32Metres;
    bytes.assign(view.step * view.height, 0xAB);
    for (std::size_t k = 0; k < pixels.size(); ++k) {
      std::memcpy(bytes.data() + (k / width) * view.step + (k % width) * sizeof(Pixel), &pixels[k],
                  sizeof(Pixel));
    }
    view.data = bytes.data();
    view.size = bytes.size();
  }
};

Scan backProject(const DepthImageView& view, std::size_t& skipped,
                 const DepthImageConfig& config = {},
                 const Eigen::Isometry3d& pose = Eigen::Isometry3d::Identity()) {
  return backProjectDepthImage(view, kCamera, pose, config, skipped);
}

TEST(BackProjectDepthImage, PutsEveryPixelWhereThePinholeModelSaysRowAfterRow) {
  const Image<float> image(4, {1.0f, 2.0f, 3.0f, 4.0f, 0.5f, 1.5f, 2.5f, 8.0f});
  std::size_t skipped = 99;
  const Scan scan = backProject(image.view, skipped);
  EXPECT_EQ(skipped, 0u);
  EXPECT_TRUE(scan.out_of_range.empty());
  ASSERT_EQ(scan.hits.size(), 8u);
  // ((u - 1.5) z / 2, (v - 0.5) z / 4, z)
  EXPECT_EQ(scan.hits[0], Eigen::Vector3f(-0.75f, -0.125f, 1.0f));
  EXPECT_EQ(scan.hits[3], Eigen::Vector3f(3.0f, -0.5f, 4.0f));
  EXPECT_EQ(scan.hits[4], Eigen::Vector3f(-0.375f, 0.0625f, 0.5f));
  EXPECT_EQ(scan.hits[7], Eigen::Vector3f(6.0f, 1.0f, 8.0f));
}

TEST(BackProjectDepthImage, StartsRaysAtTheCameraAndAppliesItsPose) {
  const Image<float> image(1, {2.0f});
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translate(Eigen::Vector3d(1.0, 2.0, 3.0));
  pose.rotate(Eigen::AngleAxisd(M_PI / 2.0, Eigen::Vector3d::UnitZ()));
  std::size_t skipped = 0;
  const Scan scan = backProject(image.view, skipped, {}, pose);
  EXPECT_TRUE(scan.origin.isApprox(Eigen::Vector3d(1.0, 2.0, 3.0)));
  ASSERT_EQ(scan.hits.size(), 1u);
  // (-1.5, -0.25, 2) in the camera frame: its x is the map's y.
  EXPECT_TRUE(scan.hits[0].isApprox(Eigen::Vector3f(1.25f, 0.5f, 5.0f)));
}

TEST(BackProjectDepthImage, FollowsRep118ForZeroNaNAndInfinities) {
  const Image<float> image(4,
                           {0.0f, kFloatNaN, -kFloatInf, -1.0f, kFloatInf, 2.0f, -0.0f, kFloatInf});
  DepthImageConfig config;
  config.no_return_length = 5.0;
  std::size_t skipped = 0;
  const Scan scan = backProject(image.view, skipped, config);
  // 0, NaN, -Inf and negative depths say nothing.
  EXPECT_EQ(skipped, 5u);
  ASSERT_EQ(scan.hits.size(), 1u);
  EXPECT_EQ(scan.hits[0], Eigen::Vector3f(-0.5f, 0.25f, 2.0f));
  // +Inf: no return, free along the pixel's ray up to no_return_length.
  ASSERT_EQ(scan.out_of_range.size(), 2u);
  const Eigen::Vector3d rays[2] = {{-0.75, 0.125, 1.0}, {0.75, 0.125, 1.0}};  // u = 0 and 3, v = 1
  for (int k = 0; k < 2; ++k) {
    EXPECT_TRUE(scan.out_of_range[k].cast<double>().isApprox(rays[k].normalized() * 5.0, 1e-6))
        << k;
  }
  // Without a length, a ray without a return says nothing either.
  const Scan without_length = backProject(image.view, skipped);
  EXPECT_EQ(skipped, 7u);
  EXPECT_TRUE(without_length.out_of_range.empty());
  EXPECT_EQ(without_length.hits.size(), 1u);
}

TEST(BackProjectDepthImage, ReadsMillimetresAndSkipsZero) {
  const Image<std::uint16_t> image(2, {1000, 0, 2500, 65535});
  std::size_t skipped = 0;
  const Scan scan = backProject(image.view, skipped);
  EXPECT_EQ(skipped, 1u);
  ASSERT_EQ(scan.hits.size(), 3u);
  EXPECT_TRUE(scan.hits[0].isApprox(Eigen::Vector3f(-0.75f, -0.125f, 1.0f)));
  EXPECT_TRUE(scan.hits[1].isApprox(Eigen::Vector3f(-1.875f, 0.3125f, 2.5f)));
  EXPECT_TRUE(scan.hits[2].isApprox(Eigen::Vector3f(-16.38375f, 8.191875f, 65.535f)));
}

TEST(BackProjectDepthImage, KeepsEveryStrideThPixelFromTheFirst) {
  // 5 x 3 pixels, each its own depth 1 + u + 10 v.
  std::vector<float> pixels;
  for (int v = 0; v < 3; ++v) {
    for (int u = 0; u < 5; ++u) pixels.push_back(static_cast<float>(1 + u + 10 * v));
  }
  const Image<float> image(5, pixels, 3);  // rows padded too
  DepthImageConfig config;
  config.stride = 2;
  EXPECT_EQ(keptPixels(image.view, config), 6u);
  std::size_t skipped = 0;
  const Scan scan = backProject(image.view, skipped, config);
  std::vector<float> depths;
  for (const Eigen::Vector3f& hit : scan.hits) depths.push_back(hit.z());
  EXPECT_EQ(depths, (std::vector<float>{1, 3, 5, 21, 23, 25}));
  config.stride = 7;
  EXPECT_EQ(keptPixels(image.view, config), 1u);
  EXPECT_EQ(backProject(image.view, skipped, config).hits.size(), 1u);
}

TEST(BackProjectDepthImage, TakesAnEmptyImage) {
  DepthImageView view;  // no data at all
  std::size_t skipped = 99;
  EXPECT_TRUE(backProject(view, skipped).hits.empty());
  EXPECT_EQ(skipped, 0u);
  view.height = 100;  // rows of no pixels
  EXPECT_TRUE(backProject(view, skipped).hits.empty());
}

void expectRefused(const DepthImageView& view, const PinholeCamera& camera,
                   const DepthImageConfig& config, const std::string& field) {
  std::size_t skipped = 0;
  try {
    backProjectDepthImage(view, camera, Eigen::Isometry3d::Identity(), config, skipped);
    ADD_FAILURE() << "accepted; expected a refusal naming " << field;
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(field + ":", 0), 0u) << e.what();
  }
}

TEST(BackProjectDepthImage, RefusesImagesCamerasAndConfigsItCannotUseNamingTheField) {
  const Image<std::uint16_t> valid(3, {1000, 1000, 1000, 1000, 1000, 1000});
  DepthImageView view = valid.view;
  view.step = 5;  // less than 3 pixels of 2 bytes
  expectRefused(view, kCamera, {}, "step");
  view = valid.view;
  view.size -= 1;
  expectRefused(view, kCamera, {}, "size");
  view = valid.view;
  view.encoding = DepthEncoding::kFloat32Metres;  // 12 bytes a row, in rows of 6
  expectRefused(view, kCamera, {}, "step");
  view = valid.view;
  view.step = std::size_t{1} << 62;  // height x step overflows
  view.height = 8;
  expectRefused(view, kCamera, {}, "size");
  view = valid.view;
  view.data = nullptr;
  expectRefused(view, kCamera, {}, "data");

  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  expectRefused(valid.view, {0.0, 4.0, 1.5, 0.5}, {}, "fx");
  expectRefused(valid.view, {2.0, nan, 1.5, 0.5}, {}, "fy");
  expectRefused(valid.view, {2.0, 4.0, inf, 0.5}, {}, "cx");
  expectRefused(valid.view, {2.0, 4.0, 1.5, nan}, {}, "cy");
  expectRefused(valid.view, PinholeCamera{}, {}, "fx");  // K all zero

  DepthImageConfig config;
  config.stride = 0;
  expectRefused(valid.view, kCamera, config, "stride");
  config = {};
  config.no_return_length = 0.0;
  expectRefused(valid.view, kCamera, config, "no_return_length");
  config.no_return_length = nan;
  expectRefused(valid.view, kCamera, config, "no_return_length");
}

}  // namespace
}  // namespace mvog
