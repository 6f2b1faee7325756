// Rostest node asking a running mapping server (planning.test) what planners and explorers ask:
// ~check_segments, ~check_boxes, ~frontiers, ~frontier_markers, ~surfaces and ~traversable_map.
//
// Two rooms of known geometry (test/core/planning_scene.h): the room built cell by cell
// (walls, a desk whose board spans [0.7, 0.8] m, a door, nothing seen beyond y = 3 m), written to
// a map file and given to ~load_map, where every answer is known exactly; and the scanned room,
// whose scans the test sends as PointCloud2 (their obstacle readings: a cloud carries no
// out-of-range reading), where the answers are known within a cell and the published outputs
// must follow the map as it grows. The bad requests are in test/reliability/test_bad_input.py.
// Every wait is for a condition, with a timeout; nothing asserts how long anything took.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include <map_msgs/OccupancyGridUpdate.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <std_srvs/Trigger.h>
#include <tf2_eigen/tf2_eigen.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <visualization_msgs/MarkerArray.h>
#include <Eigen/Geometry>

#include "../core/planning_scene.h"
#include "mvog/CheckBoxes.h"
#include "mvog/CheckSegments.h"
#include "mvog/MapFile.h"
#include "mvog/MapStatistics.h"
#include "mvog/checks.h"
#include "mvog/map_io.h"

namespace {

constexpr double kTimeout = 30.0;  // s, for any awaited message
constexpr double kCell = mvog::test::kSceneResolution;
const std::string kServer = "/mvog_mapper";
const std::string kRoomFile = "planning_room.mvog";
constexpr std::uint8_t kUnknown = mvog::CheckSegments::Response::UNKNOWN;
constexpr std::uint8_t kFree = mvog::CheckSegments::Response::FREE;
constexpr std::uint8_t kOccupied = mvog::CheckSegments::Response::OCCUPIED;

/// Where requests in another frame are asked from: a quarter turn about z and a shift.
const Eigen::Isometry3d kMapFromQueryFrame =
    Eigen::Translation3d(1.0, 2.0, 0.5) * Eigen::AngleAxisd(M_PI / 2.0, Eigen::Vector3d::UnitZ());

/// The latest message of a topic, and a wait for one that a condition accepts.
template <class Message>
class Latest {
 public:
  explicit Latest(const std::string& topic)
      : subscriber_(ros::NodeHandle().subscribe(topic, 10, &Latest::receive, this)) {}
  Latest(const Latest&) = delete;
  Latest& operator=(const Latest&) = delete;

  /// The first message (from now or the latest one received) that `accept` takes, or null after
  /// kTimeout s.
  boost::shared_ptr<const Message> await(const std::function<bool(const Message&)>& accept) {
    std::unique_lock<std::mutex> lock(mutex_);
    const bool found = received_.wait_for(lock, std::chrono::duration<double>(kTimeout),
                                          [&] { return latest_ && accept(*latest_); });
    return found ? latest_ : nullptr;
  }

 private:
  void receive(const boost::shared_ptr<const Message>& message) {
    std::lock_guard<std::mutex> lock(mutex_);
    latest_ = message;
    received_.notify_all();
  }

  std::mutex mutex_;
  std::condition_variable received_;
  boost::shared_ptr<const Message> latest_;
  ros::Subscriber subscriber_;
};

geometry_msgs::Point pointOf(const Eigen::Vector3d& p) {
  geometry_msgs::Point point;
  point.x = p.x();
  point.y = p.y();
  point.z = p.z();
  return point;
}

template <class Service>
typename Service::Response call(const std::string& name, typename Service::Request request) {
  Service service;
  service.request = request;
  EXPECT_TRUE(ros::service::call(kServer + "/" + name, service)) << name << " failed";
  return service.response;
}

/// Segments (map frame) checked in `frame_id`: their points are given in that frame.
mvog::CheckSegments::Response checkSegments(const std::vector<mvog::Segment>& segments,
                                            double radius, const std::string& frame_id = "") {
  const Eigen::Isometry3d frame_from_map =
      frame_id.empty() ? Eigen::Isometry3d::Identity() : kMapFromQueryFrame.inverse();
  mvog::CheckSegments::Request request;
  request.frame_id = frame_id;
  request.radius = radius;
  for (const mvog::Segment& segment : segments) {
    request.starts.push_back(pointOf(frame_from_map * segment.start));
    request.ends.push_back(pointOf(frame_from_map * segment.end));
  }
  return call<mvog::CheckSegments>("check_segments", request);
}

mvog::CheckBoxes::Response checkBoxes(const std::vector<mvog::Box>& boxes) {
  mvog::CheckBoxes::Request request;
  for (const mvog::Box& box : boxes) {
    request.min_corners.push_back(pointOf(box.min));
    request.max_corners.push_back(pointOf(box.max));
  }
  return call<mvog::CheckBoxes>("check_boxes", request);
}

/// The points of a cloud, field by field (float32 fields).
std::vector<std::vector<float>> pointsOf(const sensor_msgs::PointCloud2& cloud,
                                         const std::vector<std::string>& fields) {
  std::vector<std::vector<float>> points(std::size_t{cloud.width} * cloud.height);
  // sensor_msgs' iterators take data.front(), undefined on an empty cloud (UBSan reports it).
  if (points.empty()) return points;
  for (const std::string& field : fields) {
    sensor_msgs::PointCloud2ConstIterator<float> value(cloud, field);
    for (std::vector<float>& point : points) point.push_back(*value), ++value;
  }
  return points;
}

/// The value of a grid at a world point, or -2 outside it.
int valueAt(const nav_msgs::OccupancyGrid& grid, double x, double y) {
  const auto column = static_cast<std::int64_t>(
      std::floor((x - grid.info.origin.position.x) / grid.info.resolution));
  const auto row = static_cast<std::int64_t>(
      std::floor((y - grid.info.origin.position.y) / grid.info.resolution));
  if (column < 0 || row < 0 || column >= grid.info.width || row >= grid.info.height) return -2;
  return grid.data[static_cast<std::size_t>(row * grid.info.width + column)];
}

class Planning : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    for (const std::string service :
         {"check_segments", "check_boxes", "load_map", "reset", "save_map"}) {
      ASSERT_TRUE(ros::service::waitForService(kServer + "/" + service, ros::Duration(kTimeout)))
          << service;
    }
    ASSERT_TRUE(ros::param::get(kServer + "/map_directory", map_directory_));
    mvog::saveMap(mvog::test::sceneMap(), map_directory_ + "/" + kRoomFile);
    broadcaster_ = std::make_unique<tf2_ros::StaticTransformBroadcaster>();
    sendStaticTransform(kMapFromQueryFrame, "query_frame");
  }
  static void TearDownTestSuite() {
    std::remove((map_directory_ + "/" + kRoomFile).c_str());
    ::rmdir(map_directory_.c_str());
    broadcaster_.reset();
  }

  /// map -> `frame`, kept with the others sent (one broadcaster: /tf_static latches its last).
  static void sendStaticTransform(const Eigen::Isometry3d& map_from_frame,
                                  const std::string& frame) {
    geometry_msgs::TransformStamped transform = tf2::eigenToTransform(map_from_frame);
    transform.header.frame_id = "map";
    transform.header.stamp = ros::Time::now();
    transform.child_frame_id = frame;
    broadcaster_->sendTransform(transform);
  }

  void SetUp() override {
    const std_srvs::Trigger::Response reset = call<std_srvs::Trigger>("reset", {});
    ASSERT_TRUE(reset.success) << reset.message;
  }

  /// The room built cell by cell, through ~load_map.
  static void loadRoom() {
    mvog::MapFile::Request request;
    request.path = kRoomFile;
    const mvog::MapFile::Response loaded = call<mvog::MapFile>("load_map", request);
    ASSERT_TRUE(loaded.success) << loaded.message;
  }

  static std::string map_directory_;
  static std::unique_ptr<tf2_ros::StaticTransformBroadcaster> broadcaster_;
};
std::string Planning::map_directory_;
std::unique_ptr<tf2_ros::StaticTransformBroadcaster> Planning::broadcaster_;

// ---- The room built cell by cell: exact answers -------------------------------------------------

TEST_F(Planning, SegmentsThroughAWallTheOpenRoomAndIntoNeverSeenSpace) {
  loadRoom();
  const mvog::CheckSegments::Response response = checkSegments(
      {
          {{2.0, 0.55, 1.0}, {4.5, 0.55, 1.0}},  // through the wall x = 4.0, 2 m on
          {{0.5, 0.4, 1.2}, {3.5, 1.5, 1.5}},    // across the room, over the desk
          {{2.5, 2.5, 1.0}, {2.5, 3.5, 1.0}},    // beyond y = 3.0, never seen, 0.5 m on
      },
      0.0);
  ASSERT_TRUE(response.success) << response.message;
  EXPECT_EQ(response.state, (std::vector<std::uint8_t>{kOccupied, kFree, kUnknown}));
  ASSERT_EQ(response.blocked_at.size(), 3u);
  EXPECT_NEAR(response.blocked_at[0], 2.0, kCell);
  EXPECT_TRUE(std::isnan(response.blocked_at[1]));
  EXPECT_NEAR(response.blocked_at[2], 0.5, kCell);
}

TEST_F(Planning, ARadiusCatchesAWallTheBareSegmentMisses) {
  loadRoom();
  // Towards the wall x = 4.0, stopping 0.15 m before it.
  const mvog::Segment segment{{3.0, 0.55, 1.0}, {3.85, 0.55, 1.0}};
  const mvog::CheckSegments::Response bare = checkSegments({segment}, 0.0);
  ASSERT_TRUE(bare.success) << bare.message;
  EXPECT_EQ(bare.state, std::vector<std::uint8_t>{kFree});
  const mvog::CheckSegments::Response wide = checkSegments({segment}, 0.2);
  ASSERT_TRUE(wide.success) << wide.message;
  EXPECT_EQ(wide.state, std::vector<std::uint8_t>{kOccupied});
  EXPECT_NEAR(wide.blocked_at.at(0), 0.8, 1e-9);  // the sphere's centre at x = 3.8
}

TEST_F(Planning, BoxesOnTheDeskInTheAirAndHalfSeen) {
  loadRoom();
  const mvog::CheckBoxes::Response response = checkBoxes({
      {{1.2, 0.7, 0.75}, {1.5, 1.0, 1.0}},  // on the desk, its board within
      {{2.5, 2.0, 1.0}, {2.9, 2.5, 1.5}},   // in the room's air
      {{1.0, 2.8, 1.0}, {1.5, 3.2, 1.5}},   // known up to y = 3.0: half of it
      {{1.0, 5.0, 1.0}, {1.5, 5.5, 1.5}},   // nothing known
  });
  ASSERT_TRUE(response.success) << response.message;
  EXPECT_EQ(response.state, (std::vector<std::uint8_t>{kOccupied, kFree, kUnknown, kUnknown}));
  ASSERT_EQ(response.known_fraction.size(), 4u);
  ASSERT_EQ(response.max_probability.size(), 4u);
  EXPECT_NEAR(response.known_fraction[0], 1.0, 1e-6);
  EXPECT_NEAR(response.max_probability[0], 5.0 / 5.1, 1e-6);  // the board: rho+ 5, rho- 0.1
  EXPECT_NEAR(response.known_fraction[1], 1.0, 1e-6);
  EXPECT_EQ(response.max_probability[1], 0.0);
  EXPECT_NEAR(response.known_fraction[2], 0.5, 1e-6);
  EXPECT_EQ(response.known_fraction[3], 0.0);
  EXPECT_TRUE(std::isnan(response.max_probability[3]));
}

TEST_F(Planning, AnswersRequestsGivenInAnotherFrame) {
  loadRoom();
  // Once the server has the frame's transform, an empty request succeeds.
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(kTimeout);
  while (!checkSegments({}, 0.0, "query_frame").success && ros::WallTime::now() < deadline) {
    ros::WallDuration(0.05).sleep();
  }
  const std::vector<mvog::Segment> segments = {{{2.0, 0.55, 1.0}, {4.5, 0.55, 1.0}},
                                               {{0.5, 0.4, 1.2}, {3.5, 1.5, 1.5}},
                                               {{3.0, 0.55, 1.0}, {3.85, 0.55, 1.0}}};
  const mvog::CheckSegments::Response in_map = checkSegments(segments, 0.2);
  const mvog::CheckSegments::Response in_frame = checkSegments(segments, 0.2, "query_frame");
  ASSERT_TRUE(in_frame.success) << in_frame.message;
  EXPECT_EQ(in_frame.state, in_map.state);
  ASSERT_EQ(in_frame.blocked_at.size(), segments.size());
  for (std::size_t k = 0; k < segments.size(); ++k) {
    EXPECT_TRUE(std::isnan(in_map.blocked_at[k])
                    ? std::isnan(in_frame.blocked_at[k])
                    : std::abs(in_frame.blocked_at[k] - in_map.blocked_at[k]) < 1e-6)
        << "segment " << k;
  }
  // A box on the desk, given in the turned frame: its corners swap their roles in x.
  const Eigen::Isometry3d frame_from_map = kMapFromQueryFrame.inverse();
  mvog::CheckBoxes::Request request;
  request.frame_id = "query_frame";
  const Eigen::Vector3d a = frame_from_map * Eigen::Vector3d(1.2, 0.7, 0.75);
  const Eigen::Vector3d b = frame_from_map * Eigen::Vector3d(1.5, 1.0, 1.0);
  request.min_corners.push_back(pointOf(a.cwiseMin(b)));
  request.max_corners.push_back(pointOf(a.cwiseMax(b)));
  const mvog::CheckBoxes::Response box = call<mvog::CheckBoxes>("check_boxes", request);
  ASSERT_TRUE(box.success) << box.message;
  EXPECT_EQ(box.state, std::vector<std::uint8_t>{kOccupied});
  EXPECT_NEAR(box.known_fraction.at(0), 1.0, 1e-6);
}

TEST_F(Planning, FrontiersAtTheDoorAndTheUnexploredEdgeNoneInTheRoom) {
  Latest<sensor_msgs::PointCloud2> frontiers(kServer + "/frontiers");
  Latest<visualization_msgs::MarkerArray> markers(kServer + "/frontier_markers");
  loadRoom();
  // The door's cells (x = 4.05, 8 cells, free up to 2.0 m: 20 voxels each) and the cells along
  // y = 2.95 (40 cells, free up to 2.5 m), unknown beyond both.
  constexpr std::size_t kVoxels = 8 * 20 + 40 * 25;
  const auto cloud = frontiers.await(
      [](const sensor_msgs::PointCloud2& c) { return c.width * c.height == kVoxels; });
  ASSERT_TRUE(cloud) << "no frontiers of " << kVoxels << " voxels";
  EXPECT_EQ(cloud->header.frame_id, "map");
  std::set<std::uint32_t> door_clusters;
  std::set<std::uint32_t> edge_clusters;
  sensor_msgs::PointCloud2ConstIterator<std::uint32_t> cluster(*cloud, "cluster");
  for (const std::vector<float>& p : pointsOf(*cloud, {"x", "y", "z"})) {
    const bool door = std::abs(p[0] - 4.05f) < 1e-4f && p[1] > 1.0f && p[1] < 1.8f;
    const bool edge = std::abs(p[1] - 2.95f) < 1e-4f;
    EXPECT_TRUE(door || edge) << p[0] << " " << p[1] << " " << p[2];
    (door ? door_clusters : edge_clusters).insert(*cluster);
    ++cluster;
  }
  ASSERT_EQ(door_clusters.size(), 1u);
  ASSERT_EQ(edge_clusters.size(), 1u);
  EXPECT_NE(*door_clusters.begin(), *edge_clusters.begin());

  const auto array = markers.await([](const visualization_msgs::MarkerArray& m) {
    return m.markers.size() == 3 &&
           m.markers[1].points.size() + m.markers[2].points.size() == kVoxels;
  });
  ASSERT_TRUE(array) << "no markers of two clusters";
  EXPECT_EQ(array->markers[0].action, visualization_msgs::Marker::DELETEALL);
  EXPECT_EQ(array->markers[1].type, visualization_msgs::Marker::CUBE_LIST);
  EXPECT_EQ(array->markers[1].header.frame_id, "map");
}

TEST_F(Planning, TheDeskGivesTwoSurfacesTheFloorUnderItWithItsUndersideAsClearance) {
  Latest<sensor_msgs::PointCloud2> surfaces(kServer + "/surfaces");
  loadRoom();
  // Under and on the desk at (1.55, 1.05): the floor up to the board's underside, the board up
  // to the ceiling, the ceiling with unknown space above it.
  auto at_desk = [](const sensor_msgs::PointCloud2& cloud) {
    std::vector<std::vector<float>> desk;
    for (const std::vector<float>& p :
         pointsOf(cloud, {"x", "y", "z", "clearance", "probability"})) {
      if (std::abs(p[0] - 1.55f) < 1e-4f && std::abs(p[1] - 1.05f) < 1e-4f) desk.push_back(p);
    }
    std::sort(desk.begin(), desk.end(), [](const auto& a, const auto& b) { return a[2] < b[2]; });
    return desk;
  };
  const auto cloud =
      surfaces.await([&](const sensor_msgs::PointCloud2& c) { return at_desk(c).size() == 3; });
  ASSERT_TRUE(cloud) << "no surfaces at the desk";
  const std::vector<std::vector<float>> desk = at_desk(*cloud);
  EXPECT_NEAR(desk[0][2], 0.0, 1e-6);  // the floor
  EXPECT_NEAR(desk[0][3], 0.7, 1e-6);  // up to the board's underside
  EXPECT_EQ(desk[0][4], 1.0f);
  EXPECT_NEAR(desk[1][2], 0.8, 1e-6);  // the board's top
  EXPECT_NEAR(desk[1][3], 1.7, 1e-6);  // up to the ceiling
  EXPECT_NEAR(desk[1][4], 5.0 / 5.1, 1e-6);
  EXPECT_NEAR(desk[2][2], 2.6, 1e-6);  // the ceiling's top
  EXPECT_EQ(desk[2][3], 0.0f);
}

TEST_F(Planning, TheTraversableMapPassesTheFloorAndNotTheDeskForARobotTallerThanItsUnderside) {
  Latest<nav_msgs::OccupancyGrid> traversable(kServer + "/traversable_map");
  loadRoom();
  // planning_test.yaml: ~robot_height 1.0, the desk's underside 0.7 m above the floor.
  const auto grid = traversable.await([](const nav_msgs::OccupancyGrid& g) {
    return valueAt(g, 2.55, 2.55) == 0 && valueAt(g, 1.55, 1.05) == 100;
  });
  ASSERT_TRUE(grid) << "no traversable map of the room";
  EXPECT_EQ(grid->header.frame_id, "map");
  EXPECT_NEAR(grid->info.resolution, kCell, 1e-6);
  EXPECT_EQ(grid->info.origin.position.z, 0.0);  // the band [-0.5, 0.5] m holds the ground
  EXPECT_EQ(valueAt(*grid, 0.05, 0.05), 0);      // by the walls
  EXPECT_EQ(valueAt(*grid, 4.05, 1.45), 0);      // the door
  EXPECT_EQ(valueAt(*grid, 1.05, 0.55), 100);    // the desk
  EXPECT_EQ(valueAt(*grid, 0.95, 0.55), 0);      // beside it
  EXPECT_EQ(valueAt(*grid, 4.05, 0.55), 100);    // a wall
  EXPECT_EQ(valueAt(*grid, 2.55, 3.05), -1);     // unexplored
  EXPECT_EQ(valueAt(*grid, 4.25, 1.45), -1);     // past the door
}

// ---- The scanned room, through the sensor input
// --------------------------------------------------

/// The obstacle readings of a scan as a PointCloud2 in the frame `frame` at the scan's origin.
sensor_msgs::PointCloud2 cloudOf(const mvog::Scan& scan, const std::string& frame) {
  sensor_msgs::PointCloud2 cloud;
  cloud.header.frame_id = frame;
  cloud.header.stamp = ros::Time::now();
  sensor_msgs::PointCloud2Modifier modifier(cloud);
  modifier.setPointCloud2FieldsByString(1, "xyz");
  modifier.resize(scan.hits.size());
  sensor_msgs::PointCloud2Iterator<float> x(cloud, "x");
  sensor_msgs::PointCloud2Iterator<float> y(cloud, "y");
  sensor_msgs::PointCloud2Iterator<float> z(cloud, "z");
  for (const Eigen::Vector3f& hit : scan.hits) {
    const Eigen::Vector3f p = hit - scan.origin.cast<float>();
    *x = p.x(), *y = p.y(), *z = p.z();
    ++x, ++y, ++z;
  }
  return cloud;
}

TEST_F(Planning, FollowsTheScannedRoomAsItIsMappedAndStartsAfreshAfterAReset) {
  Latest<sensor_msgs::PointCloud2> frontiers(kServer + "/frontiers");
  Latest<sensor_msgs::PointCloud2> surfaces(kServer + "/surfaces");
  Latest<nav_msgs::OccupancyGrid> traversable(kServer + "/traversable_map");
  Latest<map_msgs::OccupancyGridUpdate> traversable_updates(kServer + "/traversable_map_updates");
  Latest<mvog::MapStatistics> statistics(kServer + "/statistics");
  ros::NodeHandle nh;
  ros::Publisher clouds = nh.advertise<sensor_msgs::PointCloud2>("/cloud_in", 10);
  const std::vector<mvog::Scan> scans = mvog::test::scannedRoomScans();
  for (std::size_t k = 0; k < scans.size(); ++k) {
    sendStaticTransform(Eigen::Isometry3d(Eigen::Translation3d(scans[k].origin)),
                        "room_pose_" + std::to_string(k));
  }
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(kTimeout);
  while (clouds.getNumSubscribers() == 0 && ros::WallTime::now() < deadline) {
    ros::WallDuration(0.01).sleep();
  }
  ASSERT_GT(clouds.getNumSubscribers(), 0u);
  auto inserted = [&](std::uint64_t count) {
    return statistics.await(
        [count](const mvog::MapStatistics& s) { return s.messages_inserted == count; });
  };

  // The four poses at 1.2 m.
  for (std::size_t k = 0; k < 4; ++k) {
    clouds.publish(cloudOf(scans[k], "room_pose_" + std::to_string(k)));
  }
  ASSERT_TRUE(inserted(4));
  const mvog::CheckSegments::Response checks =
      checkSegments({{{0.0, 0.2, 1.2}, {-4.0, 0.2, 1.2}},   // through the wall x = -3, 3 m on
                     {{-1.5, 0.0, 1.2}, {1.5, 0.8, 1.2}}},  // from one pose to another
                    0.0);
  ASSERT_TRUE(checks.success) << checks.message;
  EXPECT_EQ(checks.state, (std::vector<std::uint8_t>{kOccupied, kFree}));
  // Hits on the wall's face make its cell occupied, x in [-3.0, -2.9): entered at 2.9 m.
  EXPECT_NEAR(checks.blocked_at.at(0), 3.0, kCell + 1e-9);
  auto beyond_the_door = [](const sensor_msgs::PointCloud2& cloud) {
    std::size_t beyond = 0;
    for (const std::vector<float>& p : pointsOf(cloud, {"x", "y", "z"})) {
      beyond += p[0] > 3.2f && p[0] < 5.0f && std::abs(p[1]) < 2.0f;
    }
    return beyond;
  };
  const auto frontier_cloud =
      frontiers.await([&](const sensor_msgs::PointCloud2& c) { return beyond_the_door(c) > 100; });
  ASSERT_TRUE(frontier_cloud) << "no frontiers beyond the door";
  for (const std::vector<float>& p : pointsOf(*frontier_cloud, {"x", "y", "z"})) {
    // Around the poses, away from the objects, the map is known.
    EXPECT_FALSE(std::abs(p[0]) < 1.0f && p[1] > -0.2f && p[1] < 1.0f && p[2] > 0.3f && p[2] < 2.2f)
        << p[0] << " " << p[1] << " " << p[2];
  }
  const auto first_grid = traversable.await(
      [](const nav_msgs::OccupancyGrid& g) { return valueAt(g, -1.5, 0.0) == 0; });
  ASSERT_TRUE(first_grid) << "no traversable floor";

  // The pose at 0.4 m sees under the table: its floor, with the table's underside above it, and
  // its top; the table blocks the robot. What changed comes as an update of the grid too.
  clouds.publish(cloudOf(scans[4], "room_pose_4"));
  ASSERT_TRUE(inserted(5));
  auto at_table = [](const sensor_msgs::PointCloud2& cloud) {
    std::vector<std::vector<float>> table;
    for (const std::vector<float>& p : pointsOf(cloud, {"x", "y", "z", "clearance"})) {
      if (std::abs(p[0] - 1.05f) < 1e-4f && std::abs(p[1] + 1.05f) < 1e-4f) table.push_back(p);
    }
    std::sort(table.begin(), table.end(), [](const auto& a, const auto& b) { return a[2] < b[2]; });
    return table;
  };
  // The floor, up to the underside (hits are a cell high), and the table's top; the surfaces
  // published before the last scan was inserted do not see the floor there yet.
  EXPECT_TRUE(surfaces.await([&](const sensor_msgs::PointCloud2& c) {
    const std::vector<std::vector<float>> table = at_table(c);
    return table.size() >= 2 && std::abs(table[0][2] - 0.0) <= kCell &&
           std::abs(table[0][3] - 0.7) <= 2 * kCell && std::abs(table[1][2] - 0.75) <= kCell;
  })) << "no floor under the table with its underside 0.7 m above it, and its top";
  EXPECT_TRUE(traversable.await(
      [](const nav_msgs::OccupancyGrid& g) { return valueAt(g, 1.05, -1.05) == 100; }));
  EXPECT_TRUE(traversable_updates.await([](const map_msgs::OccupancyGridUpdate& u) {
    return u.header.frame_id == "map" && u.data.size() == std::size_t{u.width} * u.height &&
           u.width > 0;
  }));

  // A reset: nothing of the room is shown any more.
  const std_srvs::Trigger::Response reset = call<std_srvs::Trigger>("reset", {});
  ASSERT_TRUE(reset.success) << reset.message;
  EXPECT_TRUE(frontiers.await([](const sensor_msgs::PointCloud2& c) { return c.width == 0; }));
  EXPECT_TRUE(surfaces.await([](const sensor_msgs::PointCloud2& c) { return c.width == 0; }));
  EXPECT_TRUE(traversable.await([](const nav_msgs::OccupancyGrid& g) {
    return std::all_of(g.data.begin(), g.data.end(), [](std::int8_t v) { return v == -1; });
  }));
}

}  // namespace

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_planning_node");
  ros::AsyncSpinner spinner(2);
  spinner.start();
  return RUN_ALL_TESTS();
}
