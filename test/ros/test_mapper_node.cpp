// Rostest node driving running mapping servers (node or nodelet) through their ROS interface:
// it publishes tf and sensor streams of a known synthetic scene and checks the answers of the
// services, the published markers, grids, binary map and statistics.
//
// Suites (chosen with --gtest_filter by the .test files in this directory):
//   Mapper.*            a server at ~mapper (default /mvog_mapper) with test/ros/mapper_test.yaml
//   Decay.*             servers at /with_decay/mvog_mapper and /without_decay/mvog_mapper
//   RefusedStart.*      starts mvog_node and the nodelet with invalid parameters itself
//
// The scene, in the map frame: a wall, the face at x = 3.05 m (a cell centre at 0.1 m), from
// y = -2.5 to 2.5 m, of infinite height. A LaserScan sensor at 0.55 m height on a base moving
// along y, and a depth camera (PointCloud2) at 1.55 m, turned about z and x. Every wait is for
// a condition, with a timeout; nothing asserts how long anything took.
#include <gtest/gtest.h>
#include <limits.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <map_msgs/OccupancyGridUpdate.h>
#include <nav_msgs/OccupancyGrid.h>
#include <nodelet/NodeletList.h>
#include <ros/ros.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <std_srvs/Trigger.h>
#include <tf2_eigen/tf2_eigen.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <visualization_msgs/MarkerArray.h>
#include <Eigen/Geometry>

#include "mvog/GetCrossSection.h"
#include "mvog/GetOccupancy.h"
#include "mvog/MapBinary.h"
#include "mvog/MapFile.h"
#include "mvog/MapStatistics.h"
#include "mvog/map_io.h"
#include "mvog_scene/scene.h"

namespace {

constexpr double kTimeout = 20.0;  // s, for any awaited condition
constexpr double kResolution = 0.1;
constexpr double kLaserHeight = 0.55;
constexpr float kLaserRangeMin = 0.05f;
constexpr float kLaserRangeMax = 8.0f;
constexpr std::uint8_t kUnknown = mvog::GetOccupancy::Response::UNKNOWN;
constexpr std::uint8_t kFree = mvog::GetOccupancy::Response::FREE;
constexpr std::uint8_t kOccupied = mvog::GetOccupancy::Response::OCCUPIED;

bool waitFor(const std::function<bool()>& condition, double timeout = kTimeout) {
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout);
  while (ros::ok()) {
    if (condition()) return true;
    if (ros::WallTime::now() > deadline) return false;
    ros::WallDuration(0.01).sleep();
  }
  return false;
}

// ---- The scene -------------------------------------------------------------------------------

constexpr double kInf = std::numeric_limits<double>::infinity();
/// Obstacles of infinite height over an axis-aligned rectangle (m).
const mvog_scene::Box kWall{{3.05, -2.5, -kInf}, {3.25, 2.5, kInf}};
const mvog_scene::Box kPerson{{1.45, -0.1, -kInf}, {1.65, 0.1, kInf}};  // in the decay beams

Eigen::Isometry3d mapFromBase(double y) {
  return Eigen::Isometry3d(Eigen::Translation3d(0.0, y, 0.0));
}
const Eigen::Isometry3d kBaseFromLaser =
    Eigen::Translation3d(0.1, 0.0, kLaserHeight) * Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitZ());
const Eigen::Isometry3d kMapFromCamera = Eigen::Translation3d(0.05, 0.05, 1.55) *
                                         Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()) *
                                         Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX());
/// Where queries in another frame are asked from.
const Eigen::Isometry3d kMapFromQueryFrame =
    Eigen::Translation3d(1.0, 2.0, 0.0) * Eigen::AngleAxisd(M_PI / 2.0, Eigen::Vector3d::UnitZ());
/// The decay test's static laser.
const Eigen::Isometry3d kMapFromDecayLaser =
    Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.0, kLaserHeight));

geometry_msgs::TransformStamped transform(const Eigen::Isometry3d& parent_from_child,
                                          const std::string& parent, const std::string& child,
                                          const ros::Time& stamp) {
  geometry_msgs::TransformStamped message = tf2::eigenToTransform(parent_from_child);
  message.header.frame_id = parent;
  message.header.stamp = stamp;
  message.child_frame_id = child;
  return message;
}

struct ScanLayout {
  double angle_min, angle_max, angle_increment;
  std::size_t beams() const {
    return static_cast<std::size_t>(std::lround((angle_max - angle_min) / angle_increment)) + 1;
  }
};
const ScanLayout kMovingLaser{-1.2, 1.2, 0.005};
const ScanLayout kDecayLaser{-0.6, 0.6, 0.01};
/// Beams 0..2 of every moving-laser scan say nothing: NaN, -Inf, below range_min.
constexpr std::size_t kSkippedBeamsPerScan = 3;

/// A horizontal LaserScan of the scene by a laser at `map_from_laser` (turned about z only).
sensor_msgs::LaserScan scanOf(const Eigen::Isometry3d& map_from_laser, const ScanLayout& layout,
                              const mvog_scene::Scene& scene, const std::string& frame,
                              const ros::Time& stamp) {
  sensor_msgs::LaserScan scan;
  scan.header.frame_id = frame;
  scan.header.stamp = stamp;
  scan.angle_min = static_cast<float>(layout.angle_min);
  scan.angle_max = static_cast<float>(layout.angle_max);
  scan.angle_increment = static_cast<float>(layout.angle_increment);
  scan.range_min = kLaserRangeMin;
  scan.range_max = kLaserRangeMax;
  for (std::size_t k = 0; k < layout.beams(); ++k) {
    const double angle = scan.angle_min + static_cast<double>(k) * scan.angle_increment;
    const Eigen::Vector3d direction =
        map_from_laser.linear() * Eigen::Vector3d(std::cos(angle), std::sin(angle), 0.0);
    const double range = scene.castRay(map_from_laser.translation(), direction.normalized());
    scan.ranges.push_back(range <= kLaserRangeMax ? static_cast<float>(range)
                                                  : std::numeric_limits<float>::infinity());
  }
  return scan;
}

/// The camera's view of the wall: points at the cell centres x = 3.05, y in [-0.95, 0.95],
/// z in [1.25, 1.95], in the camera frame, plus kNaNPointsPerCloud NaN points.
constexpr std::size_t kWallColumns = 20;
constexpr std::size_t kWallRows = 8;
constexpr std::size_t kNaNPointsPerCloud = 2;
constexpr std::size_t kPointsPerCloud = kWallColumns * kWallRows + kNaNPointsPerCloud;

/// A cloud of the camera seeing points given in the map frame.
sensor_msgs::PointCloud2 cameraCloud(const std::vector<Eigen::Vector3d>& map_points,
                                     const ros::Time& stamp) {
  sensor_msgs::PointCloud2 cloud;
  cloud.header.frame_id = "camera";
  cloud.header.stamp = stamp;
  sensor_msgs::PointCloud2Modifier modifier(cloud);
  modifier.setPointCloud2FieldsByString(1, "xyz");
  modifier.resize(map_points.size());
  sensor_msgs::PointCloud2Iterator<float> x(cloud, "x"), y(cloud, "y"), z(cloud, "z");
  const Eigen::Isometry3d camera_from_map = kMapFromCamera.inverse();
  for (const Eigen::Vector3d& map_point : map_points) {
    const Eigen::Vector3d point = camera_from_map * map_point;
    *x = static_cast<float>(point.x());
    *y = static_cast<float>(point.y());
    *z = static_cast<float>(point.z());
    ++x, ++y, ++z;
  }
  cloud.is_dense = false;
  return cloud;
}

sensor_msgs::PointCloud2 wallCloud(const ros::Time& stamp) {
  std::vector<Eigen::Vector3d> points;
  for (std::size_t k = 0; k < kWallColumns * kWallRows; ++k) {
    points.emplace_back(3.05, -0.95 + 0.1 * static_cast<double>(k % kWallColumns),
                        1.25 + 0.1 * static_cast<double>(k / kWallColumns));
  }
  points.resize(kPointsPerCloud, Eigen::Vector3d::Constant(std::nan("")));
  return cameraCloud(points, stamp);
}

// ---- Probes: where the answer is known --------------------------------------------------------

struct Probe {
  Eigen::Vector3d point;
  std::uint8_t expected;
  const char* why;
};

const std::vector<Probe> kSceneProbes = {
    {{3.05, 0.05, kLaserHeight}, kOccupied, "wall, seen by the laser"},
    {{3.05, -0.95, kLaserHeight}, kOccupied, "wall, seen by the laser"},
    {{3.05, 1.05, kLaserHeight}, kOccupied, "wall, seen by the laser"},
    {{3.05, 0.05, 1.55}, kOccupied, "wall, seen by the camera"},
    {{3.05, -0.45, 1.85}, kOccupied, "wall, seen by the camera"},
    {{1.55, 0.05, kLaserHeight}, kFree, "along the laser beams"},
    {{2.55, -0.55, kLaserHeight}, kFree, "along the laser beams"},
    {{0.85, 0.65, kLaserHeight}, kFree, "along the laser beams"},
    {{1.95, 4.65, kLaserHeight}, kFree, "along out-of-range beams, within range_max"},
    {{1.55, 0.05, 1.55}, kFree, "along the camera rays"},
    {{2.05, -0.25, 1.65}, kFree, "along the camera rays"},
    {{4.05, 0.05, kLaserHeight}, kUnknown, "behind the wall"},
    {{3.55, 0.05, 1.55}, kUnknown, "behind the wall"},
    {{3.4, 8.4, kLaserHeight}, kUnknown, "beyond range_max of out-of-range beams"},
    {{1.55, 0.05, 3.55}, kUnknown, "above every ray"},
    {{-20.05, 20.05, kLaserHeight}, kUnknown, "far away"},
};

std::vector<geometry_msgs::Point> toPoints(const std::vector<Probe>& probes,
                                           const Eigen::Isometry3d& frame_from_map) {
  std::vector<geometry_msgs::Point> points;
  for (const Probe& probe : probes) {
    const Eigen::Vector3d p = frame_from_map * probe.point;
    geometry_msgs::Point point;
    point.x = p.x();
    point.y = p.y();
    point.z = p.z();
    points.push_back(point);
  }
  return points;
}

// ---- A mapping server seen from outside -------------------------------------------------------

/// The bytes of a file, or nothing if it cannot be read.
std::string readFile(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>());
}

/// Removes a server's ~map_directory if the tests left it empty (rmdir refuses anything else).
void removeEmptyMapDirectory(const std::string& server) {
  std::string directory;
  if (ros::param::get(server + "/map_directory", directory)) ::rmdir(directory.c_str());
}

/// Keeps every message of a topic.
template <class Message>
class Inbox {
 public:
  Inbox(ros::NodeHandle& nh, const std::string& topic)
      : subscriber_(nh.subscribe(topic, 100, &Inbox::receive, this)) {}
  Inbox(const Inbox&) = delete;
  Inbox& operator=(const Inbox&) = delete;

  std::vector<boost::shared_ptr<const Message>> messages() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return messages_;
  }
  std::size_t size() const { return messages().size(); }
  /// Waits for a message satisfying `accept` among those received after the first `skipped`.
  bool waitForMessage(const std::function<bool(const Message&)>& accept,
                      std::size_t skipped = 0) const {
    return waitForAll([&](const std::vector<boost::shared_ptr<const Message>>& all) {
      return std::any_of(all.begin() + static_cast<std::ptrdiff_t>(std::min(skipped, all.size())),
                         all.end(), [&](const auto& m) { return accept(*m); });
    });
  }
  /// Waits until the messages received so far satisfy `accept`.
  bool waitForAll(const std::function<bool(const std::vector<boost::shared_ptr<const Message>>&)>&
                      accept) const {
    return waitFor([&] { return accept(messages()); });
  }

 private:
  void receive(const boost::shared_ptr<const Message>& message) {
    std::lock_guard<std::mutex> lock(mutex_);
    messages_.push_back(message);
  }

  mutable std::mutex mutex_;
  std::vector<boost::shared_ptr<const Message>> messages_;
  ros::Subscriber subscriber_;
};

class MapperClient {
 public:
  /// `name`: the server's node name, e.g. /mvog_mapper.
  explicit MapperClient(const std::string& name)
      : name_(name),
        statistics_(nh_, name + "/statistics"),
        get_occupancy_(nh_.serviceClient<mvog::GetOccupancy>(name + "/get_occupancy")),
        get_cross_section_(nh_.serviceClient<mvog::GetCrossSection>(name + "/get_cross_section")),
        save_map_(nh_.serviceClient<mvog::MapFile>(name + "/save_map")),
        load_map_(nh_.serviceClient<mvog::MapFile>(name + "/load_map")),
        reset_(nh_.serviceClient<std_srvs::Trigger>(name + "/reset")) {}

  const std::string& name() const { return name_; }

  bool waitUntilReady() {
    for (ros::ServiceClient* client :
         {&get_occupancy_, &get_cross_section_, &save_map_, &load_map_, &reset_}) {
      if (!client->waitForExistence(ros::Duration(kTimeout))) return false;
    }
    return true;
  }

  mvog::GetOccupancy::Response query(const std::vector<geometry_msgs::Point>& points,
                                     const std::string& frame_id = "") {
    mvog::GetOccupancy service;
    service.request.points = points;
    service.request.frame_id = frame_id;
    EXPECT_TRUE(get_occupancy_.call(service)) << name_ << "/get_occupancy failed";
    return service.response;
  }
  /// The states at the probes, which must be answered.
  std::vector<std::uint8_t> states(const std::vector<Probe>& probes) {
    const mvog::GetOccupancy::Response response =
        query(toPoints(probes, Eigen::Isometry3d::Identity()));
    EXPECT_TRUE(response.success) << response.message;
    return response.state;
  }
  std::uint8_t state(const Eigen::Vector3d& point) {
    const std::vector<std::uint8_t> answer = states({{point, kUnknown, ""}});
    return answer.empty() ? std::numeric_limits<std::uint8_t>::max() : answer[0];
  }

  mvog::GetCrossSection::Response crossSection(mvog::GetCrossSection::Request request) {
    mvog::GetCrossSection service;
    service.request = request;
    EXPECT_TRUE(get_cross_section_.call(service));
    return service.response;
  }
  mvog::MapFile::Response save(const std::string& path) { return callMapFile(save_map_, path); }
  mvog::MapFile::Response load(const std::string& path) { return callMapFile(load_map_, path); }

  /// Empties the map and waits for statistics that show it (the counters restart at reset).
  void reset() {
    std_srvs::Trigger trigger;
    ASSERT_TRUE(reset_.call(trigger));
    ASSERT_TRUE(trigger.response.success) << trigger.response.message;
    const std::size_t seen = statistics_.size();
    ASSERT_TRUE(statistics_.waitForAll(
        [&](const std::vector<boost::shared_ptr<const mvog::MapStatistics>>& all) {
          return all.size() > seen && all.back()->messages_inserted == 0 &&
                 all.back()->cells_with_volumes == 0;
        }))
        << name_ << ": no statistics of an empty map after reset";
  }

  /// The latest statistics once `accept` holds for them.
  mvog::MapStatistics waitForStatistics(
      const std::function<bool(const mvog::MapStatistics&)>& accept) {
    mvog::MapStatistics latest;
    statistics_.waitForAll(
        [&](const std::vector<boost::shared_ptr<const mvog::MapStatistics>>& all) {
          if (all.empty()) return false;
          latest = *all.back();
          return accept(latest);
        });
    return latest;
  }
  /// Waits until `count` messages were inserted since the last reset.
  void waitForInsertedMessages(std::uint64_t count) {
    const mvog::MapStatistics statistics = waitForStatistics(
        [count](const mvog::MapStatistics& s) { return s.messages_inserted >= count; });
    ASSERT_EQ(statistics.messages_inserted, count)
        << name_ << ": dropped " << statistics.messages_dropped_tf << " for tf, "
        << statistics.messages_dropped_queue << " from the queue, "
        << statistics.messages_dropped_invalid << " invalid; " << statistics.readings_inserted
        << " readings inserted";
  }

 private:
  mvog::MapFile::Response callMapFile(ros::ServiceClient& client, const std::string& path) {
    mvog::MapFile service;
    service.request.path = path;
    EXPECT_TRUE(client.call(service));
    return service.response;
  }

  ros::NodeHandle nh_;
  std::string name_;
  Inbox<mvog::MapStatistics> statistics_;
  ros::ServiceClient get_occupancy_;
  ros::ServiceClient get_cross_section_;
  ros::ServiceClient save_map_;
  ros::ServiceClient load_map_;
  ros::ServiceClient reset_;
};

/// Publishes the tf tree and the sensor streams of the scene.
class SceneSensors {
 public:
  SceneSensors() {
    tf_ = nh_.advertise<tf2_msgs::TFMessage>("/tf", 100);
    const ros::Time now = ros::Time::now();
    static_broadcaster_.sendTransform({transform(kBaseFromLaser, "base_link", "laser", now),
                                       transform(kMapFromCamera, "map", "camera", now),
                                       transform(kMapFromQueryFrame, "map", "query_frame", now),
                                       transform(kMapFromDecayLaser, "map", "decay_laser", now)});
  }

  template <class Message>
  ros::Publisher& publisher(const std::string& topic) {
    ros::Publisher& topic_publisher = publishers_[topic];
    if (!topic_publisher) topic_publisher = nh_.advertise<Message>(topic, 100);
    return topic_publisher;
  }
  /// Waits for the servers to subscribe to `topic`, and to tf.
  template <class Message>
  bool waitForSubscribers(const std::string& topic, std::uint32_t servers = 1) {
    ros::Publisher& topic_publisher = publisher<Message>(topic);
    return waitFor([&] {
      return topic_publisher.getNumSubscribers() >= servers && tf_.getNumSubscribers() >= servers;
    });
  }

  /// One scan of the moving laser with its base at y, and the base's pose before it.
  void publishMovingScan(const std::string& topic, double base_y) {
    const ros::Time stamp = ros::Time::now();
    publishBasePose(base_y, stamp);
    publisher<sensor_msgs::LaserScan>(topic).publish(movingScan(base_y, stamp));
  }
  void publishBasePose(double base_y, const ros::Time& stamp) {
    tf2_msgs::TFMessage tf;
    tf.transforms.push_back(transform(mapFromBase(base_y), "map", "base_link", stamp));
    tf_.publish(tf);
  }
  /// A scan of the moving laser with its base at y, with three beams that say nothing.
  static sensor_msgs::LaserScan movingScan(double base_y, const ros::Time& stamp) {
    sensor_msgs::LaserScan scan =
        scanOf(mapFromBase(base_y) * kBaseFromLaser, kMovingLaser, {{kWall}, {}}, "laser", stamp);
    scan.ranges[0] = std::numeric_limits<float>::quiet_NaN();
    scan.ranges[1] = -std::numeric_limits<float>::infinity();
    scan.ranges[2] = kLaserRangeMin / 2.0f;
    return scan;
  }
  void publishDecayScan(const std::vector<std::string>& topics, bool with_person) {
    mvog_scene::Scene scene{{kWall}, {}};
    if (with_person) scene.boxes.push_back(kPerson);
    const sensor_msgs::LaserScan scan =
        scanOf(kMapFromDecayLaser, kDecayLaser, scene, "decay_laser", ros::Time::now());
    for (const std::string& topic : topics) publisher<sensor_msgs::LaserScan>(topic).publish(scan);
  }
  void publishWallCloud(const std::string& topic) {
    publisher<sensor_msgs::PointCloud2>(topic).publish(wallCloud(ros::Time::now()));
  }

 private:
  ros::NodeHandle nh_;
  ros::Publisher tf_;
  tf2_ros::StaticTransformBroadcaster static_broadcaster_;
  std::map<std::string, ros::Publisher> publishers_;
};

/// Whether `map` answers like the server at every probe.
::testing::AssertionResult answersLikeTheServer(const mvog::Map& map,
                                                const mvog::GetOccupancy::Response& server) {
  if (server.state.size() != kSceneProbes.size()) {
    return ::testing::AssertionFailure() << "the server did not answer: " << server.message;
  }
  for (std::size_t k = 0; k < kSceneProbes.size(); ++k) {
    const mvog::PointOccupancy occupancy = map.occupancy(kSceneProbes[k].point);
    const float probability = occupancy.probability.value_or(std::nanf(""));
    const bool same_probability = std::isnan(probability)
                                      ? std::isnan(server.probability[k])
                                      : std::fabs(probability - server.probability[k]) < 1e-6f;
    if (static_cast<std::uint8_t>(occupancy.state(0.5)) != server.state[k] || !same_probability) {
      return ::testing::AssertionFailure()
             << "at (" << kSceneProbes[k].point.transpose() << "): p = " << probability
             << ", the server says " << server.probability[k];
    }
  }
  return ::testing::AssertionSuccess();
}

// ---- Mapper.*: one server, the whole interface ------------------------------------------------

constexpr std::size_t kScans = 12;
constexpr std::size_t kClouds = 3;

class Mapper : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    std::string name = "/mvog_mapper";
    ros::NodeHandle("~").getParam("mapper", name);
    sensors_ = std::make_unique<SceneSensors>();
    server_ = std::make_unique<MapperClient>(name);
  }
  static void TearDownTestSuite() {
    // Empty the map directory for good: once an empty map is autosaved after the reset, nothing
    // changes, so nothing is saved anymore.
    std::remove(autosavePath().c_str());
    server_->reset();
    EXPECT_TRUE(waitForAutosave());
    std::remove(autosavePath().c_str());
    removeEmptyMapDirectory(server_->name());
    server_.reset();
    sensors_.reset();
  }

  void SetUp() override {
    ASSERT_TRUE(server_->waitUntilReady()) << server_->name() << " did not start";
    ASSERT_TRUE(sensors_->waitForSubscribers<sensor_msgs::LaserScan>("/scan"));
    ASSERT_TRUE(sensors_->waitForSubscribers<sensor_msgs::PointCloud2>("/cloud_in"));
    server_->reset();
  }

  /// Maps the scene: kScans scans while the base moves from y = -0.3 to 0.3, then kClouds
  /// clouds; waits until all are inserted.
  void mapScene() {
    for (std::size_t k = 0; k < kScans; ++k) {
      sensors_->publishMovingScan("/scan", -0.3 + 0.6 * static_cast<double>(k) / (kScans - 1));
    }
    for (std::size_t k = 0; k < kClouds; ++k) sensors_->publishWallCloud("/cloud_in");
    server_->waitForInsertedMessages(kScans + kClouds);
  }

  void expectSceneAnswers() {
    const std::vector<std::uint8_t> states = server_->states(kSceneProbes);
    ASSERT_EQ(states.size(), kSceneProbes.size());
    for (std::size_t k = 0; k < kSceneProbes.size(); ++k) {
      EXPECT_EQ(int{states[k]}, int{kSceneProbes[k].expected})
          << "at (" << kSceneProbes[k].point.transpose() << "): " << kSceneProbes[k].why;
    }
  }

  static std::string mapDirectory() {
    std::string directory;
    EXPECT_TRUE(ros::param::get(server_->name() + "/map_directory", directory));
    return directory;
  }

  /// ~autosave_file, autosave.mvog in mapper_test.yaml.
  static std::string autosavePath() { return mapDirectory() + "/autosave.mvog"; }

  /// Waits until the autosaved file holds the current map: the same bytes as a save of it now.
  /// The map must not change meanwhile.
  static bool waitForAutosave() {
    const std::string reference_path = mapDirectory() + "/autosave_reference.mvog";
    if (!server_->save(reference_path).success) return false;
    const std::string reference = readFile(reference_path);
    std::remove(reference_path.c_str());
    return waitFor([&] { return readFile(autosavePath()) == reference; });
  }

  static std::unique_ptr<SceneSensors> sensors_;
  static std::unique_ptr<MapperClient> server_;
};
std::unique_ptr<SceneSensors> Mapper::sensors_;
std::unique_ptr<MapperClient> Mapper::server_;

TEST_F(Mapper, AnswersOccupiedFreeAndUnknownInTheScene) {
  mapScene();
  expectSceneAnswers();
}

TEST_F(Mapper, CountsReadingsAndDroppedMessages) {
  mapScene();
  // Malformed messages are dropped and counted, and change nothing.
  sensor_msgs::LaserScan bad_scan =
      scanOf(kMapFromDecayLaser, kDecayLaser, {{kWall}, {}}, "decay_laser", ros::Time::now());
  bad_scan.angle_increment = std::numeric_limits<float>::quiet_NaN();
  sensors_->publisher<sensor_msgs::LaserScan>("/scan").publish(bad_scan);
  sensor_msgs::PointCloud2 bad_cloud = wallCloud(ros::Time::now());
  bad_cloud.data.resize(bad_cloud.data.size() / 2);
  sensors_->publisher<sensor_msgs::PointCloud2>("/cloud_in").publish(bad_cloud);
  bad_cloud = wallCloud(ros::Time::now());
  bad_cloud.fields.pop_back();  // no z
  sensors_->publisher<sensor_msgs::PointCloud2>("/cloud_in").publish(bad_cloud);

  const mvog::MapStatistics statistics = server_->waitForStatistics(
      [](const mvog::MapStatistics& s) { return s.messages_dropped_invalid >= 3; });
  EXPECT_EQ(statistics.messages_dropped_invalid, 3u);
  EXPECT_EQ(statistics.messages_inserted, kScans + kClouds);
  EXPECT_EQ(statistics.messages_dropped_tf, 0u);
  EXPECT_EQ(statistics.messages_dropped_queue, 0u);
  EXPECT_EQ(statistics.readings_inserted, kScans * (kMovingLaser.beams() - kSkippedBeamsPerScan) +
                                              kClouds * (kPointsPerCloud - kNaNPointsPerCloud));
  EXPECT_EQ(statistics.readings_rejected,
            kScans * kSkippedBeamsPerScan + kClouds * kNaNPointsPerCloud);
  EXPECT_GT(statistics.rays_walked, 0u);
  EXPECT_LE(statistics.rays_walked, statistics.readings_inserted);
  EXPECT_GT(statistics.positive_volumes, 0u);
  EXPECT_GT(statistics.negative_volumes, 0u);
  EXPECT_GT(statistics.cells_with_volumes, 0u);
  EXPECT_GT(statistics.bytes_held, 0u);
  EXPECT_DOUBLE_EQ(statistics.resolution, kResolution);
  EXPECT_EQ(statistics.header.frame_id, "map");
  expectSceneAnswers();
}

/// The value of `key` in the status `name` of a /diagnostics message, or "" if it is not there.
std::string diagnosticValue(const diagnostic_msgs::DiagnosticArray& array, const std::string& name,
                            const std::string& key) {
  for (const diagnostic_msgs::DiagnosticStatus& status : array.status) {
    if (status.name != name) continue;
    for (const diagnostic_msgs::KeyValue& value : status.values) {
      if (value.key == key) return value.value;
    }
  }
  return "";
}

TEST_F(Mapper, ReportsItsStatisticsOnDiagnostics) {
  ros::NodeHandle nh;
  Inbox<diagnostic_msgs::DiagnosticArray> diagnostics(nh, "/diagnostics");
  mapScene();
  const std::string status = server_->name().substr(1) + ": mapping";  // the node's name
  const std::string inserted = std::to_string(kScans + kClouds);
  EXPECT_TRUE(diagnostics.waitForMessage([&](const diagnostic_msgs::DiagnosticArray& array) {
    return diagnosticValue(array, status, "messages_inserted") == inserted &&
           diagnosticValue(array, status, "messages_dropped_queue") == "0" &&
           !diagnosticValue(array, status, "rays_walked").empty() &&
           diagnosticValue(array, status, "frame_id") == "map";
  })) << "no status '"
      << status << "' with " << inserted << " messages inserted";
}

TEST_F(Mapper, TransformsQueriesGivenInAnotherFrame) {
  mapScene();
  const mvog::GetOccupancy::Response in_map =
      server_->query(toPoints(kSceneProbes, Eigen::Isometry3d::Identity()));
  const mvog::GetOccupancy::Response in_other_frame =
      server_->query(toPoints(kSceneProbes, kMapFromQueryFrame.inverse()), "query_frame");
  ASSERT_TRUE(in_other_frame.success) << in_other_frame.message;
  ASSERT_EQ(in_other_frame.state.size(), kSceneProbes.size());
  for (std::size_t k = 0; k < kSceneProbes.size(); ++k) {
    EXPECT_EQ(int{in_other_frame.state[k]}, int{kSceneProbes[k].expected})
        << "at (" << kSceneProbes[k].point.transpose() << ") in query_frame";
    EXPECT_TRUE(in_other_frame.probability[k] == in_map.probability[k] ||
                (std::isnan(in_other_frame.probability[k]) && std::isnan(in_map.probability[k])));
  }
  const mvog::GetOccupancy::Response explicit_map_frame =
      server_->query(toPoints(kSceneProbes, Eigen::Isometry3d::Identity()), "map");
  EXPECT_TRUE(explicit_map_frame.success);
  EXPECT_EQ(explicit_map_frame.state, in_map.state);
}

TEST_F(Mapper, AnswersUnknownAtNaNAndRefusesWhatItCannotAnswer) {
  mapScene();
  geometry_msgs::Point nan_point;
  nan_point.x = std::nan("");
  nan_point.y = 0.05;
  nan_point.z = kLaserHeight;
  geometry_msgs::Point wall_point;
  wall_point.x = 3.05;
  wall_point.y = 0.05;
  wall_point.z = kLaserHeight;
  mvog::GetOccupancy::Response response = server_->query({nan_point, wall_point});
  ASSERT_TRUE(response.success) << response.message;
  EXPECT_EQ(response.state, (std::vector<std::uint8_t>{kUnknown, kOccupied}));
  EXPECT_TRUE(std::isnan(response.probability[0]));
  EXPECT_GT(response.probability[1], 0.5f);

  // ~max_query_points is 50 in mapper_test.yaml.
  response = server_->query(std::vector<geometry_msgs::Point>(50, wall_point));
  EXPECT_TRUE(response.success) << response.message;
  EXPECT_EQ(response.state.size(), 50u);
  response = server_->query(std::vector<geometry_msgs::Point>(51, wall_point));
  EXPECT_FALSE(response.success);
  EXPECT_TRUE(response.state.empty());
  EXPECT_NE(response.message.find("~max_query_points"), std::string::npos) << response.message;

  response = server_->query({wall_point}, "no_such_frame");
  EXPECT_FALSE(response.success);
  EXPECT_TRUE(response.state.empty());
  EXPECT_NE(response.message.find("'no_such_frame'"), std::string::npos) << response.message;
}

TEST_F(Mapper, WaitsForTransformsThatComeLate) {
  // The base's pose comes after the scan (the pause only makes that order likely).
  const ros::Time stamp = ros::Time::now();
  sensors_->publisher<sensor_msgs::LaserScan>("/scan").publish(
      SceneSensors::movingScan(0.0, stamp));
  ros::WallDuration(0.2).sleep();
  sensors_->publishBasePose(0.0, stamp);
  server_->waitForInsertedMessages(1);
  // A tf1-style frame id with a leading slash is fine; a message without frame id is dropped.
  sensor_msgs::LaserScan scan =
      scanOf(kMapFromDecayLaser, kDecayLaser, {{kWall}, {}}, "/decay_laser", ros::Time::now());
  sensors_->publisher<sensor_msgs::LaserScan>("/scan").publish(scan);
  scan.header.frame_id.clear();
  sensors_->publisher<sensor_msgs::LaserScan>("/scan").publish(scan);
  const mvog::MapStatistics statistics = server_->waitForStatistics(
      [](const mvog::MapStatistics& s) { return s.messages_dropped_tf >= 1; });
  EXPECT_EQ(statistics.messages_dropped_tf, 1u);
  server_->waitForInsertedMessages(2);
  EXPECT_EQ(server_->state({3.05, 0.05, kLaserHeight}), kOccupied);
  EXPECT_EQ(server_->state({1.55, 0.05, kLaserHeight}), kFree);
}

/// The value of a grid at a world point, or -2 if the point is outside it.
int gridValueAt(const nav_msgs::OccupancyGrid& grid, double x, double y) {
  const double column = std::floor((x - grid.info.origin.position.x) / grid.info.resolution);
  const double row = std::floor((y - grid.info.origin.position.y) / grid.info.resolution);
  if (column < 0 || row < 0 || column >= grid.info.width || row >= grid.info.height) return -2;
  return grid
      .data[static_cast<std::size_t>(row) * grid.info.width + static_cast<std::size_t>(column)];
}

/// A grid of the scene at the laser's height (or a projection of every height): occupied at the
/// wall (p > 0.5: rays grazing the wall's cells lower it a little), free before, unknown behind.
bool showsTheSceneAtLaserHeight(const nav_msgs::OccupancyGrid& grid) {
  return grid.header.frame_id == "map" && std::fabs(grid.info.resolution - kResolution) < 1e-6 &&
         grid.data.size() == std::size_t{grid.info.width} * grid.info.height &&
         gridValueAt(grid, 3.05, 0.05) > 50 && gridValueAt(grid, 1.55, 0.05) == 0 &&
         gridValueAt(grid, 4.05, 0.05) == -1;
}

bool onCellEdges(const std::vector<geometry_msgs::Point>& points) {
  return std::all_of(points.begin(), points.end(), [](const geometry_msgs::Point& p) {
    return std::fabs(p.x / kResolution - std::round(p.x / kResolution)) < 1e-4 &&
           std::fabs(p.y / kResolution - std::round(p.y / kResolution)) < 1e-4;
  });
}

/// Whether the markers received so far hold non-empty boxes of namespace `ns`, all of them in
/// the map frame and on cell edges.
bool haveBoxes(const std::vector<boost::shared_ptr<const visualization_msgs::MarkerArray>>& all,
               const std::string& ns) {
  bool found = false;
  for (const auto& array : all) {
    for (const visualization_msgs::Marker& marker : array->markers) {
      if (marker.header.frame_id != "map") return false;
      if (marker.ns != ns || marker.action != visualization_msgs::Marker::ADD) continue;
      if (marker.type != visualization_msgs::Marker::TRIANGLE_LIST || marker.points.empty() ||
          marker.points.size() % 36 != 0 || !onCellEdges(marker.points)) {
        return false;
      }
      found = true;
    }
  }
  return found;
}

TEST_F(Mapper, PublishesMarkersAndGridsInTheMapFrame) {
  ros::NodeHandle nh;
  const std::string& name = server_->name();
  Inbox<visualization_msgs::MarkerArray> volumes(nh, name + "/volumes");
  Inbox<visualization_msgs::MarkerArray> occupied(nh, name + "/occupied");
  Inbox<nav_msgs::OccupancyGrid> projected_map(nh, name + "/projected_map");
  Inbox<nav_msgs::OccupancyGrid> cross_section(nh, name + "/cross_section_0");
  Inbox<map_msgs::OccupancyGridUpdate> projected_map_updates(nh, name + "/projected_map_updates");
  mapScene();

  EXPECT_TRUE(volumes.waitForAll([](const auto& all) { return haveBoxes(all, "positive"); }));
  EXPECT_TRUE(volumes.waitForAll([](const auto& all) { return haveBoxes(all, "negative"); }));
  EXPECT_TRUE(occupied.waitForAll([](const auto& all) { return haveBoxes(all, "occupied"); }));
  for (const auto& array : occupied.messages()) {
    for (const visualization_msgs::Marker& marker : array->markers) {
      EXPECT_EQ(marker.colors.size(), marker.points.size());  // coloured by height
    }
  }
  // ~cross_section_heights is [0.55] in mapper_test.yaml: the laser's plane.
  EXPECT_TRUE(cross_section.waitForMessage(showsTheSceneAtLaserHeight));
  EXPECT_TRUE(cross_section.waitForMessage([](const nav_msgs::OccupancyGrid& grid) {
    return std::fabs(grid.info.origin.position.z - kLaserHeight) < 1e-9;
  }));
  EXPECT_TRUE(projected_map.waitForMessage(showsTheSceneAtLaserHeight));

  // Further readings inside the grid arrive as updates: the laser scans again from elsewhere.
  // The first scan's changes may be published together with the last clouds' that grew the grid
  // (a grid laid out anew is sent whole, without an update), or before this subscription is
  // connected (on a loaded machine): the laser then scans once more from the same place, well
  // inside the grid.
  const std::size_t updates_before = projected_map_updates.size();
  const auto updated = [&](const auto& all) {
    return all.size() > updates_before && all.back()->header.frame_id == "map" &&
           all.back()->data.size() == std::size_t{all.back()->width} * all.back()->height;
  };
  constexpr int kAttempts = 3;
  bool received = false;
  for (int attempt = 1; attempt <= kAttempts && !received; ++attempt) {
    sensors_->publishMovingScan("/scan", 1.0);
    server_->waitForInsertedMessages(kScans + kClouds + attempt);
    received = projected_map_updates.waitForAll(updated);
  }
  EXPECT_TRUE(received);
}

TEST_F(Mapper, CutsCrossSectionsOnRequest) {
  mapScene();
  mvog::GetCrossSection::Request request;
  request.height = kLaserHeight;
  mvog::GetCrossSection::Response response = server_->crossSection(request);
  ASSERT_TRUE(response.success) << response.message;
  EXPECT_TRUE(showsTheSceneAtLaserHeight(response.map));
  EXPECT_DOUBLE_EQ(response.map.info.origin.position.z, kLaserHeight);

  request.use_bounds = true;
  request.min_x = 2.5;
  request.min_y = -0.45;
  request.max_x = 3.45;
  request.max_y = 0.45;
  response = server_->crossSection(request);
  ASSERT_TRUE(response.success) << response.message;
  EXPECT_EQ(response.map.header.frame_id, "map");
  EXPECT_EQ(response.map.info.width, 10u);   // cells 25..34
  EXPECT_EQ(response.map.info.height, 10u);  // cells -5..4
  EXPECT_NEAR(response.map.info.origin.position.x, 2.5, 1e-9);
  EXPECT_NEAR(response.map.info.origin.position.y, -0.5, 1e-9);
  EXPECT_GT(gridValueAt(response.map, 3.05, 0.05), 50);
  EXPECT_EQ(gridValueAt(response.map, 2.55, 0.05), 0);
  EXPECT_EQ(gridValueAt(response.map, 3.35, 0.05), -1);

  request.height = 20.0;  // nothing seen up there
  response = server_->crossSection(request);
  ASSERT_TRUE(response.success) << response.message;
  EXPECT_TRUE(std::all_of(response.map.data.begin(), response.map.data.end(),
                          [](std::int8_t value) { return value == -1; }));

  request.height = std::nan("");
  response = server_->crossSection(request);
  EXPECT_FALSE(response.success);
  EXPECT_FALSE(response.message.empty());
  request.height = kLaserHeight;
  request.min_x = 4.0;  // above max_x
  response = server_->crossSection(request);
  EXPECT_FALSE(response.success);
  EXPECT_FALSE(response.message.empty());
}

TEST_F(Mapper, PublishesTheBinaryMap) {
  mapScene();
  const mvog::GetOccupancy::Response expected =
      server_->query(toPoints(kSceneProbes, Eigen::Isometry3d::Identity()));
  ASSERT_TRUE(expected.success);
  ros::NodeHandle nh;
  Inbox<mvog::MapBinary> binary(nh, server_->name() + "/map");
  ::testing::AssertionResult last_difference = ::testing::AssertionFailure() << "no message";
  const bool received = binary.waitForMessage([&](const mvog::MapBinary& message) {
    if (message.header.frame_id != "map" || message.format_version != mvog::kMapFormatVersion ||
        message.resolution != kResolution) {
      last_difference = ::testing::AssertionFailure() << "wrong header";
      return false;
    }
    const mvog::Map map = mvog::deserializeMap(message.data.data(), message.data.size());
    last_difference = answersLikeTheServer(map, expected);
    return static_cast<bool>(last_difference);
  });
  EXPECT_TRUE(received) << last_difference.message();
}

TEST_F(Mapper, SavesResetsAndLoads) {
  mapScene();
  const std::vector<geometry_msgs::Point> probes =
      toPoints(kSceneProbes, Eigen::Isometry3d::Identity());
  const mvog::GetOccupancy::Response mapped = server_->query(probes);
  const std::string directory = mapDirectory();

  mvog::MapFile::Response response = server_->save("rostest_map.mvog");
  ASSERT_TRUE(response.success) << response.message;
  server_->reset();
  const mvog::GetOccupancy::Response empty = server_->query(probes);
  EXPECT_TRUE(std::all_of(empty.state.begin(), empty.state.end(),
                          [](std::uint8_t state) { return state == kUnknown; }));
  response = server_->load("rostest_map.mvog");
  ASSERT_TRUE(response.success) << response.message;
  const mvog::GetOccupancy::Response loaded = server_->query(probes);
  EXPECT_EQ(loaded.state, mapped.state);
  const mvog::Map saved = mvog::loadMap(directory + "/rostest_map.mvog");
  EXPECT_TRUE(answersLikeTheServer(saved, loaded));

  // Paths outside ~map_directory are refused both ways.
  char outside_pattern[] = "/tmp/mvog_rostest_outside_XXXXXX";
  ASSERT_NE(::mkdtemp(outside_pattern), nullptr);
  const std::string outside = outside_pattern;
  std::ofstream(outside + "/copy.mvog", std::ios::binary)
      << std::ifstream(directory + "/rostest_map.mvog", std::ios::binary).rdbuf();
  for (const std::string& path :
       {outside + "/copy.mvog", outside + "/new.mvog", std::string("../rostest_escape.mvog"),
        std::string("/etc/passwd"), std::string("")}) {
    EXPECT_FALSE(server_->save(path).success) << "saved to '" << path << "'";
    EXPECT_FALSE(server_->load(path).success) << "loaded from '" << path << "'";
  }
  EXPECT_EQ(std::system(("rm -rf '" + outside + "'").c_str()), 0);
  EXPECT_FALSE(server_->load("missing.mvog").success);

  // A corrupted, a truncated and a foreign file are refused, and the map stays as it was.
  const std::string bytes = readFile(directory + "/rostest_map.mvog");
  ASSERT_GT(bytes.size(), 100u);
  std::string corrupted = bytes;
  corrupted[bytes.size() / 2] = static_cast<char>(corrupted[bytes.size() / 2] ^ 0x10);
  const std::vector<std::pair<std::string, std::string>> bad_files = {
      {"corrupted.mvog", corrupted},
      {"truncated.mvog", bytes.substr(0, bytes.size() / 2)},
      {"foreign.mvog", std::string(1000, 'x')},
      {"empty.mvog", ""}};
  for (const auto& bad : bad_files) {
    std::ofstream(directory + "/" + bad.first, std::ios::binary) << bad.second;
    response = server_->load(bad.first);
    EXPECT_FALSE(response.success) << bad.first;
    EXPECT_FALSE(response.message.empty()) << bad.first;
    EXPECT_EQ(server_->query(probes).state, mapped.state) << "after loading " << bad.first;
    std::remove((directory + "/" + bad.first).c_str());
  }
  std::remove((directory + "/rostest_map.mvog").c_str());
}

TEST_F(Mapper, AutosavesTheMap) {
  std::remove(autosavePath().c_str());  // whatever the previous tests left: the same scene
  mapScene();
  EXPECT_TRUE(waitForAutosave());
}

bool allUnknown(const nav_msgs::OccupancyGrid& grid) {
  return !grid.data.empty() && std::all_of(grid.data.begin(), grid.data.end(),
                                           [](std::int8_t value) { return value == -1; });
}

TEST_F(Mapper, ClearsWhatItPublishedOnResetAndStartsAfresh) {
  ros::NodeHandle nh;
  const std::string& name = server_->name();
  Inbox<visualization_msgs::MarkerArray> volumes(nh, name + "/volumes");
  Inbox<nav_msgs::OccupancyGrid> projected_map(nh, name + "/projected_map");
  mapScene();
  ASSERT_TRUE(projected_map.waitForMessage(showsTheSceneAtLaserHeight));
  ASSERT_TRUE(volumes.waitForAll([](const auto& all) { return haveBoxes(all, "positive"); }));

  const std::size_t volumes_before_reset = volumes.size();
  const std::size_t grids_before_reset = projected_map.size();
  server_->reset();
  EXPECT_TRUE(volumes.waitForMessage(
      [](const visualization_msgs::MarkerArray& array) {
        return array.markers.size() == 1 &&
               array.markers[0].action == visualization_msgs::Marker::DELETEALL &&
               array.markers[0].header.frame_id == "map";
      },
      volumes_before_reset));
  EXPECT_TRUE(projected_map.waitForMessage(allUnknown, grids_before_reset));
  // A subscriber arriving now is not shown the previous map.
  Inbox<nav_msgs::OccupancyGrid> late_subscriber(nh, name + "/projected_map");
  EXPECT_TRUE(late_subscriber.waitForAll([](const auto& all) { return !all.empty(); }));
  for (const auto& grid : late_subscriber.messages()) EXPECT_TRUE(allUnknown(*grid));

  // Mapping again publishes the new map.
  mapScene();
  EXPECT_TRUE(late_subscriber.waitForMessage(showsTheSceneAtLaserHeight));
  expectSceneAnswers();
}

TEST_F(Mapper, KeepsServingAMapTooWideForItsGrids) {
  // One reading 2 km away: the grids would need 400 million cells, more than the core can
  // evaluate and than ~max_cross_section_cells (16 million by default) allows.
  ros::NodeHandle nh;
  Inbox<visualization_msgs::MarkerArray> occupied(nh, server_->name() + "/occupied");
  Inbox<nav_msgs::OccupancyGrid> projected_map(nh, server_->name() + "/projected_map");
  mapScene();
  const Eigen::Vector3d far_away(2000.05, 2000.05, 1.55);
  sensors_->publisher<sensor_msgs::PointCloud2>("/cloud_in")
      .publish(cameraCloud({far_away}, ros::Time::now()));
  server_->waitForInsertedMessages(kScans + kClouds + 1);
  // Its marker is published, and the grids are brought up to date right after.
  EXPECT_TRUE(occupied.waitForAll([](const auto& all) {
    return std::any_of(all.begin(), all.end(), [](const auto& array) {
      return std::any_of(array->markers.begin(), array->markers.end(), [](const auto& marker) {
        return !marker.points.empty() && marker.points[0].x > 1000.0;
      });
    });
  }));
  EXPECT_EQ(server_->state(far_away), kOccupied);
  expectSceneAnswers();
  for (const auto& grid : projected_map.messages()) {
    EXPECT_LE(grid->data.size(), 16000000u);
  }
  mvog::GetCrossSection::Request request;
  request.height = kLaserHeight;
  const mvog::GetCrossSection::Response response = server_->crossSection(request);
  EXPECT_FALSE(response.success);
  EXPECT_NE(response.message.find("~max_cross_section_cells"), std::string::npos)
      << response.message;
}

// ---- Decay.*: a person who walked through ------------------------------------------------------

TEST(Decay, ClearsAPersonWhoLeftWithinAFewScansOnlyWithDecay) {
  MapperClient with_decay("/with_decay/mvog_mapper");
  MapperClient without_decay("/without_decay/mvog_mapper");
  SceneSensors sensors;
  const std::vector<std::string> topics = {"/with_decay/scan", "/without_decay/scan"};
  for (MapperClient* server : {&with_decay, &without_decay}) {
    ASSERT_TRUE(server->waitUntilReady()) << server->name();
  }
  ASSERT_TRUE(sensors.waitForSubscribers<sensor_msgs::LaserScan>(topics[0]));
  ASSERT_TRUE(sensors.waitForSubscribers<sensor_msgs::LaserScan>(topics[1]));
  const Eigen::Vector3d person(1.45, 0.05, kLaserHeight);  // the cell of its front face

  // The person stands in the beams for a while: both maps see it.
  constexpr std::uint64_t kScansWithPerson = 20;
  for (std::uint64_t k = 1; k <= kScansWithPerson; ++k) {
    sensors.publishDecayScan(topics, true);
    with_decay.waitForInsertedMessages(k);
    without_decay.waitForInsertedMessages(k);
  }
  ASSERT_EQ(with_decay.state(person), kOccupied);
  ASSERT_EQ(without_decay.state(person), kOccupied);

  // The person leaves. Scans come at a pace that lets decay periods (0.2 s) pass: the spot must
  // turn free within a few scans with decay, and still be occupied after them without.
  constexpr std::uint64_t kScansWithoutPerson = 10;
  constexpr std::uint64_t kMaxScansWithDecay = 6;
  std::uint64_t free_with_decay = 0;
  std::uint64_t free_without_decay = 0;
  for (std::uint64_t k = 1; k <= kScansWithoutPerson; ++k) {
    ros::WallDuration(0.4).sleep();  // time for decay to act, not a wait for a condition
    sensors.publishDecayScan(topics, false);
    with_decay.waitForInsertedMessages(kScansWithPerson + k);
    without_decay.waitForInsertedMessages(kScansWithPerson + k);
    if (free_with_decay == 0 && with_decay.state(person) == kFree) free_with_decay = k;
    if (free_without_decay == 0 && without_decay.state(person) == kFree) free_without_decay = k;
  }
  EXPECT_GE(free_with_decay, 1u) << "still occupied after " << kScansWithoutPerson << " scans";
  EXPECT_LE(free_with_decay, kMaxScansWithDecay);
  EXPECT_EQ(free_without_decay, 0u) << "free after " << free_without_decay << " scans";
  EXPECT_EQ(with_decay.state(person), kFree);
  EXPECT_EQ(without_decay.state(person), kOccupied);
  RecordProperty("scans_until_free_with_decay", static_cast<int>(free_with_decay));
  removeEmptyMapDirectory(with_decay.name());
  removeEmptyMapDirectory(without_decay.name());
}

// ---- RefusedStart.*: invalid parameters -----------------------------------------------------

struct ProcessResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr
};

/// Runs a command line under `timeout`, so that a server that starts instead of refusing ends
/// the test with a failure rather than a hang.
ProcessResult run(const std::string& command) {
  ProcessResult result;
  FILE* pipe = ::popen(("timeout -s INT 20 " + command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return result;
  std::array<char, 4096> buffer{};
  for (std::size_t n; (n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0;) {
    result.output.append(buffer.data(), n);
  }
  const int status = ::pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

/// mvog_node, built next to this test.
std::string nodeExecutable() {
  char path[PATH_MAX] = {};
  const ssize_t length = ::readlink("/proc/self/exe", path, sizeof(path) - 1);
  std::string self(path, length > 0 ? static_cast<std::size_t>(length) : 0);
  return self.substr(0, self.find_last_of('/') + 1) + "mvog_node";
}

struct InvalidStart {
  std::string node_name;
  std::string parameters;  // command-line private parameters
  std::string expected;    // in the output
};

TEST(RefusedStart, TheNodeRefusesInvalidParametersNamingThem) {
  const std::string directory = "/tmp/mvog_rostest_refused_" + std::to_string(::getpid());
  const std::vector<InvalidStart> cases = {
      {"refused_resolution", "_resolution:=-1.0", "~resolution"},
      {"refused_zero_resolution", "_resolution:=0", "~resolution"},
      {"refused_fraction", "_max_query_points:=1.5", "~max_query_points: must be an integer"},
      {"refused_type", "_insert_out_of_range:=1", "~insert_out_of_range: has the wrong type"},
      {"refused_frame", "_frame_id:=/map", "~frame_id"},
      {"refused_decay", "_decay_factor:=1.5", "~decay_factor"},
      {"refused_ranges", "_min_range:=5.0 _max_range:=2.0", "~min_range"},
      {"refused_free_space_rays", "_free_space_rays:=every-reading", "~free_space_rays"},
      {"refused_map_file", "_map_file:=missing.mvog", "~map_file"},
      {"refused_map_directory", "_map_directory:=/proc/mvog_cannot_be_here", "~map_directory"},
  };
  for (const InvalidStart& invalid : cases) {
    std::string parameters = invalid.parameters;
    if (parameters.find("_map_directory") == std::string::npos) {
      parameters += " _map_directory:=" + directory;
    }
    const ProcessResult result =
        run(nodeExecutable() + " __name:=" + invalid.node_name + " " + parameters);
    EXPECT_EQ(result.exit_code, 1) << invalid.parameters << ":\n" << result.output;
    EXPECT_NE(result.output.find(invalid.expected), std::string::npos)
        << invalid.parameters << ":\n"
        << result.output;
  }
  EXPECT_EQ(std::system(("rm -rf '" + directory + "'").c_str()), 0);
}

TEST(RefusedStart, TheNodeletRefusesInvalidParametersAndTheManagerCarriesOn) {
  const std::string manager = "/refusal_manager";
  ASSERT_TRUE(ros::service::waitForService(manager + "/list", ros::Duration(kTimeout)));
  const ProcessResult refused = run("rosrun nodelet nodelet load mvog/MapperNodelet " + manager +
                                    " __name:=refused_nodelet _resolution:=-1.0 --no-bond");
  EXPECT_NE(refused.exit_code, 0) << refused.output;
  nodelet::NodeletList list;
  ASSERT_TRUE(ros::service::call(manager + "/list", list)) << "the manager died";
  EXPECT_EQ(
      std::count(list.response.nodelets.begin(), list.response.nodelets.end(), "/refused_nodelet"),
      0);
}

}  // namespace

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_mapper_node");
  ros::AsyncSpinner spinner(2);
  spinner.start();
  return RUN_ALL_TESTS();
}
