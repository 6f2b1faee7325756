#include "mvog_scene/scene.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <Eigen/Geometry>

namespace mvog_scene {

double Scene::castRay(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) const {
  double nearest = std::numeric_limits<double>::infinity();
  for (const Box& box : boxes) {
    // The slabs' method: the ray is inside the box between the last entry into a slab and the
    // first exit from one. Dividing by a zero component gives infinite bounds: no constraint.
    double t_near = 0.0;
    double t_far = nearest;
    for (int axis = 0; axis < 3 && t_near <= t_far; ++axis) {
      double t0 = (box.min[axis] - origin[axis]) / direction[axis];
      double t1 = (box.max[axis] - origin[axis]) / direction[axis];
      if (t0 > t1) std::swap(t0, t1);
      t_near = std::max(t_near, t0);
      t_far = std::min(t_far, t1);
    }
    if (t_near <= t_far) nearest = t_near;
  }
  for (const Sphere& sphere : spheres) {
    const Eigen::Vector3d to_centre = sphere.centre - origin;
    const double along = to_centre.dot(direction);
    const double squared =
        sphere.radius * sphere.radius - (to_centre.squaredNorm() - along * along);
    if (squared >= 0.0 && along - std::sqrt(squared) > 0.0) {
      nearest = std::min(nearest, along - std::sqrt(squared));
    }
  }
  return nearest;
}

std::vector<Box> roomWalls(const Eigen::Vector3d& min, const Eigen::Vector3d& max,
                           double thickness) {
  const Eigen::Vector3d outer_min = min.array() - thickness;
  const Eigen::Vector3d outer_max = max.array() + thickness;
  std::vector<Box> walls;
  for (int axis = 0; axis < 3; ++axis) {
    Box low{outer_min, outer_max};
    low.max[axis] = min[axis];
    Box high{outer_min, outer_max};
    high.min[axis] = max[axis];
    walls.push_back(low);
    walls.push_back(high);
  }
  return walls;
}

mvog::Scan depthScan(const Scene& scene, const DepthCamera& camera, const Eigen::Vector3d& position,
                     double yaw, double tilt, double max_range) {
  const Eigen::Matrix3d rotation = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                                    Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitY()))
                                       .toRotationMatrix();
  const double tan_x = std::tan(0.5 * camera.horizontal_fov_degrees * M_PI / 180.0);
  const double tan_y = std::tan(0.5 * camera.vertical_fov_degrees * M_PI / 180.0);
  mvog::Scan scan;
  scan.origin = position;
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      const double a = (2.0 * u / (camera.width - 1) - 1.0) * tan_x;
      const double b = (2.0 * v / (camera.height - 1) - 1.0) * tan_y;
      const Eigen::Vector3d direction = (rotation * Eigen::Vector3d(1.0, -a, -b)).normalized();
      const double range = scene.castRay(position, direction);
      if (range <= max_range) {
        scan.hits.push_back((position + range * direction).cast<float>());
      } else {
        scan.out_of_range.push_back((position + max_range * direction).cast<float>());
      }
    }
  }
  return scan;
}

}  // namespace mvog_scene
