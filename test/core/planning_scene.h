// A room of known geometry for the planning queries' tests, built cell by cell with
// setCellVolumes (resolution 0.1 m: grid units are decimetres), under the default model rules:
//
//   y (m)
//   3.0 ┤· · · · · · · · · · · · · · · · · · · ·   never observed beyond y = 3 (unexplored edge)
//       │                                      █
//       │                                      █
//   1.8 ┤                                      ·   door: x in [4.0, 4.1), y in [1.0, 1.8),
//       │          ┌────────┐                  ·   free up to 2.0 m under a lintel
//   1.0 ┤          │  desk  │                  ·
//       │          └────────┘                  █
//     0 ┼█ █ █ █ █ █ █ █ █ █ █ █ █ █ █ █ █ █ █ █   walls (x = -0.1, y = -0.1, x = 4.0), full height
//      -0.1        1.0      2.0               4.0  x (m)
//
// Every cell of the room: the floor occupied over z in [-0.1, 0], free up to the ceiling at 2.5,
// the ceiling occupied over [2.5, 2.6], unknown above. The desk (x, y in [1.0, 2.0) x [0.5, 1.5))
// has its board occupied over [0.7, 0.8], free under and above it. A pillar occupies the cell
// x, y in [3.0, 3.1) x [2.0, 2.1) from floor to ceiling.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "mvog/map.h"

namespace mvog {
namespace test {

constexpr double kSceneResolution = 0.1;

/// Positive volume (obstacle) over [bottom, top] (grid units) of density `density`.
inline Volume obstacle(float bottom, float top, float density = 5.0f) {
  return {bottom, top, density * (top - bottom)};
}
/// Negative volume (free space) over [bottom, top] of density `density`.
inline Volume freeSpace(float bottom, float top, float density = 3.0f) {
  return {bottom, top, density * (top - bottom)};
}

/// A column of the room: floor, free space, ceiling.
inline CellVolumes roomColumn() {
  return {{obstacle(-1, 0), obstacle(25, 26)}, {freeSpace(0, 25)}};
}
/// The desk: the board over [7, 8] splits the free space (under the model's split rule the
/// negative list holds a piece spanning exactly the board, of low density there).
inline CellVolumes deskColumn() {
  return {{obstacle(-1, 0), obstacle(7, 8), obstacle(25, 26)},
          {freeSpace(0, 7), freeSpace(7, 8, 0.1f), freeSpace(8, 25)}};
}
inline CellVolumes wallColumn() { return {{obstacle(-1, 26)}, {}}; }
/// The door: free up to 2.0 m, the lintel above.
inline CellVolumes doorColumn() {
  return {{obstacle(-1, 0), obstacle(20, 26)}, {freeSpace(0, 20)}};
}

inline bool inDesk(int x, int y) { return x >= 10 && x < 20 && y >= 5 && y < 15; }
inline bool inDoor(int x, int y) { return x == 40 && y >= 10 && y < 18; }
inline bool isPillar(int x, int y) { return x == 30 && y == 20; }

/// The columns of the scene.
inline std::vector<Map::CellAssignment> sceneCells() {
  std::vector<Map::CellAssignment> cells;
  for (int y = -1; y < 30; ++y) {
    for (int x = -1; x <= 40; ++x) {
      const bool wall = x == -1 || y == -1 || x == 40;
      CellVolumes column = inDoor(x, y)             ? doorColumn()
                           : wall || isPillar(x, y) ? wallColumn()
                           : inDesk(x, y)           ? deskColumn()
                                                    : roomColumn();
      cells.push_back({{x, y}, column});
    }
  }
  return cells;
}

inline Map sceneMap() {
  MapConfig config;
  config.resolution = kSceneResolution;
  Map map(config);
  map.setCellVolumes(sceneCells());
  return map;
}

// ---- The same kind of room, scanned -------------------------------------------------------
//
// A room x, y in [-3, 3] x [-2, 2], floor at z = 0, ceiling at 2.5, walls 0.2 m thick, a door in
// the wall x = 3 (y in [-0.4, 0.4], up to z = 2.0) opening onto a floor up to a wall at x = 5;
// a table (top over z in [0.7, 0.75], x in [0.5, 1.5], y in [-1.5, -0.5], on four legs) and a
// cabinet (x in [-2.5, -2.0], y in [1.0, 1.8], up to z = 1.2). Mapped with insertScan at 0.1 m
// from four poses at z = 1.2 and one at 0.4 that sees under the table, each a sphere of rays
// every 2 degrees; rays meeting nothing within 8 m are out-of-range readings.

struct SolidBox {
  Eigen::Vector3d min;
  Eigen::Vector3d max;
};

inline std::vector<SolidBox> scannedRoomSolids() {
  return {
      {{-3.2, -2.2, -0.2}, {3.2, 2.2, 0.0}},  // floor
      {{-3.2, -2.2, 2.5}, {3.2, 2.2, 2.7}},   // ceiling
      {{-3.2, -2.2, 0.0}, {-3.0, 2.2, 2.5}},  // wall x = -3
      {{-3.2, -2.2, 0.0}, {3.2, -2.0, 2.5}},  // wall y = -2
      {{-3.2, 2.0, 0.0}, {3.2, 2.2, 2.5}},    // wall y = 2
      {{3.0, -2.2, 0.0}, {3.2, -0.4, 2.5}},   // wall x = 3, beside the door
      {{3.0, 0.4, 0.0}, {3.2, 2.2, 2.5}},
      {{3.0, -0.4, 2.0}, {3.2, 0.4, 2.5}},   // the lintel
      {{5.0, -3.0, -0.2}, {5.2, 3.0, 2.5}},  // the wall beyond the door, and the floor there
      {{3.2, -3.0, -0.2}, {5.0, 3.0, 0.0}},
      {{0.5, -1.5, 0.7}, {1.5, -0.5, 0.75}},  // the table's top and legs
      {{0.5, -1.5, 0.0}, {0.55, -1.45, 0.7}},
      {{1.45, -1.5, 0.0}, {1.5, -1.45, 0.7}},
      {{0.5, -0.55, 0.0}, {0.55, -0.5, 0.7}},
      {{1.45, -0.55, 0.0}, {1.5, -0.5, 0.7}},
      {{-2.5, 1.0, 0.0}, {-2.0, 1.8, 1.2}},  // the cabinet
  };
}

/// Distance from `origin` along the unit direction `d` to the first solid, or infinity.
inline double castRay(const Eigen::Vector3d& origin, const Eigen::Vector3d& d) {
  double nearest = std::numeric_limits<double>::infinity();
  for (const SolidBox& box : scannedRoomSolids()) {
    double enter = 0.0;
    double exit = nearest;
    for (int axis = 0; axis < 3 && enter <= exit; ++axis) {
      if (d[axis] == 0.0) {
        if (origin[axis] < box.min[axis] || origin[axis] > box.max[axis]) exit = -1.0;
        continue;
      }
      double a = (box.min[axis] - origin[axis]) / d[axis];
      double b = (box.max[axis] - origin[axis]) / d[axis];
      if (a > b) std::swap(a, b);
      enter = std::max(enter, a);
      exit = std::min(exit, b);
    }
    if (enter <= exit && enter > 0.0) nearest = enter;
  }
  return nearest;
}

/// The scans of the scanned room, one per pose.
inline std::vector<Scan> scannedRoomScans() {
  constexpr double kMaxRange = 8.0;
  const Eigen::Vector3d poses[] = {
      {-1.5, 0.0, 1.2}, {1.5, 0.8, 1.2}, {0.0, -1.0, 1.2}, {2.0, -1.2, 1.2}, {2.3, -1.0, 0.4}};
  std::vector<Scan> scans;
  for (const Eigen::Vector3d& origin : poses) {
    Scan scan;
    scan.origin = origin;
    for (int elevation = -89; elevation <= 89; elevation += 2) {
      for (int azimuth = 0; azimuth < 360; azimuth += 2) {
        const double e = elevation * M_PI / 180.0;
        const double a = azimuth * M_PI / 180.0;
        const Eigen::Vector3d d(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
        const double range = castRay(origin, d);
        if (range <= kMaxRange) {
          scan.hits.push_back((origin + range * d).cast<float>());
        } else {
          scan.out_of_range.push_back((origin + kMaxRange * d).cast<float>());
        }
      }
    }
    scans.push_back(std::move(scan));
  }
  return scans;
}

inline Map scannedRoomMap() {
  MapConfig config;
  config.resolution = kSceneResolution;
  Map map(config);
  for (const Scan& scan : scannedRoomScans()) map.insertScan(scan);
  return map;
}

}  // namespace test
}  // namespace mvog
