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

Scene streetScene() {
  Scene street;
  street.boxes.push_back({{-60, -60, -0.1}, {90, 60, 0}});  // the ground
  for (int block = -5; block < 9; ++block) {                // 6.5 m and 5.5 m wide, 1.5-2.5 m apart
    const double x = 8.0 * block;
    const double height = 6.0 + 3.0 * ((block + 5) % 4);  // 6, 9, 12 or 15 m, 2 m more across
    street.boxes.push_back({{x, 9, 0}, {x + 6.5, 13, height}});
    street.boxes.push_back({{x + 2, -13, 0}, {x + 7.5, -9, height + 2.0}});
  }
  for (int k = -3; k < 7; ++k) {
    const double x = 6.0 * k;
    street.boxes.push_back({{x, 4.5, 0}, {x + 4.2, 6.3, 1.5}});  // parked cars
    street.boxes.push_back({{x + 3, -6.3, 0}, {x + 7.2, -4.5, 1.5}});
    street.boxes.push_back({{x + 1, 7.5, 0}, {x + 1.2, 7.7, 5}});      // a pole
    street.boxes.push_back({{x + 3.9, -7.6, 0}, {x + 4.1, -7.4, 3}});  // a tree
    street.spheres.push_back({{x + 4, -7.5, 4.5}, 1.6});
  }
  return street;
}

Scene officeScene() {
  Scene office;
  office.boxes = roomWalls({-6, -4, 0}, {6, 4, 3}, 0.1);
  office.boxes.push_back({{1.0, 1.5, 0.72}, {3.0, 2.5, 0.75}});  // desk top and two legs
  office.boxes.push_back({{1.0, 1.5, 0}, {1.05, 1.55, 0.72}});
  office.boxes.push_back({{2.95, 2.45, 0}, {3.0, 2.5, 0.72}});
  office.boxes.push_back({{-3.0, -2.5, 0}, {-1.5, -1.8, 0.8}});  // cabinet
  office.boxes.push_back({{-0.2, -0.2, 0}, {0.2, 0.2, 3}});      // pillar
  office.boxes.push_back({{2.0, -2.0, 0}, {2.4, -1.6, 0.4}});    // boxes
  office.spheres.push_back({{-2, 2, 1.2}, 0.5});                 // a ball
  return office;
}

namespace {

/// The reading of the ray from `position` along the unit vector `direction`: a hit on the
/// nearest surface within `max_range`, else an out-of-range reading at `max_range`.
void castReading(const Scene& scene, const Eigen::Vector3d& position,
                 const Eigen::Vector3d& direction, double max_range, mvog::Scan& scan) {
  const double range = scene.castRay(position, direction);
  if (range <= max_range) {
    scan.hits.push_back((position + range * direction).cast<float>());
  } else {
    scan.out_of_range.push_back((position + max_range * direction).cast<float>());
  }
}

/// The unit vector at `azimuth` about z from +x and `elevation` above the xy-plane (rad).
Eigen::Vector3d unitDirection(double azimuth, double elevation) {
  return {std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth),
          std::sin(elevation)};
}

double radians(double degrees) { return degrees * M_PI / 180.0; }

}  // namespace

mvog::Scan lidarScan(const Scene& scene, const RotatingLidar& lidar,
                     const Eigen::Vector3d& position, double max_range) {
  mvog::Scan scan;
  scan.origin = position;
  const auto steps = static_cast<int>(std::lround(360.0 / lidar.azimuth_step_degrees));
  const int outer = lidar.firing_order ? steps : lidar.beams;
  const int inner = lidar.firing_order ? lidar.beams : steps;
  for (int o = 0; o < outer; ++o) {
    for (int i = 0; i < inner; ++i) {
      const int beam = lidar.firing_order ? i : o;
      const int step = lidar.firing_order ? o : i;
      const double elevation =
          lidar.beams == 1 ? lidar.min_elevation_degrees
                           : lidar.min_elevation_degrees +
                                 (lidar.max_elevation_degrees - lidar.min_elevation_degrees) *
                                     beam / (lidar.beams - 1);
      castReading(scene, position,
                  unitDirection(radians(step * lidar.azimuth_step_degrees), radians(elevation)),
                  max_range, scan);
    }
  }
  return scan;
}

mvog::Scan tiltingLaserScan(const Scene& scene, const TiltingLaser& laser,
                            const Eigen::Vector3d& position, double yaw, double max_range) {
  mvog::Scan scan;
  scan.origin = position;
  const auto sweeps =
      static_cast<int>(std::lround((laser.max_pitch_degrees - laser.min_pitch_degrees) /
                                   laser.pitch_step_degrees)) +
      1;
  for (int sweep = 0; sweep < sweeps; ++sweep) {
    // The scan plane turned about the laser's y axis (up by `pitch`), then about z by `yaw`: the
    // beams across, at +-90 degrees, lie on the nodding axis and stay level.
    const double pitch = radians(laser.min_pitch_degrees + sweep * laser.pitch_step_degrees);
    const Eigen::Matrix3d plane = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                                   Eigen::AngleAxisd(-pitch, Eigen::Vector3d::UnitY()))
                                      .toRotationMatrix();
    for (int beam = 0; beam < laser.beams; ++beam) {
      const double across = radians(laser.beams == 1 ? 0.0
                                                     : laser.field_of_view_degrees *
                                                           (beam / (laser.beams - 1.0) - 0.5));
      castReading(scene, position, plane * Eigen::Vector3d(std::cos(across), std::sin(across), 0.0),
                  max_range, scan);
    }
  }
  return scan;
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
      castReading(scene, position, (rotation * Eigen::Vector3d(1.0, -a, -b)).normalized(),
                  max_range, scan);
    }
  }
  return scan;
}

}  // namespace mvog_scene
