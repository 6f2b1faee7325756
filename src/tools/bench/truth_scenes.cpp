// mvog_bench's ground-truth scenes ("truth:NAME"): exact geometry, each with its own sensor and
// trajectory, a few seconds of scans each.
#include <cmath>
#include <map>
#include <utility>

#include "truth.h"

namespace mvog_bench {
namespace {

using mvog_scene::Box;
using mvog_scene::Cylinder;
using mvog_scene::Scene;
using mvog_scene::Sphere;

/// Four legs of `radius` under the corners of `top`, `inset` in from its edges.
std::vector<Cylinder> legsUnder(const Box& top, double radius, double inset) {
  std::vector<Cylinder> legs;
  for (double x : {top.min.x() + inset, top.max.x() - inset}) {
    for (double y : {top.min.y() + inset, top.max.y() - inset}) {
      legs.push_back({{x, y}, radius, 0.0, top.min.z()});
    }
  }
  return legs;
}

/// A table: its top an overhang, its legs thin objects.
void addTable(TruthScene& truth, const Box& top, double leg_radius) {
  truth.scene.boxes.push_back(top);
  truth.overhangs.push_back(top);
  for (const Cylinder& leg : legsUnder(top, leg_radius, 0.05)) {
    truth.thin_objects.cylinders.push_back(leg);
  }
}

/// A wall `thickness` thick along x (at y) or along y (at x) from `from` to `to`, `height` high,
/// with openings [begin, end] (doors, floor to `door_height`) left out.
void addWall(Scene& scene, bool along_x, double at, double from, double to, double thickness,
             double height, const std::vector<std::pair<double, double>>& doors,
             double door_height) {
  auto add = [&](double begin, double end, double bottom, double top) {
    Box box;
    box.min = along_x ? Eigen::Vector3d(begin, at, bottom) : Eigen::Vector3d(at, begin, bottom);
    box.max = along_x ? Eigen::Vector3d(end, at + thickness, top)
                      : Eigen::Vector3d(at + thickness, end, top);
    scene.boxes.push_back(box);
  };
  double begin = from;
  for (const auto& [door_begin, door_end] : doors) {
    add(begin, door_begin, 0.0, height);
    add(door_begin, door_end, door_height, height);  // the lintel
    begin = door_end;
  }
  add(begin, to, 0.0, height);
}

/// Scans `count` poses: scan k from `scan_at(k)`.
template <class ScanAt>
std::vector<mvog::Scan> scansOf(int count, const ScanAt& scan_at) {
  std::vector<mvog::Scan> scans;
  scans.reserve(static_cast<std::size_t>(count));
  for (int k = 0; k < count; ++k) scans.push_back(scan_at(k));
  return scans;
}

/// A furnished room 6 m x 5 m x 2.8 m with a doorway, seen by a moving 640 x 480 depth camera
/// whose depth noise grows as z^2 (a structured-light camera's): a table and a chair (legs
/// 5 and 3 cm across), a closed wardrobe, a sofa, a wall shelf, a floor lamp on a 2.4 cm pole
/// and a 1 cm cable across the room.
TruthScene roomDepthCamera() {
  TruthScene truth;
  Scene& room = truth.scene;
  room.boxes = mvog_scene::roomWalls({-3, -2.5, 0}, {3, 2.5, 2.8}, 0.1);
  room.boxes.erase(room.boxes.begin() + 1);  // the wall at x = 3: rebuilt with a doorway
  addWall(room, false, 3.0, -2.6, 2.6, 0.1, 2.8, {{0.5, 1.4}}, 2.05);
  room.boxes.push_back({{3.1, -1.0, -0.1}, {4.6, 3.0, 0.0}});  // beyond it: a floor, a wall
  room.boxes.push_back({{4.5, -1.0, 0.0}, {4.6, 3.0, 2.8}});
  room.boxes.push_back({{-2.95, 1.5, 0.0}, {-2.2, 2.45, 1.9}});      // the wardrobe, closed
  room.boxes.push_back({{-2.9, -2.4, 0.0}, {-2.0, -0.6, 0.45}});     // the sofa's seat
  room.boxes.push_back({{-2.95, -2.4, 0.45}, {-2.75, -0.6, 0.85}});  // and its back
  const Box shelf{{-0.5, 2.2, 1.5}, {0.7, 2.5, 1.53}};
  room.boxes.push_back(shelf);
  truth.overhangs.push_back(shelf);
  addTable(truth, {{0.4, -1.6, 0.72}, {1.8, -0.8, 0.76}}, 0.025);
  const Box seat{{0.7, -0.6, 0.44}, {1.15, -0.15, 0.47}};
  room.boxes.push_back(seat);
  room.boxes.push_back({{0.7, -0.15, 0.47}, {1.15, -0.12, 0.9}});  // the chair's back
  for (const Cylinder& leg : legsUnder(seat, 0.015, 0.03)) {
    truth.thin_objects.cylinders.push_back(leg);
  }
  truth.thin_objects.cylinders.push_back({{1.2, 1.5}, 0.012, 0.0, 1.6});         // the lamp's pole
  room.spheres.push_back({{1.2, 1.5, 1.75}, 0.18});                              // and its shade
  truth.thin_objects.boxes.push_back({{-2.0, 0.295, 2.2}, {2.5, 0.305, 2.21}});  // a cable
  room.add(truth.thin_objects);
  truth.slice = {{-3.2, -1.2, 2.95}, {6.4, 0, 0}, {0, 0, -3.1}, 0.01};  // through the table
  truth.scans = [room] {
    mvog_scene::DepthCamera camera;
    camera.width = 640;
    camera.height = 480;
    camera.horizontal_fov_degrees = 58.0;
    camera.vertical_fov_degrees = 45.0;
    camera.noise_sigma = 0.0012;
    camera.noise_growth = 0.0019;
    struct Pose {
      Eigen::Vector3d position;
      double yaw;
      double tilt;
    };
    const std::vector<Pose> poses = {
        {{-1.5, 0.0, 1.3}, 0.0, 0.35},  {{-1.0, 1.0, 1.3}, -0.8, 0.5},
        {{2.2, 0.8, 1.0}, -2.2, 0.45},  {{0.9, 0.6, 0.6}, -1.57, 0.0},  // under the table
        {{1.5, 0.0, 1.4}, 3.14, 0.3},   {{0.0, -1.0, 1.4}, 1.57, 0.2},
        {{-1.8, -1.0, 1.5}, 0.6, -0.3}, {{1.0, 1.0, 1.2}, -0.3, 0.25}};
    constexpr double kMaxRange = 6.0;
    return scansOf(static_cast<int>(poses.size()), [&](int k) {
      camera.noise_seed = static_cast<std::uint32_t>(k + 1);
      const Pose& pose = poses[static_cast<std::size_t>(k)];
      return mvog_scene::depthScan(room, camera, pose.position, pose.yaw, pose.tilt, kMaxRange);
    });
  };
  return truth;
}

/// Street furniture along a road on x: bollards (10 cm across) every 4 m on both sides, lamp
/// posts (14 cm) every 15 m, trees (a 30 cm trunk and a crown) every 12 m, from x0 to x1.
void addStreetFurniture(TruthScene& truth, double x0, double x1, double road_half_width) {
  for (double x = x0; x < x1; x += 4.0) {
    for (double side : {-1.0, 1.0}) {
      truth.thin_objects.cylinders.push_back({{x, side * (road_half_width + 0.5)}, 0.05, 0.0, 1.0});
    }
  }
  for (double x = x0 + 2.0; x < x1; x += 15.0) {
    truth.thin_objects.cylinders.push_back({{x, road_half_width + 1.5}, 0.07, 0.0, 6.0});
  }
  for (double x = x0 + 5.0; x < x1; x += 12.0) {
    truth.scene.cylinders.push_back({{x, -road_half_width - 2.5}, 0.15, 0.0, 3.0});
    truth.scene.spheres.push_back({{x, -road_half_width - 2.5, 4.5}, 1.6});
  }
}

/// A road under a bridge, seen by a 16-beam rotating lidar (a VLP-16 at 20 Hz: 0.4 degrees
/// apart in azimuth) 1.8 m up on 5 turns 6 m apart, the last two under the bridge's deck (5 m up,
/// 0.8 m thick, on round pillars): bollards, lamp posts and a cable along the road, trees, parked
/// cars, rows of buildings and an embankment at each end of the street.
TruthScene bridgeLidar16() {
  TruthScene truth;
  truth.scene.boxes.push_back({{-60, -60, -0.1}, {90, 60, 0}});  // the ground
  const Box deck{{18, -40, 5.0}, {26, -40 + 80, 5.8}};
  truth.scene.boxes.push_back(deck);
  truth.overhangs.push_back(deck);
  for (double x : {19.0, 25.0}) {
    for (double y : {-7.0, 7.0}) truth.scene.cylinders.push_back({{x, y}, 0.5, 0.0, 5.0});
  }
  // Rows of buildings behind the pavements, 8-14 m high, without gaps, and a hillside at each
  // end of the street: the rays end within the street (a map of a few hundred metres square).
  for (double x = -40.0; x < 75.0; x += 10.0) {
    truth.scene.boxes.push_back({{x, 12, 0}, {x + 10, 20, 8.0 + std::fmod(x + 40.0, 7.0)}});
    truth.scene.boxes.push_back({{x, -20, 0}, {x + 10, -12, 10.0 + std::fmod(x + 40.0, 4.0)}});
  }
  truth.scene.boxes.push_back({{-45, -20, 0}, {-40, 20, 5}});
  truth.scene.boxes.push_back({{75, -20, 0}, {80, 20, 5}});
  truth.scene.boxes.push_back({{6, 4.5, 0}, {10.2, 6.3, 1.5}});  // parked cars
  truth.scene.boxes.push_back({{32, -6.3, 0}, {36.2, -4.5, 1.5}});
  addStreetFurniture(truth, -10.0, 50.0, 4.0);
  truth.thin_objects.boxes.push_back({{-10, 5.49, 5.99}, {17, 5.51, 6.01}});  // a cable
  truth.scene.add(truth.thin_objects);
  truth.slice = {{0, 0.0, 7.0}, {40, 0, 0}, {0, 0, -7.3}, 0.04};  // along the road's middle
  truth.scans = [scene = truth.scene] {
    mvog_scene::RotatingLidar lidar;
    lidar.azimuth_step_degrees = 0.4;
    return scansOf(5, [&](int k) {
      return mvog_scene::lidarScan(scene, lidar, Eigen::Vector3d(6.0 * k, 0.3 * std::sin(k), 1.8),
                                   100.0);
    });
  };
  return truth;
}

/// A road between noise barriers seen by a car's lidar: 8 beams from -5 to +2 degrees, 0.2
/// degrees apart in azimuth, 150 m, 1.9 m up, on 6 turns 5 m apart: a guard rail, sign posts,
/// trees, cars ahead, an overpass 5.5 m up and a hillside 200 m ahead.
TruthScene carLidar() {
  TruthScene truth;
  truth.scene.boxes.push_back({{-50, -15, -0.1}, {215, 15, 0}});  // the ground
  const Box overpass{{118, -60, 5.5}, {130, 60, 6.5}};
  truth.scene.boxes.push_back(overpass);
  truth.overhangs.push_back(overpass);
  truth.scene.boxes.push_back({{120, -12, 0}, {128, -10.5, 5.5}});  // its abutments
  truth.scene.boxes.push_back({{120, 10.5, 0}, {128, 12, 5.5}});
  truth.scene.boxes.push_back({{-20, 12, 0}, {200, 12.3, 4.0}});    // a noise barrier
  truth.scene.boxes.push_back({{30, -3.8, 0}, {34.5, -2.0, 1.5}});  // cars ahead, a truck
  truth.scene.boxes.push_back({{60, 0.5, 0}, {64.5, 2.3, 1.5}});
  truth.scene.boxes.push_back({{85, -3.6, 0}, {97, -1.1, 3.8}});
  truth.thin_objects.boxes.push_back({{-40, -5.6, 0.6}, {200, -5.5, 0.9}});  // a guard rail
  for (double x = -10.0; x < 200.0; x += 25.0) {  // sign posts and their signs
    truth.thin_objects.cylinders.push_back({{x, 7.0}, 0.06, 0.0, 3.0});
    truth.scene.boxes.push_back({{x - 0.05, 6.4, 2.2}, {x, 7.6, 3.0}});
  }
  for (double x = 0.0; x < 200.0; x += 18.0) {  // trees between the guard rail and the barrier
    truth.scene.cylinders.push_back({{x, -10.0}, 0.2, 0.0, 3.5});
    truth.scene.spheres.push_back({{x, -10.0, 5.0}, 2.0});
  }
  truth.scene.add(truth.thin_objects);
  truth.slice = {{0, -2.9, 7.5}, {140, 0, 0}, {0, 0, -7.8}, 0.1};  // along the lane of the cars
  truth.scans = [scene = truth.scene] {
    mvog_scene::RotatingLidar lidar;
    lidar.beams = 8;
    lidar.min_elevation_degrees = -5.0;
    lidar.max_elevation_degrees = 2.0;
    lidar.azimuth_step_degrees = 0.2;
    return scansOf(6, [&](int k) {
      return mvog_scene::lidarScan(scene, lidar, Eigen::Vector3d(5.0 * k, 0.0, 1.9), 150.0);
    });
  };
  return truth;
}

/// An office corridor 32 m long with two rooms through doorways, seen by a level 2D laser (1081
/// beams over 270 degrees, 30 m, 0.25 m up) driving along it and into both rooms: tables and
/// chairs on thin legs, a bin, a pillar.
TruthScene corridor2dLaser() {
  TruthScene truth;
  Scene& office = truth.scene;
  constexpr double kHeight = 2.6;
  constexpr double kDoor = 2.1;
  office.boxes.push_back({{-2.3, -6.3, -0.1}, {30.3, 6.3, 0}});  // the floor
  addWall(office, true, 1.1, -2.2, 30.2, 0.1, kHeight, {{7.0, 8.0}}, kDoor);
  addWall(office, true, -1.2, -2.2, 30.2, 0.1, kHeight, {{17.0, 18.0}}, kDoor);
  addWall(office, false, -2.2, -1.2, 1.2, 0.1, kHeight, {}, kDoor);  // the corridor's ends
  addWall(office, false, 30.1, -1.2, 1.2, 0.1, kHeight, {}, kDoor);
  addWall(office, false, 4.9, 1.2, 6.1, 0.1, kHeight, {}, kDoor);  // room A, north
  addWall(office, false, 11.0, 1.2, 6.1, 0.1, kHeight, {}, kDoor);
  addWall(office, true, 6.0, 4.9, 11.1, 0.1, kHeight, {}, kDoor);
  addWall(office, false, 14.9, -6.1, -1.2, 0.1, kHeight, {}, kDoor);  // room B, south
  addWall(office, false, 21.0, -6.1, -1.2, 0.1, kHeight, {}, kDoor);
  addWall(office, true, -6.1, 14.9, 21.1, 0.1, kHeight, {}, kDoor);
  addTable(truth, {{6.0, 3.5, 0.72}, {8.0, 4.5, 0.75}}, 0.025);
  addTable(truth, {{9.2, 1.5, 0.72}, {10.8, 2.3, 0.75}}, 0.02);
  addTable(truth, {{16.0, -4.5, 0.72}, {18.5, -3.3, 0.75}}, 0.025);
  for (const Box& seat :
       {Box{{6.6, 2.8, 0.44}, {7.05, 3.25, 0.47}}, Box{{17.0, -2.9, 0.44}, {17.45, -2.45, 0.47}}}) {
    office.boxes.push_back(seat);
    for (const Cylinder& leg : legsUnder(seat, 0.012, 0.03)) {
      truth.thin_objects.cylinders.push_back(leg);
    }
  }
  office.boxes.push_back({{12.0, 0.7, 0.0}, {12.35, 1.1, 0.6}});   // a bin
  office.cylinders.push_back({{24.0, -0.9}, 0.15, 0.0, kHeight});  // a pillar
  office.add(truth.thin_objects);
  truth.slice = {{-2.4, 6.4, 0.25}, {32.8, 0, 0}, {0, -12.8, 0}, 0.02};  // the laser's plane
  truth.scans = [office] {
    // Waypoints; the laser moves between them 0.5 m a scan, facing the way it goes.
    const std::vector<Eigen::Vector2d> path = {{-1.0, 0.0},  {7.5, 0.0},  {7.5, 2.8},
                                               {9.0, 3.0},   {7.5, 0.0},  {17.5, 0.0},
                                               {17.5, -2.0}, {17.5, 0.0}, {28.5, 0.2}};
    std::vector<std::pair<Eigen::Vector2d, double>> poses;
    for (std::size_t leg = 0; leg + 1 < path.size(); ++leg) {
      const Eigen::Vector2d step = path[leg + 1] - path[leg];
      const int steps = static_cast<int>(std::ceil(step.norm() / 0.5));
      for (int k = 0; k < steps; ++k) {
        poses.emplace_back(path[leg] + step * (static_cast<double>(k) / steps),
                           std::atan2(step.y(), step.x()));
      }
    }
    mvog_scene::TiltingLaser laser;  // level: one sweep
    laser.beams = 1081;
    laser.field_of_view_degrees = 270.0;
    laser.min_pitch_degrees = laser.max_pitch_degrees = 0.0;
    return scansOf(static_cast<int>(poses.size()), [&](int k) {
      const auto& [xy, yaw] = poses[static_cast<std::size_t>(k)];
      // 0.25 is exact in float: the hits lie at the laser's height exactly (a level scan).
      return mvog_scene::tiltingLaserScan(office, laser, Eigen::Vector3d(xy.x(), xy.y(), 0.25), yaw,
                                          30.0);
    });
  };
  return truth;
}

/// mvog_scene::officeScene with a floor lamp on a 3 cm pole and a 1 cm cable, seen by the
/// tilting laser (181 beams, nodding from -45 to +45 degrees) 0.5 m up on 10 poses, some near
/// the desk.
TruthScene tiltingLaser() {
  TruthScene truth;
  truth.scene = mvog_scene::officeScene();
  const Box desk_top{{1.0, 1.5, 0.72}, {3.0, 2.5, 0.75}};  // officeScene's desk and legs
  truth.overhangs.push_back(desk_top);
  truth.thin_objects.boxes.push_back({{1.0, 1.5, 0}, {1.05, 1.55, 0.72}});
  truth.thin_objects.boxes.push_back({{2.95, 2.45, 0}, {3.0, 2.5, 0.72}});
  Scene added;
  added.cylinders.push_back({{-1.0, 0.8}, 0.015, 0.0, 1.7});
  added.boxes.push_back({{-4.0, -0.505, 2.3}, {4.0, -0.495, 2.31}});
  truth.scene.add(added);
  truth.thin_objects.add(added);
  truth.slice = {{-6.2, 2.0, 3.15}, {12.4, 0, 0}, {0, 0, -3.3}, 0.01};  // through the desk
  truth.scans = [office = truth.scene] {
    return scansOf(10, [&](int k) {
      const double angle = 0.6 * k;
      return mvog_scene::tiltingLaserScan(
          office, mvog_scene::TiltingLaser(),
          Eigen::Vector3d(-2.5 + 0.55 * k, 0.9 + 0.6 * std::sin(angle), 0.5), angle, 30.0);
    });
  };
  return truth;
}

}  // namespace

TruthScene truthScene(const std::string& name) {
  static const std::map<std::string, TruthScene (*)()> kScenes = {
      {"room-depth-camera", roomDepthCamera},
      {"bridge-lidar-16", bridgeLidar16},
      {"car-lidar", carLidar},
      {"corridor-2d-laser", corridor2dLaser},
      {"tilting-laser", tiltingLaser}};
  const auto scene = kScenes.find(name);
  if (scene == kScenes.end()) {
    std::string names;
    for (const auto& [known, make] : kScenes) names += (names.empty() ? "" : ", ") + known;
    throw InputError(std::string(kTruthPrefix) + name + ": no such scene (there are " + names +
                     ")");
  }
  TruthScene truth = scene->second();
  truth.name = name;
  // Every scene is built on round coordinates (a floor at z = 0, walls at whole metres), which
  // lie on the boundaries of the maps' cells at every cell size: which cell a hit there falls in
  // is a matter of rounding, and a point 1 mm inside the surface is in the other one. Moved off
  // the grids, each surface lies within a cell, as a real one does.
  const Eigen::Vector3d off_grid(0.0125, 0.0125, 0.0125);
  truth.scene.translate(off_grid);
  truth.thin_objects.translate(off_grid);
  for (Box& overhang : truth.overhangs) {
    overhang.min += off_grid;
    overhang.max += off_grid;
  }
  truth.slice.corner += off_grid;
  truth.scans = [cast = std::move(truth.scans), off_grid] {
    std::vector<mvog::Scan> scans = cast();
    const auto moved = [&](const Eigen::Vector3f& point) {
      return Eigen::Vector3f((point.cast<double>() + off_grid).cast<float>());
    };
    for (mvog::Scan& scan : scans) {
      scan.origin += off_grid;
      // In float, as its readings: a level laser's hits stay at its height exactly.
      scan.origin.z() = static_cast<float>(scan.origin.z());
      for (Eigen::Vector3f& hit : scan.hits) hit = moved(hit);
      for (Eigen::Vector3f& end : scan.out_of_range) end = moved(end);
    }
    return scans;
  };
  return truth;
}

InputData loadTruth(const TruthScene& truth) { return inputOfScans("truth", truth.scans()); }

}  // namespace mvog_bench
