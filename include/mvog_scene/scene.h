#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "mvog/map.h"

/// Synthetic scenes for the tools and the tests (mvog_synthetic_demo, mvog_microbench,
/// mvog_bench's synthetic inputs, test_mapper_node): obstacles to cast rays into, and the
/// sensors that see them (a depth camera, a rotating lidar, a tilting laser). ROS-free.
namespace mvog_scene {

/// An axis-aligned box (m). Infinite bounds make a slab or a column of infinite height.
struct Box {
  Eigen::Vector3d min;
  Eigen::Vector3d max;
};

struct Sphere {
  Eigen::Vector3d centre;
  double radius = 0.0;
};

/// A vertical cylinder (a pole, a table leg, a trunk): its axis at `centre` (x, y), from
/// `bottom` to `top` (m).
struct Cylinder {
  Eigen::Vector2d centre;
  double radius = 0.0;
  double bottom = 0.0;
  double top = 0.0;
};

/// Where the ray from `origin` along `direction` is inside `box`: [t_near, t_far] along it
/// (t_near clamped to 0), false if it never is (the slabs' method).
bool rayThroughBox(const Box& box, const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                   double& t_near, double& t_far);

/// Obstacles: a ray stops at the first surface it meets.
struct Scene {
  std::vector<Box> boxes;
  std::vector<Sphere> spheres;  // seen from outside only
  /// Initialised here so that a scene listing its boxes and spheres only needs nothing more
  /// (-Wmissing-field-initializers).
  std::vector<Cylinder> cylinders = {};

  /// Distance from `origin` along the unit vector `direction` to the nearest surface, or
  /// +infinity. An origin inside a box or a cylinder is 0 away from it.
  double castRay(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) const;

  /// The signed distance from `point` to the nearest obstacle (m): negative inside one, 0 on a
  /// surface, +infinity without obstacles.
  double distance(const Eigen::Vector3d& point) const;

  /// Adds the obstacles of `other`.
  void add(const Scene& other);

  /// Moves every obstacle by `offset`.
  void translate(const Eigen::Vector3d& offset);
};

/// The inside of the room [min, max] as six walls `thickness` thick, overlapping at the corners:
/// every ray from inside ends on a wall, the floor or the ceiling.
std::vector<Box> roomWalls(const Eigen::Vector3d& min, const Eigen::Vector3d& max,
                           double thickness);

/// A street with 110 m of buildings along x: the ground (150 m x 120 m), blocks of buildings
/// 6-17 m high on both sides with gaps between them, parked cars, poles and trees (a trunk and a
/// round crown).
Scene streetScene();

/// An office 12 m x 8 m x 3 m (walls, floor and ceiling) with a desk, a cabinet, a pillar, boxes
/// and a ball.
Scene officeScene();

/// A depth camera, by default the paper's SwissRanger 4000 (176 x 144 pixels), exact.
struct DepthCamera {
  int width = 176;
  int height = 144;
  double horizontal_fov_degrees = 43.6;
  double vertical_fov_degrees = 34.6;
  /// Gaussian noise on each hit's depth z (along the optical axis; the point moves along its
  /// pixel's ray): sigma = noise_sigma + noise_growth * (z - noise_min_depth)^2 (m), as a
  /// structured-light camera's (0, 0: exact). Seeded: the same scan every time.
  double noise_sigma = 0.0;
  double noise_growth = 0.0;  ///< 1/m
  double noise_min_depth = 0.4;
  std::uint32_t noise_seed = 1;
};

/// What `camera` at `position` sees of `scene`, looking along `yaw` about z, tilted down by
/// `tilt` (rad): a hit where a pixel's ray meets a surface within `max_range` (with the camera's
/// noise), else an out-of-range reading at `max_range`.
mvog::Scan depthScan(const Scene& scene, const DepthCamera& camera, const Eigen::Vector3d& position,
                     double yaw, double tilt, double max_range);

/// A rotating multi-beam lidar (an automotive one), by default a Velodyne VLP-16: `beams`
/// elevations spread evenly over [min, max], each read every `azimuth_step_degrees` of a turn.
struct RotatingLidar {
  int beams = 16;
  double min_elevation_degrees = -15.0;
  double max_elevation_degrees = 15.0;
  double azimuth_step_degrees = 0.2;
  /// The readings' order in a scan: every beam at one azimuth, then the next azimuth (the
  /// order of firing, as an unorganised Velodyne cloud), or else each beam's whole turn, then
  /// the next beam (as the rows of an organised cloud). The map does not depend on it, the
  /// speed of insertion does.
  bool firing_order = false;
};

/// One turn of `lidar` at `position`: a hit where a beam meets a surface within `max_range`,
/// else an out-of-range reading at `max_range`.
mvog::Scan lidarScan(const Scene& scene, const RotatingLidar& lidar,
                     const Eigen::Vector3d& position, double max_range);

/// A 2D laser nodding about its horizontal axis across its heading (a tilting laser, as on
/// Kurt3D or a MAV): `beams` over `field_of_view_degrees` in its scan plane, one sweep with the
/// plane pitched from min to max (up is positive) every `pitch_step_degrees`.
struct TiltingLaser {
  int beams = 181;
  double field_of_view_degrees = 180.0;
  double min_pitch_degrees = -45.0;
  double max_pitch_degrees = 45.0;
  double pitch_step_degrees = 1.0;
};

/// One nod of `laser` at `position`, heading `yaw` about z (readings as lidarScan's).
mvog::Scan tiltingLaserScan(const Scene& scene, const TiltingLaser& laser,
                            const Eigen::Vector3d& position, double yaw, double max_range);

}  // namespace mvog_scene
