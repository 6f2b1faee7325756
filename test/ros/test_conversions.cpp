// LaserScan, PointCloud2 and depth images to readings (mvog_ros/conversions.h): REP-117 and REP-118
// semantics, every cloud layout, the sensor pose, the same scene as an organised PointCloud2 and as
// a depth image (16UC1 and 32FC1) building the same map, and the refusal of every malformed
// message.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "mvog/map_io.h"
#include "mvog_ros/conversions.h"
#include "mvog_scene/scene.h"

namespace mvog_ros {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr std::size_t kManyPoints = 1000000;

/// A sensor at (1, 2, 3), turned 90 degrees about z: its x axis is the map's y axis.
Eigen::Isometry3d sensorPose() {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translate(Eigen::Vector3d(1.0, 2.0, 3.0));
  pose.rotate(Eigen::AngleAxisd(M_PI / 2.0, Eigen::Vector3d::UnitZ()));
  return pose;
}

void expectNear(const Eigen::Vector3f& actual, const Eigen::Vector3d& expected) {
  EXPECT_NEAR(actual.x(), expected.x(), 1e-5) << "y " << actual.y() << " z " << actual.z();
  EXPECT_NEAR(actual.y(), expected.y(), 1e-5) << "x " << actual.x() << " z " << actual.z();
  EXPECT_NEAR(actual.z(), expected.z(), 1e-5) << "x " << actual.x() << " y " << actual.y();
}

// ---- LaserScan ------------------------------------------------------------------------------

/// Four beams at 0, 90, 180 and 270 degrees, valid ranges in [0.5, 10].
sensor_msgs::LaserScan fourBeamScan(std::vector<float> ranges) {
  sensor_msgs::LaserScan scan;
  scan.angle_min = 0.0f;
  scan.angle_increment = static_cast<float>(M_PI / 2.0);
  scan.angle_max = static_cast<float>(3.0 * M_PI / 2.0);
  scan.range_min = 0.5f;
  scan.range_max = 10.0f;
  scan.ranges = std::move(ranges);
  return scan;
}

mvog::Scan convert(const sensor_msgs::LaserScan& scan, double max_free_range,
                   std::size_t& skipped) {
  return laserScanToScan(scan, Eigen::Isometry3d::Identity(), max_free_range, kManyPoints, skipped);
}

TEST(LaserScanToScan, ValidRangesAreHitsAlongTheirBeams) {
  std::size_t skipped = 99;
  const mvog::Scan readings = convert(fourBeamScan({1.0f, 2.0f, 0.5f, 10.0f}), kInf, skipped);
  EXPECT_EQ(skipped, 0u);
  EXPECT_TRUE(readings.out_of_range.empty());
  ASSERT_EQ(readings.hits.size(), 4u);
  expectNear(readings.hits[0], {1.0, 0.0, 0.0});
  expectNear(readings.hits[1], {0.0, 2.0, 0.0});
  expectNear(readings.hits[2], {-0.5, 0.0, 0.0});   // range_min itself is valid
  expectNear(readings.hits[3], {0.0, -10.0, 0.0});  // and so is range_max
}

TEST(LaserScanToScan, OutOfRangeBeamsAreFreeUpToRangeMaxOrTheMaximumFreeRange) {
  std::size_t skipped = 99;
  const sensor_msgs::LaserScan scan = fourBeamScan({kInf, 12.0f, 1.0f, 5.0f});
  mvog::Scan readings = convert(scan, kInf, skipped);
  EXPECT_EQ(skipped, 0u);
  ASSERT_EQ(readings.hits.size(), 2u);
  expectNear(readings.hits[0], {-1.0, 0.0, 0.0});
  expectNear(readings.hits[1], {0.0, -5.0, 0.0});  // a hit beyond max_free_range stays a hit
  ASSERT_EQ(readings.out_of_range.size(), 2u);
  expectNear(readings.out_of_range[0], {10.0, 0.0, 0.0});  // +Inf: free up to range_max
  expectNear(readings.out_of_range[1], {0.0, 10.0, 0.0});  // beyond range_max: same

  readings = convert(scan, 4.0, skipped);  // ~max_range shorter than range_max
  ASSERT_EQ(readings.out_of_range.size(), 2u);
  expectNear(readings.out_of_range[0], {4.0, 0.0, 0.0});
  expectNear(readings.out_of_range[1], {0.0, 4.0, 0.0});
}

TEST(LaserScanToScan, NaNNegativeInfinityAndTooShortRangesAreSkippedAndCounted) {
  std::size_t skipped = 0;
  const mvog::Scan readings = convert(fourBeamScan({kNaN, -kInf, 0.4f, 3.0f}), kInf, skipped);
  EXPECT_EQ(skipped, 3u);
  EXPECT_TRUE(readings.out_of_range.empty());
  ASSERT_EQ(readings.hits.size(), 1u);
  expectNear(readings.hits[0], {0.0, -3.0, 0.0});
}

TEST(LaserScanToScan, AppliesTheSensorPoseAndStartsRaysAtTheSensor) {
  std::size_t skipped = 0;
  const mvog::Scan readings = laserScanToScan(fourBeamScan({1.0f, 2.0f, kNaN, kInf}), sensorPose(),
                                              kInf, kManyPoints, skipped);
  EXPECT_TRUE(readings.origin.isApprox(Eigen::Vector3d(1.0, 2.0, 3.0)));
  ASSERT_EQ(readings.hits.size(), 2u);
  expectNear(readings.hits[0], {1.0, 3.0, 3.0});   // sensor x = map y
  expectNear(readings.hits[1], {-1.0, 2.0, 3.0});  // sensor y = map -x
  ASSERT_EQ(readings.out_of_range.size(), 1u);
  expectNear(readings.out_of_range[0], {11.0, 2.0, 3.0});  // sensor -y = map x
}

TEST(LaserScanToScan, ALevelLasersReadingsLieAtItsHeightExactly) {
  // A level laser 0.3 m up (not a float), turned about z: every reading at the origin's height,
  // bit for bit (the map then inserts the scan as a level one), within a float's step of 0.3 m.
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translate(Eigen::Vector3d(1.25, -2.0, 0.3));
  pose.rotate(Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ())));
  std::size_t skipped = 0;
  const mvog::Scan readings =
      laserScanToScan(fourBeamScan({1.3f, 2.7f, 9.9f, kInf}), pose, kInf, kManyPoints, skipped);
  EXPECT_NEAR(readings.origin.z(), 0.3, 1e-7);
  EXPECT_EQ(readings.origin.x(), 1.25);
  ASSERT_EQ(readings.hits.size(), 3u);
  ASSERT_EQ(readings.out_of_range.size(), 1u);
  for (const Eigen::Vector3f& hit : readings.hits) EXPECT_EQ(hit.z(), readings.origin.z());
  EXPECT_EQ(readings.out_of_range[0].z(), readings.origin.z());
}

TEST(LaserScanToScan, AcceptsOneBeamWithoutIncrement) {
  sensor_msgs::LaserScan scan = fourBeamScan({2.0f});
  scan.angle_increment = 0.0f;
  std::size_t skipped = 0;
  const mvog::Scan readings = convert(scan, kInf, skipped);
  ASSERT_EQ(readings.hits.size(), 1u);
  expectNear(readings.hits[0], {2.0, 0.0, 0.0});
}

void expectRefused(const sensor_msgs::LaserScan& scan, const std::string& why,
                   std::size_t max_beams = kManyPoints) {
  std::size_t skipped = 0;
  EXPECT_THROW(laserScanToScan(scan, Eigen::Isometry3d::Identity(), kInf, max_beams, skipped),
               InvalidMessage)
      << why;
}

TEST(LaserScanToScan, RefusesEveryMalformedScan) {
  const sensor_msgs::LaserScan valid = fourBeamScan({1.0f, 1.0f, 1.0f, 1.0f});
  sensor_msgs::LaserScan scan = valid;
  scan.angle_increment = 0.0f;
  expectRefused(scan, "angle_increment 0 with several beams");
  scan.angle_increment = kNaN;
  expectRefused(scan, "angle_increment NaN");
  scan.angle_increment = kInf;
  expectRefused(scan, "angle_increment Inf");
  scan = valid;
  scan.angle_min = kNaN;
  expectRefused(scan, "angle_min NaN");
  scan = valid;
  scan.range_min = 20.0f;
  expectRefused(scan, "range_min > range_max");
  scan.range_min = scan.range_max;
  expectRefused(scan, "range_min = range_max");
  scan = valid;
  scan.range_min = kNaN;
  expectRefused(scan, "range_min NaN");
  scan = valid;
  scan.range_max = kNaN;
  expectRefused(scan, "range_max NaN");
  scan = valid;
  scan.range_max = kInf;
  expectRefused(scan, "range_max Inf");
  scan = valid;
  scan.range_min = -1.0f;
  expectRefused(scan, "range_min < 0");
  scan = valid;
  scan.ranges.clear();
  expectRefused(scan, "no beams");
  expectRefused(valid, "more beams than the maximum", 3);
  std::size_t skipped = 0;
  EXPECT_NO_THROW(laserScanToScan(valid, Eigen::Isometry3d::Identity(), kInf, 4, skipped));
}

// ---- PointCloud2 -----------------------------------------------------------------------------

struct FieldLayout {
  std::string name;
  std::uint32_t offset;
  std::uint8_t datatype;
};

void appendBytes(std::vector<std::uint8_t>& data, std::size_t at, const void* value,
                 std::size_t size, bool big_endian) {
  const auto* bytes = static_cast<const std::uint8_t*>(value);
  for (std::size_t k = 0; k < size; ++k) data[at + k] = bytes[big_endian ? size - 1 - k : k];
}

/// A cloud of `points` laid out as `fields` in points of `point_step` bytes, `width` points per
/// row and `row_padding` spare bytes at the end of every row. Bytes not covered are 0xAB.
sensor_msgs::PointCloud2 makeCloud(const std::vector<Eigen::Vector3d>& points,
                                   const std::vector<FieldLayout>& fields, std::uint32_t point_step,
                                   std::uint32_t width, std::uint32_t row_padding = 0,
                                   bool big_endian = false) {
  sensor_msgs::PointCloud2 cloud;
  cloud.width = width;
  cloud.height = static_cast<std::uint32_t>(points.size()) / width;
  cloud.point_step = point_step;
  cloud.row_step = point_step * width + row_padding;
  cloud.is_bigendian = big_endian;
  cloud.is_dense = false;
  for (const FieldLayout& layout : fields) {
    sensor_msgs::PointField field;
    field.name = layout.name;
    field.offset = layout.offset;
    field.datatype = layout.datatype;
    field.count = 1;
    cloud.fields.push_back(field);
  }
  cloud.data.assign(std::size_t{cloud.row_step} * cloud.height, 0xAB);
  for (std::size_t k = 0; k < points.size(); ++k) {
    const std::size_t start = (k / width) * cloud.row_step + (k % width) * point_step;
    for (const FieldLayout& layout : fields) {
      const int axis = layout.name[0] - 'x';
      if (layout.name.size() != 1 || axis < 0 || axis > 2) continue;
      if (layout.datatype == sensor_msgs::PointField::FLOAT64) {
        const double value = points[k][axis];
        appendBytes(cloud.data, start + layout.offset, &value, 8, big_endian);
      } else {
        const auto value = static_cast<float>(points[k][axis]);
        appendBytes(cloud.data, start + layout.offset, &value, 4, big_endian);
      }
    }
  }
  return cloud;
}

const std::vector<FieldLayout> kXyzFloat32 = {{"x", 0, sensor_msgs::PointField::FLOAT32},
                                              {"y", 4, sensor_msgs::PointField::FLOAT32},
                                              {"z", 8, sensor_msgs::PointField::FLOAT32}};

std::vector<Eigen::Vector3d> samplePoints() {
  return {{1.0, 2.0, 3.0},     {-4.5, 0.25, 7.0},  {0.0, -1.5, 2.5},
          {10.0, 11.0, -12.0}, {0.125, 0.5, 0.75}, {-3.0, -2.0, -1.0}};
}

void expectPoints(const sensor_msgs::PointCloud2& cloud,
                  const std::vector<Eigen::Vector3d>& points) {
  const mvog::Scan readings = pointCloudToScan(cloud, Eigen::Isometry3d::Identity(), kManyPoints);
  EXPECT_TRUE(readings.out_of_range.empty());
  ASSERT_EQ(readings.hits.size(), points.size());
  for (std::size_t k = 0; k < points.size(); ++k) expectNear(readings.hits[k], points[k]);
}

TEST(PointCloudToScan, ReadsPackedFloat32Points) {
  const std::vector<Eigen::Vector3d> points = samplePoints();
  expectPoints(makeCloud(points, kXyzFloat32, 12, 6), points);
}

TEST(PointCloudToScan, ReadsFloat64Fields) {
  const std::vector<Eigen::Vector3d> points = samplePoints();
  expectPoints(makeCloud(points,
                         {{"x", 0, sensor_msgs::PointField::FLOAT64},
                          {"y", 8, sensor_msgs::PointField::FLOAT64},
                          {"z", 16, sensor_msgs::PointField::FLOAT64}},
                         24, 6),
               points);
}

TEST(PointCloudToScan, ReadsOrganizedCloudsWithRowPadding) {
  const std::vector<Eigen::Vector3d> points = samplePoints();
  expectPoints(makeCloud(points, kXyzFloat32, 12, 3, 5), points);  // 2 rows of 3, 5 spare bytes
  expectPoints(makeCloud(points, kXyzFloat32, 12, 2), points);     // 3 rows of 2
}

TEST(PointCloudToScan, ReadsOddOffsetsMixedTypesAndOtherFields) {
  // z before x, unaligned offsets, an rgb and an intensity field around them, padding at the end.
  const std::vector<Eigen::Vector3d> points = samplePoints();
  expectPoints(makeCloud(points,
                         {{"rgb", 0, sensor_msgs::PointField::FLOAT32},
                          {"z", 5, sensor_msgs::PointField::FLOAT32},
                          {"intensity", 9, sensor_msgs::PointField::UINT16},
                          {"x", 11, sensor_msgs::PointField::FLOAT64},
                          {"y", 19, sensor_msgs::PointField::FLOAT32}},
                         29, 3, 1),
               points);
}

TEST(PointCloudToScan, ReadsBigEndianData) {
  const std::vector<Eigen::Vector3d> points = samplePoints();
  expectPoints(makeCloud(points, kXyzFloat32, 12, 6, 0, true), points);
  expectPoints(makeCloud(points,
                         {{"x", 16, sensor_msgs::PointField::FLOAT64},
                          {"y", 0, sensor_msgs::PointField::FLOAT32},
                          {"z", 4, sensor_msgs::PointField::FLOAT64}},
                         24, 2, 3, true),
               points);
}

TEST(PointCloudToScan, PassesNaNPointsOnForTheMapToCount) {
  const std::vector<Eigen::Vector3d> points = {
      {1.0, 2.0, 3.0}, {std::nan(""), 0.0, 0.0}, {0.0, 0.0, std::nan("")}, {4.0, 5.0, 6.0}};
  const mvog::Scan readings =
      pointCloudToScan(makeCloud(points, kXyzFloat32, 12, 2), Eigen::Isometry3d::Identity(), 10);
  ASSERT_EQ(readings.hits.size(), 4u);
  expectNear(readings.hits[0], points[0]);
  EXPECT_TRUE(std::isnan(readings.hits[1].x()));
  EXPECT_TRUE(std::isnan(readings.hits[2].z()));
  expectNear(readings.hits[3], points[3]);
}

TEST(PointCloudToScan, AppliesTheSensorPoseAndStartsRaysAtTheSensor) {
  const mvog::Scan readings = pointCloudToScan(
      makeCloud({{1.0, 0.0, 0.0}, {0.0, 1.0, 0.5}}, kXyzFloat32, 12, 2), sensorPose(), kManyPoints);
  EXPECT_TRUE(readings.origin.isApprox(Eigen::Vector3d(1.0, 2.0, 3.0)));
  ASSERT_EQ(readings.hits.size(), 2u);
  expectNear(readings.hits[0], {1.0, 3.0, 3.0});
  expectNear(readings.hits[1], {0.0, 2.0, 3.5});
}

TEST(PointCloudToScan, AcceptsAnEmptyCloud) {
  sensor_msgs::PointCloud2 cloud = makeCloud({}, kXyzFloat32, 12, 1);  // height 0
  EXPECT_TRUE(pointCloudToScan(cloud, Eigen::Isometry3d::Identity(), 10).hits.empty());
  cloud.width = 0;
  cloud.height = 5;  // rows without points, and no data
  cloud.row_step = 0;
  EXPECT_TRUE(pointCloudToScan(cloud, Eigen::Isometry3d::Identity(), 10).hits.empty());
}

void expectRefused(const sensor_msgs::PointCloud2& cloud, const std::string& why,
                   std::size_t max_points = kManyPoints) {
  EXPECT_THROW(pointCloudToScan(cloud, Eigen::Isometry3d::Identity(), max_points), InvalidMessage)
      << why;
}

TEST(PointCloudToScan, RefusesEveryMalformedCloud) {
  const sensor_msgs::PointCloud2 valid = makeCloud(samplePoints(), kXyzFloat32, 12, 3);
  sensor_msgs::PointCloud2 cloud = valid;
  cloud.data.pop_back();
  expectRefused(cloud, "data one byte short");
  cloud = valid;
  cloud.row_step = 35;  // shorter than width * point_step
  expectRefused(cloud, "row_step below width * point_step");
  cloud = valid;
  cloud.height = 3;
  expectRefused(cloud, "more rows than data");
  cloud = valid;
  cloud.width = 4;
  expectRefused(cloud, "more columns than row_step");

  for (const char* name : {"x", "y", "z"}) {
    cloud = valid;
    for (sensor_msgs::PointField& field : cloud.fields) {
      if (field.name == name) field.name = "w";
    }
    expectRefused(cloud, std::string("no ") + name);
  }
  using Field = sensor_msgs::PointField;
  for (int datatype : std::vector<int>{Field::INT8, Field::UINT8, Field::INT16, Field::UINT16,
                                       Field::INT32, Field::UINT32, 0, 42}) {
    cloud = valid;
    cloud.fields[1].datatype = static_cast<std::uint8_t>(datatype);
    expectRefused(cloud, "y of datatype " + std::to_string(datatype));
  }
  cloud = valid;
  cloud.fields[2].offset = 9;  // float32 z over bytes 9..12 of a 12-byte point
  expectRefused(cloud, "z beyond point_step");
  cloud = valid;
  cloud.fields[0].datatype = sensor_msgs::PointField::FLOAT64;  // x over bytes 0..7 is fine...
  EXPECT_NO_THROW(pointCloudToScan(cloud, Eigen::Isometry3d::Identity(), kManyPoints));
  cloud.fields[0].offset = 5;  // ...but not over 5..12
  expectRefused(cloud, "float64 x beyond point_step");
  cloud = valid;
  cloud.fields[0].offset = 0xFFFFFFFFu;
  expectRefused(cloud, "offset overflowing 32 bits");

  cloud = valid;
  cloud.width = 0xFFFFFFFFu;
  cloud.height = 0xFFFFFFFFu;
  expectRefused(cloud, "absurd width and height");
  cloud.width = 1u << 20;
  cloud.height = 1u << 20;
  cloud.row_step = 12u << 20;
  expectRefused(cloud, "2^40 points with short data", std::size_t{1} << 41);
  expectRefused(valid, "more points than the maximum", 5);
  EXPECT_NO_THROW(pointCloudToScan(valid, Eigen::Isometry3d::Identity(), 6));
}

// ---- Depth images: a scene seen by a depth camera --------------------------------------------

/// A 6 m x 5 m x 3 m room with a box and a sphere in it. No wall lies on a cell's border (as
/// in a real room): there, a hit would change cells on the least difference of its position.
mvog_scene::Scene roomScene() {
  mvog_scene::Scene scene;
  scene.boxes = mvog_scene::roomWalls({-0.0123, -0.0231, 0.0}, {6.0177, 5.0119, 3.0}, 0.2);
  scene.boxes.push_back({{3.0137, 1.0271, 0.0}, {3.6213, 1.8169, 0.9}});
  scene.spheres.push_back({{2.0, 3.5, 1.2}, 0.5});
  return scene;
}

/// A 160 x 120 camera (about 62 x 49 degrees), its principal point off the centre.
sensor_msgs::CameraInfo cameraInfo() {
  sensor_msgs::CameraInfo info;
  info.header.frame_id = "camera";
  info.width = 160;
  info.height = 120;
  info.K = {130.0, 0.0, 79.25, 0.0, 131.5, 60.75, 0.0, 0.0, 1.0};
  return info;
}

/// The camera's optical frame (x right, y down, z forward) at `position`, looking along `yaw`
/// about the map's z and down by `tilt`.
Eigen::Isometry3d cameraPose(const Eigen::Vector3d& position, double yaw, double tilt) {
  const Eigen::Matrix3d optical_axes =
      (Eigen::Matrix3d() << 0.0, 0.0, 1.0, -1.0, 0.0, 0.0, 0.0, -1.0, 0.0).finished();
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translate(position);
  pose.rotate(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
              Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitY()) * optical_axes);
  return pose;
}

std::vector<Eigen::Isometry3d> cameraPoses() {
  return {cameraPose({1.0, 1.0, 1.5}, 0.6, 0.2), cameraPose({5.0, 4.0, 2.0}, -2.4, 0.4),
          cameraPose({1.5, 4.2, 1.0}, -0.9, -0.1)};
}

/// The depth (m, along the optical axis) of each pixel's first surface in `scene`, row after
/// row; every 97th pixel has no measurement (NaN).
std::vector<double> trueDepths(const mvog_scene::Scene& scene, const sensor_msgs::CameraInfo& info,
                               const Eigen::Isometry3d& map_from_camera) {
  std::vector<double> depths;
  for (std::uint32_t v = 0; v < info.height; ++v) {
    for (std::uint32_t u = 0; u < info.width; ++u) {
      const Eigen::Vector3d ray((u - info.K[2]) / info.K[0], (v - info.K[5]) / info.K[4], 1.0);
      const double range = scene.castRay(map_from_camera.translation(),
                                         (map_from_camera.linear() * ray).normalized());
      depths.push_back(depths.size() % 97 == 5 ? std::nan("") : range / ray.norm());
    }
  }
  return depths;
}

/// `depths` as a depth image: 16UC1 (rounded to millimetres, 0 where NaN) or 32FC1, every row
/// padded with `padding` bytes.
sensor_msgs::Image depthImage(const std::vector<double>& depths,
                              const sensor_msgs::CameraInfo& info, const std::string& encoding,
                              std::uint32_t padding = 0) {
  sensor_msgs::Image image;
  image.header.frame_id = "camera";
  image.width = info.width;
  image.height = info.height;
  image.encoding = encoding;
  const std::uint32_t pixel_bytes = encoding == "16UC1" ? 2 : 4;
  image.step = image.width * pixel_bytes + padding;
  image.data.assign(std::size_t{image.step} * image.height, 0xAB);
  for (std::size_t k = 0; k < depths.size(); ++k) {
    std::uint8_t* at =
        image.data.data() + (k / image.width) * image.step + (k % image.width) * pixel_bytes;
    if (pixel_bytes == 2) {
      const auto millimetres =
          static_cast<std::uint16_t>(std::isnan(depths[k]) ? 0 : std::lround(1000.0 * depths[k]));
      std::memcpy(at, &millimetres, 2);
    } else {
      const auto metres = static_cast<float>(depths[k]);
      std::memcpy(at, &metres, 4);
    }
  }
  return image;
}

/// The cloud depth_image_proc's point_cloud_xyz nodelet (ROS 1) makes of a depth image: its
/// convert() step by step, NaN where a pixel says nothing.
sensor_msgs::PointCloud2 depthImageProcCloud(const sensor_msgs::Image& image,
                                             const sensor_msgs::CameraInfo& info) {
  const bool millimetres = image.encoding == "16UC1";
  const auto center_x = static_cast<float>(info.K[2]);
  const auto center_y = static_cast<float>(info.K[5]);
  const double unit_scaling = millimetres ? double{1 * 0.001f} : 1.0;  // toMeters(T(1))
  const auto constant_x = static_cast<float>(unit_scaling / info.K[0]);
  const auto constant_y = static_cast<float>(unit_scaling / info.K[4]);
  std::vector<Eigen::Vector3d> points;  // floats, exactly
  for (std::uint32_t v = 0; v < image.height; ++v) {
    for (std::uint32_t u = 0; u < image.width; ++u) {
      const std::uint8_t* at = image.data.data() + v * image.step + u * (millimetres ? 2 : 4);
      float depth = 0.0f;
      float metres = 0.0f;
      bool valid = false;
      if (millimetres) {
        std::uint16_t raw = 0;
        std::memcpy(&raw, at, 2);
        valid = raw != 0;
        depth = raw;
        metres = raw * 0.001f;
      } else {
        std::memcpy(&depth, at, 4);
        valid = std::isfinite(depth);
        metres = depth;
      }
      if (!valid) {
        points.emplace_back(kNaN, kNaN, kNaN);
        continue;
      }
      // (u - center_x): depth_image_proc's int u, converted to float.
      points.emplace_back((static_cast<float>(u) - center_x) * depth * constant_x,
                          (static_cast<float>(v) - center_y) * depth * constant_y, metres);
    }
  }
  return makeCloud(points, kXyzFloat32, 12, info.width);
}

/// The cloud of the true surface points, rounded to float, NaN where a pixel has no measurement.
sensor_msgs::PointCloud2 trueCloud(const std::vector<double>& depths,
                                   const sensor_msgs::CameraInfo& info) {
  std::vector<Eigen::Vector3d> points;
  for (std::size_t k = 0; k < depths.size(); ++k) {
    const double u = static_cast<double>(k % info.width);
    const double v = static_cast<double>(k / info.width);
    const Eigen::Vector3d ray((u - info.K[2]) / info.K[0], (v - info.K[5]) / info.K[4], 1.0);
    points.push_back(ray * depths[k]);
  }
  return makeCloud(points, kXyzFloat32, 12, info.width);
}

mvog::Map emptyMap() {
  mvog::MapConfig config;
  config.resolution = 0.05;
  return mvog::Map(config);
}

mvog::InsertionConfig insertionConfig() {
  mvog::InsertionConfig config;
  config.max_range = 10.0;
  return config;
}

mvog::Scan imageScan(const sensor_msgs::Image& image, const sensor_msgs::CameraInfo& info,
                     const Eigen::Isometry3d& pose, std::size_t& skipped) {
  return depthImageToScan(image, info, pose, mvog::DepthImageConfig{}, kManyPoints, skipped);
}

/// The map of the scene from every camera pose: each view as a depth image of `encoding`, or
/// as the cloud `to_cloud` makes of it.
template <class ToCloud>
void mapTheScene(const std::string& encoding, mvog::Map& from_images, mvog::Map& from_clouds,
                 ToCloud&& to_cloud) {
  const mvog_scene::Scene scene = roomScene();
  const sensor_msgs::CameraInfo info = cameraInfo();
  for (const Eigen::Isometry3d& pose : cameraPoses()) {
    const std::vector<double> depths = trueDepths(scene, info, pose);
    const sensor_msgs::Image image = depthImage(depths, info, encoding, 6);
    std::size_t skipped = 0;
    const mvog::Scan from_image = imageScan(image, info, pose, skipped);
    EXPECT_EQ(skipped, (depths.size() + 91) / 97) << "the pixels without a measurement";
    const mvog::InsertionResult image_result =
        from_images.insertScan(from_image, insertionConfig());
    EXPECT_EQ(image_result.inserted(), depths.size() - skipped);
    const mvog::Scan from_cloud =
        pointCloudToScan(to_cloud(image, depths, info), pose, kManyPoints);
    from_clouds.insertScan(from_cloud, insertionConfig());
  }
}

TEST(DepthImageToScan, MapsTheSameBitForBitAsTheCloudDepthImageProcMakesOfTheImage) {
  for (const std::string encoding : {"16UC1", "32FC1"}) {
    SCOPED_TRACE(encoding);
    mvog::Map from_images = emptyMap();
    mvog::Map from_clouds = emptyMap();
    mapTheScene(
        encoding, from_images, from_clouds,
        [](const sensor_msgs::Image& image, const std::vector<double>&,
           const sensor_msgs::CameraInfo& info) { return depthImageProcCloud(image, info); });
    EXPECT_GT(from_images.memoryUsage().positive_volumes, 1000u);
    EXPECT_EQ(mvog::serializeMap(from_images), mvog::serializeMap(from_clouds));
  }
}

TEST(DepthImageToScan, MapsWhatTheTrueCloudMapsAtAllButATenthOfAPercentOfSampledPoints) {
  // The true surface points are not exactly representable in the image (millimetres, or the
  // float depth and back-projection), so the maps differ a little where a hit moved to another
  // cell. Sampled: points all over the room, and the surface itself.
  const mvog_scene::Scene scene = roomScene();
  for (const std::string encoding : {"16UC1", "32FC1"}) {
    SCOPED_TRACE(encoding);
    mvog::Map from_images = emptyMap();
    mvog::Map from_clouds = emptyMap();
    mapTheScene(encoding, from_images, from_clouds,
                [](const sensor_msgs::Image&, const std::vector<double>& depths,
                   const sensor_msgs::CameraInfo& info) { return trueCloud(depths, info); });
    std::mt19937 random(7);
    std::uniform_real_distribution<double> x(-0.2, 6.2), y(-0.2, 5.2), z(-0.2, 3.2);
    std::vector<Eigen::Vector3d> samples;
    constexpr std::size_t kUniformSamples = 200000;
    for (std::size_t k = 0; k < kUniformSamples; ++k) {
      samples.emplace_back(x(random), y(random), z(random));
    }
    const mvog::Scan surface =
        pointCloudToScan(trueCloud(trueDepths(scene, cameraInfo(), cameraPoses()[0]), cameraInfo()),
                         cameraPoses()[0], kManyPoints);
    std::size_t surface_points = 0;
    for (const Eigen::Vector3f& hit : surface.hits) {
      if (hit.allFinite()) samples.push_back(hit.cast<double>());
      surface_points += hit.allFinite() ? 1 : 0;
    }
    auto state = [](const mvog::Map& map, const Eigen::Vector3d& p) {
      return map.occupancy(p).state(mvog::kDefaultOccupancyThreshold);
    };
    // Agreement of the occupancy state (occupied, free, unknown) over the samples [first, last).
    auto agreement = [&](std::size_t first, std::size_t last) {
      std::size_t agree = 0;
      for (std::size_t k = first; k < last; ++k) {
        agree += state(from_images, samples[k]) == state(from_clouds, samples[k]) ? 1 : 0;
      }
      return static_cast<double>(agree) / static_cast<double>(last - first);
    };
    EXPECT_GE(agreement(0, kUniformSamples), 0.999) << "all over the room";
    EXPECT_GE(agreement(kUniformSamples, samples.size()), 0.999) << "on the surface";
    EXPECT_GT(surface_points, 10000u);
    std::size_t occupied = 0;
    for (std::size_t k = kUniformSamples; k < samples.size(); ++k) {
      occupied += state(from_images, samples[k]) == mvog::OccupancyState::kOccupied ? 1 : 0;
    }
    EXPECT_GT(occupied, surface_points / 2) << "the surface is mapped occupied";
  }
}

// ---- Depth images: the messages -------------------------------------------------------------

/// A 4 x 2 camera: fx = 2, fy = 4, cx = 1.5, cy = 0.5.
sensor_msgs::CameraInfo smallCameraInfo() {
  sensor_msgs::CameraInfo info;
  info.width = 4;
  info.height = 2;
  info.K = {2.0, 0.0, 1.5, 0.0, 4.0, 0.5, 0.0, 0.0, 1.0};
  return info;
}

TEST(DepthImageToScan, FollowsRep118In32FC1) {
  const sensor_msgs::CameraInfo info = smallCameraInfo();
  // Row 0: a hit, 0, NaN, -Inf; row 1: +Inf, a hit, a negative depth, +Inf.
  const sensor_msgs::Image image =
      depthImage({2.0, 0.0, kNaN, -kInf, kInf, 3.0, -1.0, kInf}, info, "32FC1");
  mvog::DepthImageConfig config;
  config.no_return_length = 6.0;
  std::size_t skipped = 0;
  const mvog::Scan scan =
      depthImageToScan(image, info, Eigen::Isometry3d::Identity(), config, kManyPoints, skipped);
  EXPECT_EQ(skipped, 4u);
  ASSERT_EQ(scan.hits.size(), 2u);
  EXPECT_EQ(scan.hits[0], Eigen::Vector3f(-1.5f, -0.25f, 2.0f));
  EXPECT_EQ(scan.hits[1], Eigen::Vector3f(-0.75f, 0.375f, 3.0f));
  ASSERT_EQ(scan.out_of_range.size(), 2u);
  EXPECT_NEAR(scan.out_of_range[0].norm(), 6.0, 1e-5);  // free up to the no-return length
  EXPECT_NEAR(scan.out_of_range[1].norm(), 6.0, 1e-5);
  EXPECT_LT(scan.out_of_range[0].x(), 0.0f);  // pixel u = 0 looks left
  EXPECT_GT(scan.out_of_range[1].x(), 0.0f);  // pixel u = 3 right
}

TEST(DepthImageToScan, ReadsMillimetresWithRowPaddingAndStride) {
  sensor_msgs::CameraInfo info = smallCameraInfo();
  const sensor_msgs::Image image =
      depthImage({1.0, 0.0, 2.0, 4.0, 1.5, 1.5, 0.0, 1.5}, info, "16UC1", 3);
  std::size_t skipped = 0;
  mvog::Scan scan = imageScan(image, info, Eigen::Isometry3d::Identity(), skipped);
  EXPECT_EQ(skipped, 2u);
  ASSERT_EQ(scan.hits.size(), 6u);
  EXPECT_TRUE(scan.hits[0].isApprox(Eigen::Vector3f(-0.75f, -0.125f, 1.0f)));
  EXPECT_TRUE(scan.hits[5].isApprox(Eigen::Vector3f(1.125f, 0.1875f, 1.5f)));
  mvog::DepthImageConfig every_other;
  every_other.stride = 2;  // (0, 0) and (2, 0)
  scan = depthImageToScan(image, info, Eigen::Isometry3d::Identity(), every_other, kManyPoints,
                          skipped);
  EXPECT_EQ(skipped, 0u);
  ASSERT_EQ(scan.hits.size(), 2u);
  EXPECT_FLOAT_EQ(scan.hits[1].z(), 2.0f);
}

TEST(DepthImageToScan, StartsRaysAtTheOpticalFrameAndAppliesItsPose) {
  const Eigen::Isometry3d pose = cameraPose({1.0, 2.0, 3.0}, 0.0, 0.0);  // looking along map x
  const sensor_msgs::CameraInfo info = smallCameraInfo();
  const sensor_msgs::Image image =
      depthImage({0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 8.0}, info, "32FC1");
  std::size_t skipped = 0;
  const mvog::Scan scan = imageScan(image, info, pose, skipped);
  EXPECT_TRUE(scan.origin.isApprox(Eigen::Vector3d(1.0, 2.0, 3.0)));
  ASSERT_EQ(scan.hits.size(), 1u);
  // (6, 1, 8) in the optical frame: 8 m ahead, 6 m right (map -y), 1 m down.
  EXPECT_TRUE(scan.hits[0].isApprox(Eigen::Vector3f(9.0f, -4.0f, 2.0f)));
}

void expectRefused(const sensor_msgs::Image& image, const sensor_msgs::CameraInfo& info,
                   const std::string& why, const std::string& named,
                   std::size_t max_points = kManyPoints) {
  std::size_t skipped = 0;
  try {
    depthImageToScan(image, info, Eigen::Isometry3d::Identity(), mvog::DepthImageConfig{},
                     max_points, skipped);
    ADD_FAILURE() << why << ": accepted";
  } catch (const InvalidMessage& e) {
    EXPECT_NE(std::string(e.what()).find(named), std::string::npos) << why << ": " << e.what();
  }
}

TEST(DepthImageToScan, RefusesEveryImageAndCameraInfoItCannotUseSayingWhy) {
  const sensor_msgs::CameraInfo info = smallCameraInfo();
  const sensor_msgs::Image valid = depthImage(std::vector<double>(8, 1.0), info, "16UC1");
  for (const char* encoding : {"mono16", "16SC1", "32FC2", "64FC1", "rgb8", "bgra8", ""}) {
    sensor_msgs::Image image = valid;
    image.encoding = encoding;
    expectRefused(image, info, std::string("encoding ") + encoding,
                  std::string("encoding '") + encoding + "'");
  }
  sensor_msgs::Image image = valid;
  image.is_bigendian = 1;
  expectRefused(image, info, "big-endian 16-bit", "big-endian");
  image = depthImage(std::vector<double>(8, 1.0), info, "32FC1");
  image.is_bigendian = 1;
  expectRefused(image, info, "big-endian float", "big-endian");
  image = valid;
  image.step = 7;  // 4 pixels of 2 bytes
  expectRefused(image, info, "step below width x bytes", "step");
  image = valid;
  image.data.pop_back();
  expectRefused(image, info, "data shorter than height x step", "size");
  image = valid;
  image.step = 0xFFFFFFFFu;
  expectRefused(image, info, "absurd step", "size");

  sensor_msgs::CameraInfo bad_info = info;
  bad_info.K = {};
  expectRefused(valid, bad_info, "K zero", "K: fx");
  bad_info = info;
  bad_info.K[4] = std::nan("");
  expectRefused(valid, bad_info, "fy NaN", "K: fy");
  bad_info = info;
  bad_info.K[2] = std::numeric_limits<double>::infinity();
  expectRefused(valid, bad_info, "cx infinite", "K: cx");
  bad_info = info;
  bad_info.width = 8;
  expectRefused(valid, bad_info, "camera info of another width", "8x2");
  bad_info = info;
  bad_info.height = 1;
  expectRefused(valid, bad_info, "camera info of another height", "4x1");

  expectRefused(valid, info, "more pixels than the maximum", "~max_points_per_message", 7);
  std::size_t skipped = 0;
  EXPECT_NO_THROW(depthImageToScan(valid, info, Eigen::Isometry3d::Identity(),
                                   mvog::DepthImageConfig{}, 8, skipped));
  mvog::DepthImageConfig every_other;
  every_other.stride = 2;  // 2 of the 8 pixels
  EXPECT_NO_THROW(
      depthImageToScan(valid, info, Eigen::Isometry3d::Identity(), every_other, 2, skipped));
}

TEST(DepthImageToScan, TakesAnEmptyImage) {
  sensor_msgs::CameraInfo info = smallCameraInfo();
  info.width = 0;
  info.height = 0;
  sensor_msgs::Image image;
  image.encoding = "32FC1";
  std::size_t skipped = 0;
  EXPECT_TRUE(imageScan(image, info, Eigen::Isometry3d::Identity(), skipped).hits.empty());
}

// ---- Voxel filter ----------------------------------------------------------------------------

TEST(VoxelFilter, KeepsOneCentroidPerVoxelAndCountsTheNonFinitePointsItDrops) {
  std::vector<Eigen::Vector3f> points = {{0.01f, 0.01f, 0.01f},
                                         {0.03f, 0.05f, 0.07f},
                                         {kNaN, 0.0f, 0.0f},
                                         {2.05f, 0.05f, 0.05f},
                                         {0.0f, kInf, 0.0f}};
  EXPECT_EQ(voxelFilter(points, 0.1), 2u);
  ASSERT_EQ(points.size(), 2u);
  std::sort(points.begin(), points.end(),
            [](const Eigen::Vector3f& a, const Eigen::Vector3f& b) { return a.x() < b.x(); });
  expectNear(points[0], {0.02, 0.03, 0.04});
  expectNear(points[1], {2.05, 0.05, 0.05});
}

}  // namespace
}  // namespace mvog_ros
