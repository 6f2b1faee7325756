// Builds an MVOG from a scene generated in code (a room with desks, a pillar and clutter, seen
// by a depth camera from several poses), prints its statistics and saves it. It needs no ROS:
// it is the core library's own demonstration. Usage:
//   mvog_synthetic_demo [--output FILE] [--resolution METRES]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "mvog/map.h"
#include "mvog/map_io.h"
#include "mvog_scene/scene.h"

namespace {

/// The room: floor, ceiling and four walls as thin boxes, plus furniture.
mvog_scene::Scene makeRoom() {
  const double t = 0.1;
  mvog_scene::Scene room;
  room.boxes = {
      {{-4, -3, -t}, {4, 3, 0}},      // floor
      {{-4, -3, 3}, {4, 3, 3 + t}},   // ceiling
      {{-4 - t, -3, 0}, {-4, 3, 3}},  // walls
      {{4, -3, 0}, {4 + t, 3, 3}},
      {{-4, -3 - t, 0}, {4, -3, 3}},
      {{-4, 3, 0}, {4, 3 + t, 3}},
      {{1.0, 1.5, 0.72}, {3.0, 2.5, 0.75}},  // desk top and legs
      {{1.0, 1.5, 0}, {1.05, 1.55, 0.72}},
      {{2.95, 2.45, 0}, {3.0, 2.5, 0.72}},
      {{-3.0, -2.5, 0}, {-1.5, -1.8, 0.8}},  // low cabinet
      {{-0.2, -0.2, 0}, {0.2, 0.2, 3}},      // pillar
      {{2.0, -2.0, 0}, {2.4, -1.6, 0.4}},    // boxes on the floor
      {{2.1, -1.9, 0.4}, {2.3, -1.7, 0.7}},
  };
  return room;
}

}  // namespace

int main(int argc, char** argv) {
  std::string output = "synthetic_room.mvog";
  mvog::MapConfig map_config;
  map_config.resolution = 0.05;
  for (int k = 1; k < argc; ++k) {
    const std::string arg = argv[k];
    if (arg == "--output" && k + 1 < argc) {
      output = argv[++k];
    } else if (arg == "--resolution" && k + 1 < argc) {
      map_config.resolution = std::atof(argv[++k]);
    } else {
      std::fprintf(stderr, "usage: %s [--output FILE] [--resolution METRES]\n", argv[0]);
      return arg == "--help" || arg == "-h" ? 0 : 2;
    }
  }
  try {
    mvog::Map map(map_config);
    mvog::InsertionConfig insertion;
    insertion.max_range = 8.0;
    const mvog_scene::Scene room = makeRoom();
    std::vector<mvog::Scan> scans;
    for (int k = 0; k < 24; ++k) {  // a loop around the pillar, turning to see every wall
      const double angle = 2.0 * M_PI * k / 24.0;
      const Eigen::Vector3d position(2.0 * std::cos(angle), 1.6 * std::sin(angle),
                                     1.4 + 0.3 * std::sin(3 * angle));
      scans.push_back(mvog_scene::depthScan(room, mvog_scene::DepthCamera(), position,
                                            angle + M_PI / 2.0 + 0.4, 0.25, insertion.max_range));
    }
    mvog::InsertionResult result;
    const auto start = std::chrono::steady_clock::now();
    for (const mvog::Scan& scan : scans) result += map.insertScan(scan, insertion);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    mvog::saveMap(map, output);

    const mvog::MemoryUsage memory = map.memoryUsage();
    std::printf("resolution           %.3f m\n", map.resolution());
    std::printf("scans                %zu\n", scans.size());
    std::printf("readings inserted    %zu (%zu obstacle, %zu out of range)\n", result.inserted(),
                result.obstacle_readings, result.out_of_range_readings);
    std::printf("insertion            %.3f s, %.0f readings/s\n", seconds,
                static_cast<double>(result.inserted()) / seconds);
    std::printf("cells with volumes   %zu (minimal grid %zu cells)\n", memory.cells_with_volumes,
                memory.minimal_grid_cells);
    std::printf("volumes              %zu positive, %zu negative\n", memory.positive_volumes,
                memory.negative_volumes);
    std::printf("memory held          %zu bytes\n", memory.bytes_held);
    std::printf("Table I accounting   %zu bytes\n", memory.table_one_bytes);
    const auto desk = map.occupancy({2.0, 2.0, 0.74});
    const auto middle = map.occupancy({3.0, 0.0, 1.5});
    std::printf("p(desk top)          %.3f\n", desk.probability.value_or(NAN));
    std::printf("p(free air)          %.3f\n", middle.probability.value_or(NAN));
    std::printf("saved                %s\n", output.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mvog_synthetic_demo: %s\n", e.what());
    return 1;
  }
  return 0;
}
