// Depth images to readings (mvog/depth_image.h): the pinhole back-projection, REP-118's special
// depths, millimetres, the stride, row padding, and the refusal of inconsistent images, cameras
// and configs.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "mvog/depth_image.h"
#include "mvog/map.h"
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

/// Both the back-projection and the insertion straight from the image refuse the image, naming
/// `field`, and the map stays as it was.
void expectRefused(const DepthImageView& view, const PinholeCamera& camera,
                   const DepthImageConfig& config, const std::string& field) {
  std::size_t skipped = 0;
  try {
    backProjectDepthImage(view, camera, Eigen::Isometry3d::Identity(), config, skipped);
    ADD_FAILURE() << "accepted; expected a refusal naming " << field;
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(field + ":", 0), 0u) << e.what();
  }
  Map map(MapConfig{});
  map.insertReading({0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}, ReadingKind::kObstacle);
  const std::vector<test::VolumeRecord> before = test::allVolumes(map);
  const std::uint64_t revision = map.revision();
  try {
    map.insertDepthImage({view, camera, Eigen::Isometry3d::Identity(), config});
    ADD_FAILURE() << "inserted; expected a refusal naming " << field;
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(field + ":", 0), 0u) << e.what();
  }
  EXPECT_TRUE(test::sameVolumes(test::allVolumes(map), before));
  EXPECT_EQ(map.revision(), revision);
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

// ---- Straight from the image (Map::insertDepthImage) ------------------------------------------

/// A Kinect's intrinsics at 640 x 480.
const PinholeCamera kKinect{525.0, 525.0, 319.5, 239.5};
constexpr std::uint32_t kKinectWidth = 640;
constexpr std::uint32_t kKinectHeight = 480;

/// The camera 1.2 m above the floor looking along +x, pitched 10 degrees down and turned 30
/// degrees: optical z forward, x right, y down.
Eigen::Isometry3d kinectPose() {
  Eigen::Matrix3d looking_along_x;
  looking_along_x << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translate(Eigen::Vector3d(0.3, -0.2, 1.2));
  pose.rotate(Eigen::AngleAxisd(0.5236, Eigen::Vector3d::UnitZ()) *
              Eigen::AngleAxisd(0.1745, Eigen::Vector3d::UnitY()) * looking_along_x);
  return pose;
}

/// The depth (along the optical axis) of pixel (u, v) seeing a wall `wall` m ahead with a
/// vertical pole of radius `pole_radius` m in front of it, `pole_depth` m ahead and 0.3 m to
/// the right (the pole along the image's columns); no pole if pole_radius is 0.
double sceneDepth(std::uint32_t u, std::uint32_t v, double wall, double pole_depth = 0.0,
                  double pole_radius = 0.0) {
  const double a = (u - kKinect.cx) / kKinect.fx;  // x / z along the pixel's ray
  static_cast<void>(v);
  double depth = wall;
  if (pole_radius > 0.0) {
    // (a t - 0.3)^2 + (t - pole_depth)^2 = r^2, t the depth.
    const double qa = a * a + 1.0;
    const double qb = -2.0 * (0.3 * a + pole_depth);
    const double qc = 0.09 + pole_depth * pole_depth - pole_radius * pole_radius;
    const double discriminant = qb * qb - 4.0 * qa * qc;
    if (discriminant >= 0.0) depth = std::min(depth, (-qb - std::sqrt(discriminant)) / (2.0 * qa));
  }
  return depth;
}

/// A Kinect-sized image of sceneDepth, in either encoding, with every 97th pixel set to
/// `special` (NaN, 0, +Inf, -Inf, or a saturated 65535 mm), so that every kind of pixel comes.
template <class Pixel>
Image<Pixel> sceneImage(double wall, double pole_depth, double pole_radius, Pixel special) {
  std::vector<Pixel> pixels;
  for (std::uint32_t v = 0; v < kKinectHeight; ++v) {
    for (std::uint32_t u = 0; u < kKinectWidth; ++u) {
      const double depth = sceneDepth(u, v, wall, pole_depth, pole_radius);
      Pixel pixel = sizeof(Pixel) == 2 ? static_cast<Pixel>(std::lround(1000.0 * depth))
                                       : static_cast<Pixel>(depth);
      if ((v * kKinectWidth + u) % 97 == 0) pixel = special;
      pixels.push_back(pixel);
    }
  }
  return Image<Pixel>(kKinectWidth, pixels, 4);
}

/// Inserting `frame` straight from its pixels makes the map, and counts, of inserting the Scan
/// backProjectDepthImage makes of it, bit for bit.
void expectSameAsItsScan(const DepthFrame& frame, const MapConfig& map_config,
                         const InsertionConfig& insertion) {
  std::size_t skipped = 0;
  const Scan scan = backProjectDepthImage(frame, skipped);
  Map from_scan(map_config);
  Map from_image(map_config);
  const InsertionResult scan_result = from_scan.insertScan(scan, insertion);
  const InsertionResult image_result = from_image.insertDepthImage(frame, insertion);
  EXPECT_TRUE(test::sameVolumes(test::allVolumes(from_image), test::allVolumes(from_scan)));
  EXPECT_EQ(image_result.obstacle_readings, scan_result.obstacle_readings);
  EXPECT_EQ(image_result.out_of_range_readings, scan_result.out_of_range_readings);
  EXPECT_EQ(image_result.truncated_to_max_range, scan_result.truncated_to_max_range);
  EXPECT_EQ(image_result.rays_walked, scan_result.rays_walked);
  EXPECT_EQ(image_result.rejected_too_close, scan_result.rejected_too_close);
  EXPECT_EQ(image_result.rejected_no_measurement, skipped);
  EXPECT_EQ(image_result.rejected(), scan_result.rejected() + skipped);
  EXPECT_EQ(image_result.inserted() + image_result.rejected(),
            keptPixels(frame.image, frame.config));
}

TEST(InsertDepthImage, MakesTheMapOfTheImagesReadingsBitForBitWhateverTheThreadsAndOptions) {
  const auto mm = sceneImage<std::uint16_t>(3.5, 2.0, 0.05, 0);
  const auto metres = sceneImage<float>(3.5, 2.0, 0.05, std::numeric_limits<float>::quiet_NaN());
  const auto no_return = sceneImage<float>(3.5, 2.0, 0.05, kFloatInf);
  const auto too_close = sceneImage<float>(3.5, 2.0, 0.05, -kFloatInf);
  const auto saturated = sceneImage<std::uint16_t>(3.5, 2.0, 0.05, 65535);
  DepthImageConfig strided;
  strided.stride = 3;
  DepthImageConfig free_when_no_return;
  free_when_no_return.no_return_length = 3.0;
  InsertionConfig ranged;
  ranged.min_range = 0.8;
  ranged.max_range = 3.0;
  InsertionConfig every_reading;
  every_reading.free_space_rays = FreeSpaceRays::kEveryReading;
  MapConfig paper;
  paper.resolution = 0.05;
  paper.rules = ModelRules::paper();
  MapConfig defaults;
  defaults.resolution = 0.05;
  const struct {
    const char* name;
    DepthImageView image;
    DepthImageConfig config;
    MapConfig map;
    InsertionConfig insertion;
  } cases[] = {
      {"16UC1, zeros", mm.view, {}, defaults, {}},
      {"32FC1, NaNs, stride 3", metres.view, strided, defaults, {}},
      {"+Inf freeing 3 m", no_return.view, free_when_no_return, defaults, {}},
      {"+Inf skipped", no_return.view, {}, defaults, {}},
      {"-Inf", too_close.view, {}, defaults, {}},
      {"saturated 65535 mm, min and max range", saturated.view, {}, defaults, ranged},
      {"every reading's ray", no_return.view, free_when_no_return, defaults, every_reading},
      {"the paper's model", mm.view, {}, paper, {}},
  };
  for (const auto& c : cases) {
    for (int threads : {1, 2, 4}) {
      SCOPED_TRACE(std::string(c.name) + ", " + std::to_string(threads) + " threads");
      InsertionConfig insertion = c.insertion;
      insertion.insertion_threads = threads;
      expectSameAsItsScan({c.image, kKinect, kinectPose(), c.config}, c.map, insertion);
    }
  }
}

TEST(InsertDepthImage, AWallAt1And4MetresAndA2cmPoleAt3MetresAreOccupiedAcrossTheImage) {
  // Every pixel inserted: every hit's point is occupied, the pole's too (3.5 pixels wide: a
  // stride of 4 could miss it), and the space halfway to the hits is free.
  for (const auto& [wall, pole_radius] : {std::pair{1.0, 0.0}, std::pair{4.0, 0.01}}) {
    SCOPED_TRACE("wall at " + std::to_string(wall) + " m");
    const auto image = sceneImage<float>(wall, 3.0, pole_radius, static_cast<float>(wall));
    const DepthFrame frame{image.view, kKinect, kinectPose(), {}};
    MapConfig config;
    config.resolution = 0.05;
    Map map(config);
    const InsertionResult result = map.insertDepthImage(frame);
    EXPECT_EQ(result.obstacle_readings, std::size_t{kKinectWidth} * kKinectHeight);
    EXPECT_LT(result.rays_walked, result.obstacle_readings / 5);
    std::size_t skipped = 0;
    const Scan scan = backProjectDepthImage(frame, skipped);
    const test::HitStates states = test::hitStates(map, scan, [&](std::size_t k) {
      const auto u = static_cast<std::uint32_t>(k % kKinectWidth);
      return pole_radius > 0.0 && sceneDepth(u, 0, wall, 3.0, pole_radius) < wall;
    });
    EXPECT_EQ(states.occupied, scan.hits.size());
    EXPECT_GE(100 * states.free_midpoints, 99 * scan.hits.size());
    if (pole_radius > 0.0) {
      EXPECT_GE(states.marked, 3u * kKinectHeight);
      EXPECT_EQ(states.marked_occupied, states.marked);
    }
  }
}

}  // namespace
}  // namespace mvog
