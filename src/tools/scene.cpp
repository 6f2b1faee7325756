#include "mvog_scene/scene.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <utility>

#include <Eigen/Geometry>

namespace mvog_scene {

bool rayThroughBox(const Box& box, const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                   double& t_near, double& t_far) {
  // The ray is inside the box between the last entry into a slab and the first exit from one.
  // Dividing by a zero component gives infinite bounds: no constraint.
  t_near = 0.0;
  t_far = std::numeric_limits<double>::infinity();
  for (int axis = 0; axis < 3 && t_near <= t_far; ++axis) {
    double t0 = (box.min[axis] - origin[axis]) / direction[axis];
    double t1 = (box.max[axis] - origin[axis]) / direction[axis];
    if (t0 > t1) std::swap(t0, t1);
    t_near = std::max(t_near, t0);
    t_far = std::min(t_far, t1);
  }
  return t_near <= t_far;
}

namespace {

/// Where the ray is inside `cylinder`, as rayThroughBox: within its radius about the axis (a
/// quadratic in the ray's horizontal part) and between its bottom and top.
bool rayThroughCylinder(const Cylinder& cylinder, const Eigen::Vector3d& origin,
                        const Eigen::Vector3d& direction, double& t_near, double& t_far) {
  const Box slab{{-INFINITY, -INFINITY, cylinder.bottom}, {INFINITY, INFINITY, cylinder.top}};
  if (!rayThroughBox(slab, origin, direction, t_near, t_far)) return false;
  const Eigen::Vector2d from_axis = origin.head<2>() - cylinder.centre;
  const Eigen::Vector2d across = direction.head<2>();
  const double a = across.squaredNorm();
  const double c = from_axis.squaredNorm() - cylinder.radius * cylinder.radius;
  if (a == 0.0) return c <= 0.0;  // a vertical ray: inside the radius all along, or never
  const double b = from_axis.dot(across);
  const double discriminant = b * b - a * c;
  if (discriminant < 0.0) return false;
  const double root = std::sqrt(discriminant);
  t_near = std::max(t_near, (-b - root) / a);
  t_far = std::min(t_far, (-b + root) / a);
  return t_near <= t_far;
}

/// How far `value` is outside [low, high]: negative inside, minus the distance to the nearer end.
double outside(double value, double low, double high) {
  return std::max(low - value, value - high);
}

/// The signed distance of a point whose signed distances to two slabs crossing at right angles
/// are `first` and `second`, to their intersection.
double intersectionDistance(double first, double second) {
  return std::hypot(std::max(first, 0.0), std::max(second, 0.0)) +
         std::min(std::max(first, second), 0.0);
}

}  // namespace

double Scene::castRay(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) const {
  double nearest = std::numeric_limits<double>::infinity();
  double t_near = 0.0;
  double t_far = 0.0;
  for (const Box& box : boxes) {
    if (rayThroughBox(box, origin, direction, t_near, t_far)) nearest = std::min(nearest, t_near);
  }
  for (const Cylinder& cylinder : cylinders) {
    if (rayThroughCylinder(cylinder, origin, direction, t_near, t_far)) {
      nearest = std::min(nearest, t_near);
    }
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

double Scene::distance(const Eigen::Vector3d& point) const {
  double nearest = std::numeric_limits<double>::infinity();
  for (const Box& box : boxes) {
    Eigen::Vector3d per_axis;
    for (int axis = 0; axis < 3; ++axis) {
      per_axis[axis] = outside(point[axis], box.min[axis], box.max[axis]);
    }
    nearest = std::min(nearest, per_axis.cwiseMax(0.0).norm() + std::min(per_axis.maxCoeff(), 0.0));
  }
  for (const Cylinder& cylinder : cylinders) {
    nearest = std::min(
        nearest, intersectionDistance((point.head<2>() - cylinder.centre).norm() - cylinder.radius,
                                      outside(point.z(), cylinder.bottom, cylinder.top)));
  }
  for (const Sphere& sphere : spheres) {
    nearest = std::min(nearest, (point - sphere.centre).norm() - sphere.radius);
  }
  return nearest;
}

void Scene::add(const Scene& other) {
  boxes.insert(boxes.end(), other.boxes.begin(), other.boxes.end());
  spheres.insert(spheres.end(), other.spheres.begin(), other.spheres.end());
  cylinders.insert(cylinders.end(), other.cylinders.begin(), other.cylinders.end());
}

void Scene::translate(const Eigen::Vector3d& offset) {
  for (Box& box : boxes) {
    box.min += offset;
    box.max += offset;
  }
  for (Sphere& sphere : spheres) sphere.centre += offset;
  for (Cylinder& cylinder : cylinders) {
    cylinder.centre += offset.head<2>();
    cylinder.bottom += offset.z();
    cylinder.top += offset.z();
  }
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
/// nearest surface within `max_range`, `measured(range)` away, else an out-of-range reading at
/// `max_range`.
template <class Measured>
void castReading(const Scene& scene, const Eigen::Vector3d& position,
                 const Eigen::Vector3d& direction, double max_range, mvog::Scan& scan,
                 const Measured& measured) {
  const double range = scene.castRay(position, direction);
  if (range <= max_range) {
    scan.hits.push_back(Eigen::Vector3d(position + measured(range) * direction).cast<float>());
  } else {
    scan.out_of_range.push_back((position + max_range * direction).cast<float>());
  }
}

/// An exact reading.
void castReading(const Scene& scene, const Eigen::Vector3d& position,
                 const Eigen::Vector3d& direction, double max_range, mvog::Scan& scan) {
  castReading(scene, position, direction, max_range, scan, [](double range) { return range; });
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
  const bool noisy = camera.noise_sigma > 0.0 || camera.noise_growth > 0.0;
  std::mt19937 rng(camera.noise_seed);
  std::normal_distribution<double> standard_normal;
  mvog::Scan scan;
  scan.origin = position;
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      const double a = (2.0 * u / (camera.width - 1) - 1.0) * tan_x;
      const double b = (2.0 * v / (camera.height - 1) - 1.0) * tan_y;
      // (1, -a, -b) is the pixel's ray scaled to depth 1: its length is range / depth.
      const Eigen::Vector3d ray = rotation * Eigen::Vector3d(1.0, -a, -b);
      const double range_per_depth = ray.norm();
      castReading(scene, position, ray / range_per_depth, max_range, scan, [&](double range) {
        if (!noisy) return range;
        const double depth = range / range_per_depth;
        const double from_min = depth - camera.noise_min_depth;
        const double sigma = camera.noise_sigma + camera.noise_growth * from_min * from_min;
        return (depth + sigma * standard_normal(rng)) * range_per_depth;
      });
    }
  }
  return scan;
}

}  // namespace mvog_scene
