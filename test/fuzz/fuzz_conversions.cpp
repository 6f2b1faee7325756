// libFuzzer target: the message conversions of the ROS layer (mvog_ros/conversions.h) on
// LaserScan, PointCloud2 and depth Image (with CameraInfo) messages built from arbitrary bytes,
// then insertion of what they yield into a map.
//
// Whatever the message, laserScanToScan / pointCloudToScan / depthImageToScan return a Scan or
// throw InvalidMessage: no crash, no undefined behaviour, no allocation beyond what the message
// holds.
// Readings that come out go into an mvog::Map, which must count every one of them exactly once.
//
// Input layout (little-endian, read from the front; missing bytes read as zero), also written by
// test/fuzz/make_seeds.py:
//   u8  kind            bits 0-1: 0 LaserScan, 1 PointCloud2, 2 or 3 depth image
//   u8  options         bit 0: insert the readings into a map, bit 1: the paper's model (else the
//                       default rules),
//                       bit 2: no negative space, bit 3: two insertion threads
//   f32 x, y, z, roll, pitch, yaw      sensor pose (non-finite -> 0, translation clamped to 40 m)
//   LaserScan:   f32 angle_min, angle_max, angle_increment, range_min, range_max, max_free_range,
//                u32 beams (at most 8192; missing ranges repeat the last one), u16 intensities,
//                then the ranges (f32 each)
//   PointCloud2: u8 is_bigendian, u32 height, width, point_step, row_step, u8 fields (at most 8),
//                each: u8 name (x y z rgb intensity xx), u32 offset, u8 datatype, u32 count;
//                the rest is the data
//   depth image: u8 encoding (16UC1 32FC1 mono16 32FC2 rgb8), u8 is_bigendian, u32 width,
//                height, step, camera info u32 width, height, f64 fx, fy, cx, cy, u8 stride
//                (1 + its value % 8), f32 no_return_length (not > 0: infinite); the rest is the
//                data
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "mvog_ros/conversions.h"

namespace {

constexpr std::size_t kMaxPoints = 4096;  // ~max_points_per_message of this harness
constexpr double kMaxTranslation = 40.0;

class Input {
 public:
  Input(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  template <class T>
  T take() {
    T value{};
    if (at_ + sizeof(T) <= size_) {
      std::memcpy(&value, data_ + at_, sizeof(T));
      at_ += sizeof(T);
    } else {
      at_ = size_;
    }
    return value;
  }
  std::size_t remaining() const { return size_ - at_; }
  std::vector<std::uint8_t> rest() {
    std::vector<std::uint8_t> bytes(data_ + at_, data_ + size_);
    at_ = size_;
    return bytes;
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t at_ = 0;
};

void check(bool condition) {
  if (!condition) std::abort();
}

/// MVOG_FUZZ_VERBOSE=1 prints what became of each input (to check a seed does what it says).
bool verbose() {
  static const bool value = std::getenv("MVOG_FUZZ_VERBOSE") != nullptr;
  return value;
}

double finiteOrZero(float value) { return std::isfinite(value) ? value : 0.0; }

Eigen::Isometry3d takePose(Input& in) {
  double t[3];
  for (double& v : t) {
    v = finiteOrZero(in.take<float>());
    v = std::max(-kMaxTranslation, std::min(kMaxTranslation, v));
  }
  double angles[3];
  for (double& a : angles) a = std::fmod(finiteOrZero(in.take<float>()), 2.0 * M_PI);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translate(Eigen::Vector3d(t[0], t[1], t[2]));
  pose.rotate(Eigen::AngleAxisd(angles[2], Eigen::Vector3d::UnitZ()) *
              Eigen::AngleAxisd(angles[1], Eigen::Vector3d::UnitY()) *
              Eigen::AngleAxisd(angles[0], Eigen::Vector3d::UnitX()));
  return pose;
}

sensor_msgs::LaserScan takeScan(Input& in, double& max_free_range) {
  sensor_msgs::LaserScan scan;
  scan.header.frame_id = "laser";
  scan.angle_min = in.take<float>();
  scan.angle_max = in.take<float>();
  scan.angle_increment = in.take<float>();
  scan.range_min = in.take<float>();
  scan.range_max = in.take<float>();
  // ~max_range, validated by the server: > 0, infinity for no limit.
  const float max_range = in.take<float>();
  max_free_range = max_range > 0.0f ? max_range : std::numeric_limits<double>::infinity();
  const std::uint32_t beams = std::min<std::uint32_t>(in.take<std::uint32_t>(), 2 * kMaxPoints);
  scan.intensities.assign(in.take<std::uint16_t>(), 1.0f);
  float last = 0.0f;
  scan.ranges.reserve(beams);
  for (std::uint32_t k = 0; k < beams; ++k) {
    if (in.remaining() >= sizeof(float)) last = in.take<float>();
    scan.ranges.push_back(last);
  }
  return scan;
}

struct DepthImageMessage {
  sensor_msgs::Image image;
  sensor_msgs::CameraInfo camera_info;
  mvog::DepthImageConfig config;
};

DepthImageMessage takeDepthImage(Input& in) {
  static const char* const kEncodings[] = {"16UC1", "32FC1", "mono16", "32FC2", "rgb8"};
  DepthImageMessage message;
  sensor_msgs::Image& image = message.image;
  image.header.frame_id = "camera";
  image.encoding = kEncodings[in.take<std::uint8_t>() % 5];
  image.is_bigendian = in.take<std::uint8_t>() & 1;
  image.width = in.take<std::uint32_t>();
  image.height = in.take<std::uint32_t>();
  image.step = in.take<std::uint32_t>();
  sensor_msgs::CameraInfo& info = message.camera_info;
  info.width = in.take<std::uint32_t>();
  info.height = in.take<std::uint32_t>();
  info.K[0] = in.take<double>();
  info.K[4] = in.take<double>();
  info.K[2] = in.take<double>();
  info.K[5] = in.take<double>();
  info.K[8] = 1.0;
  message.config.stride = 1 + in.take<std::uint8_t>() % 8;
  const float no_return_length = in.take<float>();  // validated by the server: > 0 or infinite
  if (no_return_length > 0.0f) message.config.no_return_length = no_return_length;
  image.data = in.rest();
  return message;
}

sensor_msgs::PointCloud2 takeCloud(Input& in) {
  static const char* const kNames[] = {"x", "y", "z", "rgb", "intensity", "xx"};
  sensor_msgs::PointCloud2 cloud;
  cloud.header.frame_id = "camera";
  cloud.is_bigendian = in.take<std::uint8_t>() & 1;
  cloud.height = in.take<std::uint32_t>();
  cloud.width = in.take<std::uint32_t>();
  cloud.point_step = in.take<std::uint32_t>();
  cloud.row_step = in.take<std::uint32_t>();
  const unsigned fields = in.take<std::uint8_t>() % 9;
  for (unsigned k = 0; k < fields; ++k) {
    sensor_msgs::PointField field;
    field.name = kNames[in.take<std::uint8_t>() % 6];
    field.offset = in.take<std::uint32_t>();
    field.datatype = in.take<std::uint8_t>();
    field.count = in.take<std::uint32_t>();
    cloud.fields.push_back(field);
  }
  cloud.data = in.rest();
  return cloud;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Input in(data, size);
  const unsigned kind = in.take<std::uint8_t>() & 3;
  const std::uint8_t options = in.take<std::uint8_t>();
  const Eigen::Isometry3d pose = takePose(in);
  mvog::Scan readings;
  std::size_t skipped = 0;
  std::size_t message_points = 0;
  try {
    if (kind >= 2) {
      const DepthImageMessage message = takeDepthImage(in);
      readings = mvog_ros::depthImageToScan(message.image, message.camera_info, pose,
                                            message.config, kMaxPoints, skipped);
      // Refused unless every kept pixel lies within the data.
      const std::size_t pixel_bytes = message.image.encoding == "16UC1" ? 2 : 4;
      check(std::uint64_t{message.image.step} * message.image.height <= message.image.data.size());
      check(std::uint64_t{message.image.width} * pixel_bytes <= message.image.step);
      // Every kept pixel counted once: a reading, or skipped.
      const std::size_t stride = static_cast<std::size_t>(message.config.stride);
      message_points = ((message.image.width + stride - 1) / stride) *
                       ((message.image.height + stride - 1) / stride);
      check(readings.hits.size() + readings.out_of_range.size() + skipped == message_points);
    } else if (kind == 1) {
      const sensor_msgs::PointCloud2 cloud = takeCloud(in);
      readings = mvog_ros::pointCloudToScan(cloud, pose, kMaxPoints);
      message_points = std::size_t{cloud.width} * cloud.height;
      check(readings.out_of_range.empty());
      check(readings.hits.size() == message_points);
    } else {
      double max_free_range = 0.0;
      const sensor_msgs::LaserScan scan = takeScan(in, max_free_range);
      readings = mvog_ros::laserScanToScan(scan, pose, max_free_range, kMaxPoints, skipped);
      message_points = scan.ranges.size();
      check(readings.hits.size() + readings.out_of_range.size() + skipped == message_points);
    }
  } catch (const mvog_ros::InvalidMessage& e) {
    check(std::strlen(e.what()) > 0);  // refused, saying why
    if (verbose()) std::printf("  refused: %s\n", e.what());
    return 0;
  }
  if (verbose()) {
    std::printf("  %zu hits, %zu free endpoints, %zu skipped\n", readings.hits.size(),
                readings.out_of_range.size(), skipped);
  }
  check(message_points <= kMaxPoints);
  check(readings.origin.isApprox(pose.translation()));
  if ((options & 1) == 0) return 0;

  mvog::MapConfig map_config;
  map_config.resolution = 1.0;
  map_config.max_coordinate = 32.0;  // keeps the rays of a fuzz input short
  if ((options & 2) != 0) map_config.rules = mvog::ModelRules::paper();
  mvog::Map map(map_config);
  mvog::InsertionConfig insertion;
  insertion.model_negative_space = (options & 4) == 0;
  insertion.insertion_threads = (options & 8) != 0 ? 2 : 1;
  const mvog::InsertionResult result = map.insertScan(readings, insertion);
  check(result.inserted() + result.rejected() ==
        readings.hits.size() + readings.out_of_range.size());
  const mvog::MemoryUsage usage = map.memoryUsage();
  check(result.inserted() > 0 || usage.cells_with_volumes == 0);
  if (verbose()) {
    std::printf("  inserted %zu, rejected %zu, %zu cells\n", result.inserted(), result.rejected(),
                usage.cells_with_volumes);
  }
  return 0;
}
