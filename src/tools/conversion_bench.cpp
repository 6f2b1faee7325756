// Google Benchmark of the ROS layer's conversions of a depth camera's frame (see
// BENCHMARKS.md section 11): the depth-image path (Image 16UC1 or 32FC1 with its camera
// info to readings) against the cloud path (the image back-projected into an organised
// PointCloud2, as depth_image_proc does beside the driver, then the cloud to readings), and what
// each message costs to serialise and deserialise (once per connection). One 640 x 480 frame of a
// closed room (Kinect-like intrinsics): every pixel is a hit. Counters: s_per_Mpx, the time per
// million pixels.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include <benchmark/benchmark.h>
#include <ros/serialization.h>
#include <Eigen/Geometry>

#include "mvog/depth_image.h"
#include "mvog/map.h"
#include "mvog_ros/conversions.h"
#include "mvog_scene/scene.h"

namespace {

constexpr std::uint32_t kWidth = 640;
constexpr std::uint32_t kHeight = 480;
constexpr std::size_t kPixels = std::size_t{kWidth} * kHeight;
constexpr std::size_t kNoLimit = kPixels;

sensor_msgs::CameraInfo cameraInfo() {
  sensor_msgs::CameraInfo info;
  info.header.frame_id = "camera";
  info.width = kWidth;
  info.height = kHeight;
  info.K = {525.0, 0.0, 319.5, 0.0, 525.0, 239.5, 0.0, 0.0, 1.0};
  return info;
}

/// The optical frame 1.2 m above the floor of a 10 m x 8 m x 3 m room, looking along x.
Eigen::Isometry3d cameraPose() {
  const Eigen::Matrix3d optical_axes =
      (Eigen::Matrix3d() << 0.0, 0.0, 1.0, -1.0, 0.0, 0.0, 0.0, -1.0, 0.0).finished();
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translate(Eigen::Vector3d(-2.0, 0.5, 1.2));
  pose.rotate(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()) * optical_axes);
  return pose;
}

/// The frame as a depth image of `encoding`.
sensor_msgs::Image depthImage(const std::string& encoding) {
  mvog_scene::Scene scene;
  scene.boxes = mvog_scene::roomWalls({-5.0, -4.0, 0.0}, {5.0, 4.0, 3.0}, 0.1);
  scene.spheres = {{{2.0, 1.0, 0.8}, 0.6}};
  const sensor_msgs::CameraInfo info = cameraInfo();
  const Eigen::Isometry3d pose = cameraPose();
  sensor_msgs::Image image;
  image.header.frame_id = "camera";
  image.width = kWidth;
  image.height = kHeight;
  image.encoding = encoding;
  const std::uint32_t pixel_bytes = encoding == "16UC1" ? 2 : 4;
  image.step = kWidth * pixel_bytes;
  image.data.resize(std::size_t{image.step} * kHeight);
  for (std::size_t k = 0; k < kPixels; ++k) {
    const std::size_t row = k / kWidth;
    const std::size_t column = k % kWidth;
    const Eigen::Vector3d ray((static_cast<double>(column) - info.K[2]) / info.K[0],
                              (static_cast<double>(row) - info.K[5]) / info.K[4], 1.0);
    const double depth =
        scene.castRay(pose.translation(), (pose.linear() * ray).normalized()) / ray.norm();
    if (pixel_bytes == 2) {
      const auto millimetres = static_cast<std::uint16_t>(std::lround(1000.0 * depth));
      std::memcpy(image.data.data() + 2 * k, &millimetres, 2);
    } else {
      const auto metres = static_cast<float>(depth);
      std::memcpy(image.data.data() + 4 * k, &metres, 4);
    }
  }
  return image;
}

/// The organised float32 x, y, z cloud of `image` in the optical frame: every pixel back-projected
/// (the core's arithmetic is depth_image_proc's), with the empty cloud's layout in `cloud`.
void backProjectIntoCloud(const sensor_msgs::Image& image, const sensor_msgs::CameraInfo& info,
                          sensor_msgs::PointCloud2& cloud) {
  std::size_t skipped = 0;
  const mvog::Scan points = mvog_ros::depthImageToScan(image, info, Eigen::Isometry3d::Identity(),
                                                       mvog::DepthImageConfig{}, kNoLimit, skipped);
  constexpr std::size_t kPointBytes = 3 * sizeof(float);
  cloud.data.resize(points.hits.size() * kPointBytes);
  for (std::size_t k = 0; k < points.hits.size(); ++k) {
    std::memcpy(cloud.data.data() + k * kPointBytes, points.hits[k].data(), kPointBytes);
  }
}

sensor_msgs::PointCloud2 cloudLayout() {
  sensor_msgs::PointCloud2 cloud;
  cloud.header.frame_id = "camera";
  cloud.width = kWidth;
  cloud.height = kHeight;
  cloud.point_step = 12;
  cloud.row_step = 12 * kWidth;
  for (std::uint32_t axis = 0; axis < 3; ++axis) {
    sensor_msgs::PointField field;
    field.name = std::string(1, static_cast<char>('x' + axis));
    field.offset = 4 * axis;
    field.datatype = sensor_msgs::PointField::FLOAT32;
    field.count = 1;
    cloud.fields.push_back(field);
  }
  return cloud;
}

void countPixels(benchmark::State& state) {
  const auto pixels = static_cast<double>(state.iterations()) * static_cast<double>(kPixels);
  state.SetItemsProcessed(static_cast<std::int64_t>(pixels));
  state.counters["s_per_Mpx"] =
      benchmark::Counter(pixels / 1e6, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

/// The depth-image path: the image and its camera info to readings in the map frame.
void BM_DepthImageToScan(benchmark::State& state, const char* encoding) {
  const sensor_msgs::Image image = depthImage(encoding);
  const sensor_msgs::CameraInfo info = cameraInfo();
  const Eigen::Isometry3d pose = cameraPose();
  for (auto _ : state) {
    std::size_t skipped = 0;
    benchmark::DoNotOptimize(
        mvog_ros::depthImageToScan(image, info, pose, mvog::DepthImageConfig{}, kNoLimit, skipped));
  }
  countPixels(state);
}
BENCHMARK_CAPTURE(BM_DepthImageToScan, 16UC1, "16UC1")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_DepthImageToScan, 32FC1, "32FC1")->Unit(benchmark::kMillisecond);

/// A depth image into a map of 0.05 m (the same frame again and again, the map kept): straight
/// from its pixels (as the server does), or through a Scan of every pixel (as it did).
void BM_InsertDepthImage(benchmark::State& state, const char* encoding, bool straight) {
  const sensor_msgs::Image image = depthImage(encoding);
  const sensor_msgs::CameraInfo info = cameraInfo();
  const Eigen::Isometry3d pose = cameraPose();
  mvog::MapConfig config;
  config.resolution = 0.05;
  mvog::Map map(config);
  mvog::InsertionResult result;
  for (auto _ : state) {
    if (straight) {
      result = map.insertDepthImage(
          mvog_ros::depthFrameOf(image, info, pose, mvog::DepthImageConfig{}, kNoLimit));
    } else {
      std::size_t skipped = 0;
      result = map.insertScan(mvog_ros::depthImageToScan(
          image, info, pose, mvog::DepthImageConfig{}, kNoLimit, skipped));
    }
  }
  countPixels(state);
  state.counters["rays_walked"] = static_cast<double>(result.rays_walked);
}
BENCHMARK_CAPTURE(BM_InsertDepthImage, straight 16UC1, "16UC1", true)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_InsertDepthImage, through a Scan 16UC1, "16UC1", false)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_InsertDepthImage, straight 32FC1, "32FC1", true)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_InsertDepthImage, through a Scan 32FC1, "32FC1", false)
    ->Unit(benchmark::kMillisecond);

/// The cloud path, first half: the image back-projected into an organised PointCloud2.
void BM_DepthImageToCloud(benchmark::State& state) {
  const sensor_msgs::Image image = depthImage("16UC1");
  const sensor_msgs::CameraInfo info = cameraInfo();
  for (auto _ : state) {
    sensor_msgs::PointCloud2 cloud = cloudLayout();
    backProjectIntoCloud(image, info, cloud);
    benchmark::DoNotOptimize(cloud.data.data());
  }
  countPixels(state);
}
BENCHMARK(BM_DepthImageToCloud)->Unit(benchmark::kMillisecond);

/// The cloud path, second half: the cloud to readings in the map frame.
void BM_PointCloudToScan(benchmark::State& state) {
  sensor_msgs::PointCloud2 cloud = cloudLayout();
  backProjectIntoCloud(depthImage("16UC1"), cameraInfo(), cloud);
  const Eigen::Isometry3d pose = cameraPose();
  for (auto _ : state) {
    benchmark::DoNotOptimize(mvog_ros::pointCloudToScan(cloud, pose, kNoLimit));
  }
  countPixels(state);
}
BENCHMARK(BM_PointCloudToScan)->Unit(benchmark::kMillisecond);

/// A message serialised and deserialised, as between a publisher and a subscriber.
template <class Message>
void roundTrip(benchmark::State& state, const Message& message) {
  for (auto _ : state) {
    const ros::SerializedMessage bytes = ros::serialization::serializeMessage(message);
    Message received;
    ros::serialization::IStream stream(
        bytes.message_start,
        static_cast<std::uint32_t>(bytes.num_bytes - (bytes.message_start - bytes.buf.get())));
    ros::serialization::deserialize(stream, received);
    benchmark::DoNotOptimize(received.data.data());
  }
  countPixels(state);
  state.counters["bytes"] = static_cast<double>(ros::serialization::serializationLength(message));
}

void BM_RoundTripImage(benchmark::State& state, const char* encoding) {
  roundTrip(state, depthImage(encoding));
}
BENCHMARK_CAPTURE(BM_RoundTripImage, 16UC1, "16UC1")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_RoundTripImage, 32FC1, "32FC1")->Unit(benchmark::kMillisecond);

void BM_RoundTripPointCloud2(benchmark::State& state) {
  sensor_msgs::PointCloud2 cloud = cloudLayout();
  backProjectIntoCloud(depthImage("16UC1"), cameraInfo(), cloud);
  roundTrip(state, cloud);
}
BENCHMARK(BM_RoundTripPointCloud2)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
