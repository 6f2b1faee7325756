// Smoke test of mvog_bench: behaviour only (never timings). Runs the executable on
// spherical_scan.graph from the shared data (MVOG_DATA_DIR, default ../shared/data beside the
// repository; skipped when absent unless CI=true), on scan graphs and a bag of depth images it
// writes itself, on its synthetic sensors, its ground-truth scenes, and on bad input; Bonxai's
// backend when mvog_bench was built with it (MVOG_BENCH_HAVE_BONXAI), else its message.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <json/json.h>
#include <rosbag/bag.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <tf2_msgs/TFMessage.h>

#include "../recordings.h"

namespace {

class BenchSmokeTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char pattern[] = "/tmp/mvog_bench_test_XXXXXX";
    ASSERT_NE(::mkdtemp(pattern), nullptr);
    directory_ = pattern;
  }
  void TearDown() override {
    const std::string command = "rm -rf '" + directory_ + "'";
    EXPECT_EQ(std::system(command.c_str()), 0);
  }

  /// Runs mvog_bench with `arguments`; returns its exit code, its stderr in `errors` (and its
  /// stdout in `*output` if given).
  int runBench(const std::string& arguments, std::string& errors,
               std::string* output = nullptr) const {
    const std::string error_file = directory_ + "/stderr.txt";
    const std::string output_file = directory_ + "/stdout.txt";
    const std::string command = std::string("'") + MVOG_BENCH_EXECUTABLE + "' " + arguments +
                                " > '" + output_file + "' 2> '" + error_file + "'";
    const int status = std::system(command.c_str());
    errors = readText(error_file);
    if (output != nullptr) *output = readText(output_file);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }

  static std::string readText(const std::string& path) {
    std::ifstream file(path);
    std::stringstream text;
    text << file.rdbuf();
    return text.str();
  }

  Json::Value readJson(const std::string& path) const {
    std::ifstream file(path);
    Json::Value root;
    Json::CharReaderBuilder builder;
    std::string errors;
    EXPECT_TRUE(Json::parseFromStream(builder, file, &root, &errors)) << errors;
    return root;
  }

  /// Runs mvog_bench on synthetic input `name` at 0.1 m with `backends` (its --backend options);
  /// returns its JSON report (null if it failed, with a test failure).
  Json::Value runSynthetic(const std::string& name, const std::string& backends) const {
    const std::string json = directory_ + "/" + name + ".json";
    std::string errors;
    const int code = runBench(
        "--input synthetic:" + name + " --resolution 0.1 " + backends + " --json '" + json + "'",
        errors);
    EXPECT_EQ(code, 0) << errors;
    return code == 0 ? readJson(json) : Json::Value();
  }

  /// Writes a ScanGraph: one node per entry of `nodes` (points in the sensor frame), pose
  /// translation (0, 0, 1) and identity rotation, no edges; `cut` bytes are left off the end.
  std::string writeGraph(const std::string& name, const std::vector<std::vector<double>>& nodes,
                         std::size_t cut = 0) const {
    std::string bytes;
    auto u32 = [&](std::uint32_t v) { bytes.append(reinterpret_cast<const char*>(&v), 4); };
    auto f64 = [&](double v) { bytes.append(reinterpret_cast<const char*>(&v), 8); };
    u32(static_cast<std::uint32_t>(nodes.size()));
    for (std::size_t n = 0; n < nodes.size(); ++n) {
      u32(static_cast<std::uint32_t>(nodes[n].size() / 3));
      for (std::size_t k = 0; k < nodes[n].size(); k += 3) {
        u32(3);
        for (int axis = 0; axis < 3; ++axis) f64(nodes[n][k + axis]);
      }
      u32(3);
      for (double t : {0.0, 0.0, 1.0}) f64(t);
      u32(4);
      for (double q : {1.0, 0.0, 0.0, 0.0}) f64(q);
      u32(static_cast<std::uint32_t>(n));
    }
    u32(0);  // edges
    bytes.resize(bytes.size() - cut);
    const std::string path = directory_ + "/" + name;
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
  }

  std::string directory_;
};

TEST_F(BenchSmokeTest, BothBackendsMapTheSphericalScan) {
  const std::string input = mvog_test::dataDirectory() + "/spherical_scan.graph";
  MVOG_REQUIRE_RECORDING(input);
  const std::string json = directory_ + "/x.json";
  std::string errors;
  ASSERT_EQ(
      runBench("--input '" + input + "' --resolution 0.1 --backend both --json '" + json + "'",
               errors),
      0)
      << errors;
  const Json::Value root = readJson(json);
  std::set<std::string> backends;
  for (const Json::Value& result : root["results"]) {
    backends.insert(result["backend"].asString());
    EXPECT_EQ(result["resolution"].asDouble(), 0.1);
    EXPECT_EQ(result["readings"].asUInt64(), 10201u);  // the fixture's point count
    EXPECT_GT(result["memory_bytes"].asUInt64(), 0u);
    EXPECT_GT(result["file_bytes"].asUInt64(), 0u);
  }
  EXPECT_EQ(backends, (std::set<std::string>{"mvog", "octomap"}));
  ASSERT_EQ(root["agreement"].size(), 1u);
  EXPECT_GT(root["agreement"][0]["endpoints"]["points"].asUInt64(), 0u);
  ASSERT_EQ(root["table_one"].size(), 1u);
  EXPECT_EQ(root["table_one"][0]["point_cloud_bytes"].asUInt64(), 12u * 10201u);
}

TEST_F(BenchSmokeTest, ReadsEveryNodeOfAGraphItWrote) {
  const std::string input =
      writeGraph("two.graph", {{2, 0, 0, 0, 2, 0, -2, 0, 0}, {0, -2, 0.5, 1.5, 1.5, 0}});
  const std::string json = directory_ + "/two.json";
  std::string errors;
  ASSERT_EQ(runBench("--input '" + input + "' --resolution 0.1 --resolution 0.2 --threads 2 " +
                         "--repeat 2 --json '" + json + "'",
                     errors),
            0)
      << errors;
  const Json::Value root = readJson(json);
  ASSERT_EQ(root["results"].size(), 4u);  // two resolutions, both backends by default
  for (const Json::Value& result : root["results"]) {
    EXPECT_EQ(result["readings"].asUInt64(), 5u);
  }
  EXPECT_EQ(root["input"]["scans"].asUInt64(), 2u);
  EXPECT_EQ(root["repeat"].asInt(), 2);
}

// --octomap-clamping off: OctoMap's every update counts. A voxel that ten scans' rays cross,
// then three scans hit, is occupied with OctoMap's default clamping (its log-odds stop at
// logodds(0.1192), about five misses, so three hits outweigh them) and free without it (ten
// misses of 0.405 outweigh three hits of 0.847), as MVOG's summed masses weigh them.
TEST_F(BenchSmokeTest, OctomapWithoutClampingCountsEveryUpdate) {
  std::vector<std::vector<double>> nodes(10, {2.05, 0.05, 0.05});  // crossing (1.05, 0.05, 0.025)
  nodes.resize(13, {1.05, 0.05, 0.05});                            // then hitting it
  const std::string input = writeGraph("crossed_then_hit.graph", nodes);
  auto endpoints_occupied = [&](const std::string& clamping) {
    const std::string json = directory_ + "/" + clamping + ".json";
    std::string errors;
    EXPECT_EQ(runBench("--input '" + input + "' --resolution 0.1 --backend octomap " +
                           "--octomap-clamping " + clamping + " --json '" + json + "'",
                       errors),
              0)
        << errors;
    const Json::Value root = readJson(json);
    EXPECT_EQ(root["octomap_clamping"].asBool(), clamping == "on");
    return root["quality"][0]["endpoints_occupied_percent"].asDouble();
  };
  EXPECT_EQ(endpoints_occupied("on"), 100.0);
  EXPECT_NEAR(endpoints_occupied("off"), 100.0 * 10.0 / 13.0, 1e-6);  // JSON keeps 9 digits
  std::string errors;
  EXPECT_EQ(runBench("--input '" + input + "' --octomap-clamping maybe", errors), 2);
  EXPECT_NE(errors.find("--octomap-clamping must be on or off, got 'maybe'"), std::string::npos)
      << errors;
}

// Sensors none of the shared recordings has (a multi-beam automotive lidar, a tilting laser),
// cast into scenes built in code: what each saw stays occupied as in OctoMap on the same rays,
// within issue 10's margins (ends occupied >= OctoMap's - 2 points, along the rays free >=
// OctoMap's - 1), and nothing is known far from the rays.
TEST_F(BenchSmokeTest, SyntheticSensorsKeepWhatTheySawAsOctoMapDoes) {
  for (const std::string& name : {std::string("rotating-lidar-16"), std::string("tilting-laser")}) {
    SCOPED_TRACE(name);
    const Json::Value root = runSynthetic(name, "--backend both");
    ASSERT_FALSE(root.isNull());
    EXPECT_EQ(root["input"]["format"].asString(), "synthetic");
    EXPECT_EQ(root["input"]["scans"].asUInt64(), 10u);
    Json::Value mvog;
    Json::Value octomap;
    for (const Json::Value& quality : root["quality"]) {
      (quality["backend"].asString() == "mvog" ? mvog : octomap) = quality;
    }
    ASSERT_FALSE(mvog.isNull());
    ASSERT_FALSE(octomap.isNull());
    EXPECT_GE(mvog["endpoints_occupied_percent"].asDouble(),
              octomap["endpoints_occupied_percent"].asDouble() - 2.0);
    EXPECT_GE(mvog["along_rays_free_percent"].asDouble(),
              octomap["along_rays_free_percent"].asDouble() - 1.0);
    EXPECT_GE(mvog["far_unknown_percent"].asDouble(), 99.0);
  }
  // The lidar's readings in firing order (as an unorganised Velodyne cloud gives them) build the
  // same map as beam by beam: the order changes the speed of insertion only.
  const Json::Value beam_by_beam = runSynthetic("rotating-lidar-16", "--backend mvog");
  const Json::Value firing_order = runSynthetic("rotating-lidar-16-firing-order", "--backend mvog");
  ASSERT_FALSE(beam_by_beam.isNull());
  ASSERT_FALSE(firing_order.isNull());
  const std::string checksum = beam_by_beam["results"][0]["map_checksum"].asString();
  EXPECT_FALSE(checksum.empty());
  EXPECT_EQ(firing_order["results"][0]["map_checksum"].asString(), checksum);
  std::string errors;
  EXPECT_EQ(runBench("--input synthetic:sonar", errors), 1);
  EXPECT_NE(errors.find("no such synthetic input (there are rotating-lidar-16"), std::string::npos)
      << errors;
}

// The ground truth (truth:NAME, BENCHMARKS.md "Ground truth"). On every scene the labels pass
// their two checks: a classifier with perfect knowledge of the geometry and of where the rays
// went scores 1.0 on every metric, and the map of the endpoints alone calls none of the free
// space free. Then MVOG's defaults at 0.05 m keep what each sensor saw: surfaces occupied, thin
// objects occupied, free space beside a surface and under an overhang free. Each threshold is
// the figure measured at the commit that added this test less about a point (two where the
// figure is below 0.95): the scenes, the sensors and the camera's noise are seeded, so a change
// of the figures is a change of the map.
TEST_F(BenchSmokeTest, GroundTruthLabelsHoldAndMvogKeepsWhatEachSensorSaw) {
  struct Expected {
    const char* scene;
    double surface_occupied;
    double thin_occupied;
    double free_near_surface_free;
    double free_under_overhang_free;
  };
  const Expected expected[] = {
      // Measured: 1.000, 1.000, 0.936, 0.989 (the camera's noise reaches into the free space
      // beside far surfaces: 6.7 % of those points lie in a voxel holding a hit).
      {"room-depth-camera", 0.99, 0.99, 0.915, 0.975},
      {"bridge-lidar-16", 0.97, 0.98, 0.99, 0.99},     // 0.984, 0.993, 1.000, 1.000
      {"car-lidar", 0.98, 0.98, 0.99, 0.99},           // 0.992, 0.994, 1.000, 1.000
      {"corridor-2d-laser", 0.965, 0.92, 0.99, 0.99},  // 0.978, 0.938, 1.000, 1.000
      {"tilting-laser", 0.97, 0.97, 0.99, 0.99},       // 0.981, 0.984, 1.000, 1.000
  };
  for (const Expected& scene : expected) {
    SCOPED_TRACE(scene.scene);
    const std::string json = directory_ + "/truth.json";
    std::string errors;
    ASSERT_EQ(runBench(std::string("--input truth:") + scene.scene +
                           " --resolution 0.05 --backend mvog --json '" + json + "'",
                       errors),
              0)
        << errors;
    const Json::Value root = readJson(json);
    EXPECT_EQ(root["input"]["format"].asString(), "truth");
    std::map<std::string, Json::Value> rows;
    for (const Json::Value& row : root["truth"]) rows[row["backend"].asString()] = row;
    ASSERT_EQ(rows.size(), 3u);  // the two checks and mvog
    const Json::Value& oracle = rows["oracle"];
    for (const char* key :
         {"surface_occupied", "thin_occupied", "free_near_surface_free", "free_far_free",
          "free_under_overhang_free", "unobserved_unknown", "occupancy_f1"}) {
      EXPECT_EQ(oracle[key].asDouble(), 1.0) << key;
    }
    EXPECT_EQ(oracle["surface_free"].asDouble(), 0.0);
    for (const char* key :
         {"free_near_surface_free", "free_far_free", "free_under_overhang_free"}) {
      EXPECT_EQ(rows["endpoints-only"][key].asDouble(), 0.0) << key;
    }
    // Enough points of every label for its figure to mean something.
    for (const char* key : {"surface_points", "free_near_surface_points", "free_far_points"}) {
      EXPECT_GE(oracle[key].asUInt64(), 10000u) << key;
    }
    EXPECT_GE(oracle["thin_points"].asUInt64(), 100u);
    EXPECT_GE(oracle["free_under_overhang_points"].asUInt64(), 200u);
    EXPECT_EQ(oracle["unobserved_points"].asUInt64(), 10000u);
    const Json::Value& mvog = rows["mvog"];
    EXPECT_GE(mvog["surface_occupied"].asDouble(), scene.surface_occupied);
    EXPECT_GE(mvog["thin_occupied"].asDouble(), scene.thin_occupied);
    EXPECT_GE(mvog["free_near_surface_free"].asDouble(), scene.free_near_surface_free);
    EXPECT_GE(mvog["free_under_overhang_free"].asDouble(), scene.free_under_overhang_free);
  }
  // The slice: a panel per map run, a binary PPM (the corridor's: 32.8 m x 12.8 m at 2 cm).
  const std::string slice = directory_ + "/slice.ppm";
  std::string errors;
  ASSERT_EQ(runBench("--input truth:corridor-2d-laser --resolution 0.05 --backend both "
                     "--truth-slice '" +
                         slice + "'",
                     errors),
            0)
      << errors;
  const std::string pixels = readText(slice);
  const std::string header = "P6\n1640 1284\n255\n";  // two panels 640 high, 4 between
  EXPECT_EQ(pixels.substr(0, header.size()), header);
  EXPECT_EQ(pixels.size(), header.size() + 1640u * 1284u * 3u);
  EXPECT_EQ(runBench("--input truth:moon", errors), 1);
  EXPECT_NE(errors.find("no such scene (there are bridge-lidar-16"), std::string::npos) << errors;
  EXPECT_EQ(runBench("--input synthetic:tilting-laser --truth-slice x.ppm", errors), 2);
  EXPECT_NE(errors.find("--truth-slice needs --input truth:NAME"), std::string::npos) << errors;
}

#ifdef MVOG_BENCH_HAVE_BONXAI
// Bonxai's map is OctoMap's model (the same hit and miss log-odds, a voxel updated once a scan):
// on the same rays it keeps what the sensor saw as OctoMap does, and knows nothing far from them.
TEST_F(BenchSmokeTest, BonxaiMapsTheSameRaysAsOctoMap) {
  const std::string json = directory_ + "/bonxai.json";
  std::string errors;
  std::string output;
  ASSERT_EQ(runBench("--input synthetic:tilting-laser --resolution 0.1 --backend both "
                     "--backend bonxai --json '" +
                         json + "'",
                     errors, &output),
            0)
      << errors;
  EXPECT_NE(output.find("\nbonxai     0.100       1 "), std::string::npos) << output;
  EXPECT_NE(output.find("\nMVOG / Bonxai\n"), std::string::npos) << output;
  const Json::Value root = readJson(json);
  Json::Value bonxai;
  for (const Json::Value& result : root["results"]) {
    if (result["backend"].asString() == "bonxai") bonxai = result;
  }
  ASSERT_FALSE(bonxai.isNull());
  EXPECT_EQ(bonxai["readings"].asUInt64(), root["input"]["readings"].asUInt64());
  EXPECT_GT(bonxai["insert_seconds"].asDouble(), 0.0);
  EXPECT_GT(bonxai["memory_bytes"].asUInt64(), 0u);
  EXPECT_GT(bonxai["active_cells"].asUInt64(), 0u);
  std::map<std::string, Json::Value> quality;
  for (const Json::Value& row : root["quality"]) quality[row["backend"].asString()] = row;
  ASSERT_EQ(quality.count("bonxai"), 1u);
  ASSERT_EQ(quality.count("octomap"), 1u);
  for (const char* key : {"endpoints_occupied_percent", "along_rays_free_percent"}) {
    EXPECT_NEAR(quality["bonxai"][key].asDouble(), quality["octomap"][key].asDouble(), 2.0) << key;
  }
  EXPECT_GE(quality["bonxai"]["far_unknown_percent"].asDouble(), 99.0);
  ASSERT_EQ(root["bonxai_comparison"].size(), 1u);
  EXPECT_GT(root["bonxai_comparison"][0]["readings_per_second_ratio"].asDouble(), 0.0);
  EXPECT_GT(root["bonxai_comparison"][0]["memory_ratio"].asDouble(), 0.0);
}
#else
TEST_F(BenchSmokeTest, WithoutBonxaiSaysWhyAndAllRunsTheOthers) {
  std::string errors;
  EXPECT_EQ(runBench("--input synthetic:tilting-laser --backend bonxai", errors), 2);
  EXPECT_NE(errors.find("mvog_bench was built without Bonxai"), std::string::npos) << errors;
  EXPECT_NE(errors.find("MVOG_PEERS_DIR"), std::string::npos) << errors;
  const std::string json = directory_ + "/all.json";
  ASSERT_EQ(runBench("--input synthetic:tilting-laser --resolution 0.1 --backend all --json '" +
                         json + "'",
                     errors),
            0)
      << errors;
  EXPECT_NE(errors.find("--backend all skips Bonxai: mvog_bench was built without Bonxai"),
            std::string::npos)
      << errors;
  const Json::Value root = readJson(json);
  EXPECT_EQ(root["results"].size(), 4u);  // mvog, octomap, the walk and every reading's walk
  EXPECT_EQ(root["bonxai_comparison"].size(), 0u);
}
#endif

/// A depth image of `width` x `height` pixels of `encoding` (Pixel: std::uint16_t for 16UC1,
/// float for 32FC1), every pixel `depth`, at `seconds`.
template <class Pixel>
sensor_msgs::Image depthImage(const std::string& encoding, std::uint32_t width,
                              std::uint32_t height, Pixel depth, double seconds) {
  sensor_msgs::Image image;
  image.header.frame_id = "camera";
  image.header.stamp = ros::Time(seconds);
  image.width = width;
  image.height = height;
  image.encoding = encoding;
  image.step = width * static_cast<std::uint32_t>(sizeof(Pixel));
  const std::vector<Pixel> pixels(std::size_t{width} * height, depth);
  image.data.resize(pixels.size() * sizeof(Pixel));
  std::memcpy(image.data.data(), pixels.data(), image.data.size());
  return image;
}

sensor_msgs::CameraInfo cameraInfoOf(const sensor_msgs::Image& image) {
  sensor_msgs::CameraInfo info;
  info.header = image.header;
  info.width = image.width;
  info.height = image.height;
  info.K = {4.0, 0.0, 1.5, 0.0, 4.0, 1.0, 0.0, 0.0, 1.0};
  return info;
}

TEST_F(BenchSmokeTest, ReadsTheDepthImagesOfABagWithTheCameraInfoOfTheirStamp) {
  const std::string input = directory_ + "/depth.bag";
  {
    rosbag::Bag bag(input, rosbag::bagmode::Write);
    tf2_msgs::TFMessage tf;
    tf.transforms.resize(1);
    tf.transforms[0].header.frame_id = "map";
    tf.transforms[0].header.stamp = ros::Time(1.0);
    tf.transforms[0].child_frame_id = "camera";
    tf.transforms[0].transform.translation.z = 1.0;
    tf.transforms[0].transform.rotation.w = 1.0;
    bag.write("/tf_static", ros::Time(1.0), tf);
    const std::string image_topic = "/camera/depth/image";
    const std::string info_topic = "/camera/depth/camera_info";
    const sensor_msgs::Image millimetres = depthImage<std::uint16_t>("16UC1", 4, 3, 2000, 2.0);
    bag.write(info_topic, ros::Time(2.0), cameraInfoOf(millimetres));
    bag.write(image_topic, ros::Time(2.0), millimetres);
    // Not range data: not read.
    bag.write("/camera/rgb/image", ros::Time(2.5), depthImage<float>("rgb8", 4, 3, 1.0f, 2.5));
    // Without the camera info of its stamp: skipped.
    bag.write(image_topic, ros::Time(3.0), depthImage<std::uint16_t>("16UC1", 4, 3, 1000, 3.0));
    sensor_msgs::Image metres = depthImage<float>("32FC1", 4, 3, 1.5f, 4.0);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    std::memcpy(metres.data.data() + 4 * 5, &nan, 4);  // one pixel says nothing
    bag.write(image_topic, ros::Time(4.0), metres);    // its camera info comes after it
    bag.write(info_topic, ros::Time(4.1), cameraInfoOf(metres));
  }
  const std::string json = directory_ + "/depth.json";
  std::string errors;
  ASSERT_EQ(runBench("--input '" + input + "' --backend mvog --json '" + json + "'", errors), 0)
      << errors;
  const Json::Value root = readJson(json);
  EXPECT_EQ(root["input"]["sensor_messages"].asUInt64(), 3u);
  EXPECT_EQ(root["input"]["messages_without_camera_info"].asUInt64(), 1u);
  EXPECT_EQ(root["input"]["scans"].asUInt64(), 2u);
  EXPECT_EQ(root["input"]["readings"].asUInt64(), 12u + 11u);
  EXPECT_EQ(root["input"]["invalid_pixels"].asUInt64(), 1u);
}

TEST_F(BenchSmokeTest, RefusesBadInputWithAMessage) {
  std::string errors;
  EXPECT_NE(runBench("--input '" + directory_ + "/missing.bag'", errors), 0);
  EXPECT_NE(errors.find("cannot open"), std::string::npos) << errors;

  const std::string truncated = writeGraph("cut.graph", {{2, 0, 0, 0, 2, 0}}, 30);
  EXPECT_NE(runBench("--input '" + truncated + "'", errors), 0);
  EXPECT_NE(errors.find("truncated"), std::string::npos) << errors;

  const std::string not_a_bag = directory_ + "/notes.bag";
  std::ofstream(not_a_bag) << "not a bag\n";
  EXPECT_NE(runBench("--input '" + not_a_bag + "'", errors), 0);
  EXPECT_NE(errors.find("neither a ROS bag"), std::string::npos) << errors;

  EXPECT_EQ(runBench("--input x --backend nothing", errors), 2);
  EXPECT_EQ(runBench("--input x --repeat 0", errors), 2);
  EXPECT_NE(errors.find("--repeat needs a whole number"), std::string::npos) << errors;
}

}  // namespace
