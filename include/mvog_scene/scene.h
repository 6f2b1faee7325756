#pragma once

#include <vector>

#include <Eigen/Core>

#include "mvog/map.h"

/// Synthetic scenes for the tools and the tests (mvog_synthetic_demo, mvog_microbench,
/// test_mapper_node): obstacles to cast rays into, and a depth camera that sees them. ROS-free.
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

/// Obstacles: a ray stops at the first surface it meets.
struct Scene {
  std::vector<Box> boxes;
  std::vector<Sphere> spheres;  // seen from outside only

  /// Distance from `origin` along the unit vector `direction` to the nearest surface, or
  /// +infinity. An origin inside a box is 0 away from it.
  double castRay(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) const;
};

/// The inside of the room [min, max] as six walls `thickness` thick, overlapping at the corners:
/// every ray from inside ends on a wall, the floor or the ceiling.
std::vector<Box> roomWalls(const Eigen::Vector3d& min, const Eigen::Vector3d& max,
                           double thickness);

/// A depth camera, by default the paper's SwissRanger 4000 (176 x 144 pixels).
struct DepthCamera {
  int width = 176;
  int height = 144;
  double horizontal_fov_degrees = 43.6;
  double vertical_fov_degrees = 34.6;
};

/// What `camera` at `position` sees of `scene`, looking along `yaw` about z, tilted down by
/// `tilt` (rad): a hit where a pixel's ray meets a surface within `max_range`, else an
/// out-of-range reading at `max_range`.
mvog::Scan depthScan(const Scene& scene, const DepthCamera& camera, const Eigen::Vector3d& position,
                     double yaw, double tilt, double max_range);

}  // namespace mvog_scene
