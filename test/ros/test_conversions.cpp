// LaserScan and PointCloud2 to readings (mvog_ros/conversions.h): REP-117 semantics, every cloud
// layout, the sensor pose, and the refusal of every malformed message.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "mvog_ros/conversions.h"

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
