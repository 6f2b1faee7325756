// mvog_bench's synthetic inputs: sensors that none of the shared recordings has, in scenes built
// in code (mvog_scene), so that the quality of the defaults is also measured on range data they
// were not tuned on.
#include <cmath>
#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "input.h"
#include "mvog_scene/scene.h"

namespace mvog_bench {
namespace {

/// Every synthetic input has this many scans, scan k from `scan_at(k)`.
template <class ScanAt>
std::vector<mvog::Scan> tenScans(const ScanAt& scan_at) {
  constexpr int kScans = 10;
  std::vector<mvog::Scan> scans;
  scans.reserve(kScans);
  for (int k = 0; k < kScans; ++k) scans.push_back(scan_at(k));
  return scans;
}

/// A drive of `lidar` 1.8 m above the street: 10 turns 2 m apart along it, weaving a little.
std::vector<mvog::Scan> streetDrive(const mvog_scene::RotatingLidar& lidar) {
  constexpr double kMaxRange = 100.0;
  const mvog_scene::Scene street = mvog_scene::streetScene();
  return tenScans([&](int k) {
    return mvog_scene::lidarScan(street, lidar, Eigen::Vector3d(2.0 * k, 0.3 * std::sin(k), 1.8),
                                 kMaxRange);
  });
}

/// A tilting laser 0.5 m above the office floor: 10 nods from poses across the room, each turned
/// 0.3 rad further.
std::vector<mvog::Scan> officeNods() {
  constexpr double kMaxRange = 30.0;
  const mvog_scene::Scene office = mvog_scene::officeScene();
  return tenScans([&](int k) {
    return mvog_scene::tiltingLaserScan(office, mvog_scene::TiltingLaser(),
                                        Eigen::Vector3d(-3.0 + 0.6 * k, 0.2 * k - 1.3, 0.5),
                                        0.3 * k, kMaxRange);
  });
}

mvog_scene::RotatingLidar thirtyTwoBeams() {  // a Velodyne HDL-32E
  mvog_scene::RotatingLidar lidar;
  lidar.beams = 32;
  lidar.min_elevation_degrees = -30.67;
  lidar.max_elevation_degrees = 10.67;
  return lidar;
}

const std::map<std::string, std::function<std::vector<mvog::Scan>()>>& sensors() {
  static const std::map<std::string, std::function<std::vector<mvog::Scan>()>> kSensors = {
      {"rotating-lidar-16", [] { return streetDrive(mvog_scene::RotatingLidar()); }},
      {"rotating-lidar-16-firing-order",
       [] {
         mvog_scene::RotatingLidar lidar;
         lidar.firing_order = true;
         return streetDrive(lidar);
       }},
      {"rotating-lidar-32", [] { return streetDrive(thirtyTwoBeams()); }},
      {"tilting-laser", officeNods},
  };
  return kSensors;
}

}  // namespace

InputData loadSynthetic(const std::string& name) {
  const auto sensor = sensors().find(name);
  if (sensor == sensors().end()) {
    std::string names;
    for (const auto& [known, scans] : sensors()) names += (names.empty() ? "" : ", ") + known;
    throw InputError(std::string(kSyntheticPrefix) + name +
                     ": no such synthetic input (there are " + names + ")");
  }
  return inputOfScans("synthetic", sensor->second());
}

}  // namespace mvog_bench
