// OMPL on an mvog::Map (mvog_ompl): the exact swept-sphere motion validator beside OMPL's default
// DiscreteMotionValidator at the map's resolution, and the planner through a door (BENCHMARKS.md,
// "Planning with OMPL"). ROS-free. Usage:
//   mvog_ompl_bench [--map FILE | --graph FILE [--resolution R]] [--start X,Y,Z --goal X,Y,Z]
//                   [--radius R] [--edges N] [--plans N] [--time-limit S] [--allow-unknown]
//                   [--print-path] [--close-box X0,Y0,Z0,X1,Y1,Z1] [--seed N]
// Without --map: the office of the demo (mvog_scene::officeScene) split by a wall at x = 3.0-3.1
// with a door (y in [-0.5, 0.5], z up to 2.0), mapped at 0.05 m by a rotating lidar and a tilting
// laser from poses on both sides; then again with the door closed by a box, where no path may be
// found. With --map: a saved map (e.g. a recording replayed through the server, ~save_map); with
// --graph: an OctoMap scan graph of $MVOG_DATA_DIR (kurt3d_3scans.graph) mapped at --resolution
// (default 0.1 m) from its hits; each with the start and goal to plan between. --close-box: plans
// a second time in the map with the box made occupied space (the columns over its cells replaced
// by one occupied volume over its heights: a door closed).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <ompl/base/DiscreteMotionValidator.h>
#include <ompl/base/ScopedState.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>

#include "input.h"  // mvog_bench's scan graph reader (src/tools/bench), ROS-free
#include "mvog/checks.h"
#include "mvog/map_io.h"
#include "mvog_ompl/map_validity.h"
#include "mvog_ompl/sphere_planner.h"
#include "mvog_scene/scene.h"

namespace {

namespace ob = ompl::base;
using Clock = std::chrono::steady_clock;

struct Options {
  std::string map_file;
  std::string graph_file;
  double resolution = 0.1;                // of a map built from --graph
  Eigen::Vector3d start{-3.0, 1.0, 1.2};  // in the office, west of the wall
  Eigen::Vector3d goal{4.5, 0.5, 1.2};    // east of it
  double radius = 0.25;
  int edges = 20000;
  int plans = 20;
  double time_limit = 1.0;
  bool allow_unknown = false;
  bool print_path = false;             // the first path's waypoints, to see where it passes
  std::optional<mvog::Box> close_box;  // made occupied for a second plan (--map, --graph)
  unsigned seed = 1;
};

/// The office split by a wall with a door; the door closed by a box if `closed`.
mvog_scene::Scene officeWithDoor(bool closed) {
  mvog_scene::Scene scene = mvog_scene::officeScene();
  scene.boxes.push_back({{3.0, -4.0, 0.0}, {3.1, -0.5, 3.0}});
  scene.boxes.push_back({{3.0, 0.5, 0.0}, {3.1, 4.0, 3.0}});
  scene.boxes.push_back({{3.0, -0.5, 2.0}, {3.1, 0.5, 3.0}});  // the lintel
  if (closed) scene.boxes.push_back({{3.0, -0.5, 0.0}, {3.1, 0.5, 2.0}});
  return scene;
}

mvog::Map mapOf(const mvog_scene::Scene& scene) {
  mvog::MapConfig config;
  config.resolution = 0.05;
  mvog::Map map(config);
  mvog::InsertionConfig insertion;
  insertion.max_range = 10.0;
  for (double x = -5.0; x <= 5.5; x += 1.5) {
    for (double y = -3.0; y <= 3.0; y += 1.5) {
      for (const double z : {0.8, 1.6}) {
        const Eigen::Vector3d position(x, y, z);
        if (scene.distance(position) < 0.3) continue;
        map.insertScan(mvog_scene::lidarScan(scene, mvog_scene::RotatingLidar(), position,
                                             insertion.max_range),
                       insertion);
      }
      const Eigen::Vector3d laser(x, y, 1.2);
      if (scene.distance(laser) < 0.3) continue;
      for (const double yaw : {0.0, M_PI / 2.0, M_PI, 3.0 * M_PI / 2.0}) {
        map.insertScan(mvog_scene::tiltingLaserScan(scene, mvog_scene::TiltingLaser(), laser, yaw,
                                                    insertion.max_range),
                       insertion);
      }
    }
  }
  return map;
}

/// The map of a scan graph's hits at options.resolution.
mvog::Map graphMap(const Options& options) {
  mvog::MapConfig config;
  config.resolution = options.resolution;
  mvog::Map map(config);
  for (const mvog::Scan& scan : mvog_bench::loadScanGraph(options.graph_file).scans) {
    map.insertScan(scan);
  }
  return map;
}

Eigen::Vector3d parsePoint(const char* text) {
  Eigen::Vector3d point;
  if (std::sscanf(text, "%lf,%lf,%lf", &point.x(), &point.y(), &point.z()) != 3) {
    throw std::invalid_argument(std::string("not a point X,Y,Z: ") + text);
  }
  return point;
}

mvog::Box parseBox(const char* text) {
  mvog::Box box;
  if (std::sscanf(text, "%lf,%lf,%lf,%lf,%lf,%lf", &box.min.x(), &box.min.y(), &box.min.z(),
                  &box.max.x(), &box.max.y(), &box.max.z()) != 6 ||
      (box.min.array() > box.max.array()).any()) {
    throw std::invalid_argument(std::string("not a box X0,Y0,Z0,X1,Y1,Z1 (min, max): ") + text);
  }
  return box;
}

/// `map` with the columns over `box`'s cells replaced by one occupied volume over its heights.
void makeOccupied(mvog::Map& map, const mvog::Box& box) {
  const mvog::CellRange cells =
      map.cellsInRectangle(box.min.x(), box.min.y(), box.max.x(), box.max.y());
  const auto bottom = static_cast<float>(box.min.z() / map.resolution());
  const auto top = static_cast<float>(box.max.z() / map.resolution());
  std::vector<mvog::Map::CellAssignment> columns;
  for (int y = cells.min.y; y <= cells.max.y; ++y) {
    for (int x = cells.min.x; x <= cells.max.x; ++x) {
      columns.push_back({{x, y}, {{{bottom, top, top - bottom}}, {}}});
    }
  }
  map.setCellVolumes(columns);
}

double median(std::vector<double> values) {
  if (values.empty()) return std::nan("");
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

/// Random edges between valid states within the planning bounds, each checked by both
/// validators: how many the discrete one accepts and ours refuses, and each one's time per edge.
void compareValidators(const mvog::Map& map, const Options& options) {
  mvog_ompl::PlanRequest request;
  request.start = options.start;
  request.goal = options.goal;
  request.robot = {options.radius, options.allow_unknown};
  const mvog_ompl::PlanBounds box = mvog_ompl::planBounds(map, request);
  const std::shared_ptr<ob::RealVectorStateSpace> space = mvog_ompl::boundedSpace(box);
  auto space_information = std::make_shared<ob::SpaceInformation>(space);
  mvog_ompl::useMap(space_information, map, request.robot);
  // OMPL's default: states every resolution along a motion, as a fraction of the space's extent.
  space_information->setStateValidityCheckingResolution(map.resolution() /
                                                        space->getMaximumExtent());
  space_information->setup();
  const mvog_ompl::MapMotionValidator exact(space_information, map, request.robot);
  ob::DiscreteMotionValidator discrete(space_information);

  std::mt19937 rng(options.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<ob::ScopedState<ob::RealVectorStateSpace>> states;
  states.reserve(2 * static_cast<std::size_t>(options.edges));
  const auto random_valid = [&]() {
    ob::ScopedState<ob::RealVectorStateSpace> state(space);
    do {
      for (int axis = 0; axis < 3; ++axis) {
        state[axis] = box.min[axis] + unit(rng) * (box.max[axis] - box.min[axis]);
      }
    } while (!space_information->isValid(state.get()));
    return state;
  };
  for (int k = 0; k < options.edges; ++k) {
    states.push_back(random_valid());
    ob::ScopedState<ob::RealVectorStateSpace> end(space);
    // Edges up to 2 m long, as RRT-Connect's range in a room.
    do {
      end = states.back();
      const Eigen::Vector3d step =
          2.0 * unit(rng) *
          Eigen::Vector3d(unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5).normalized();
      for (int axis = 0; axis < 3; ++axis) end[axis] = end[axis] + step[axis];
    } while (!space->satisfiesBounds(end.get()) || !space_information->isValid(end.get()));
    states.push_back(end);
  }
  std::size_t discrete_accepted = 0;
  std::size_t exact_accepted = 0;
  std::size_t refused_by_exact_only = 0;
  std::size_t refused_by_discrete_only = 0;
  std::vector<char> discrete_says(states.size() / 2);
  auto begin = Clock::now();
  for (std::size_t k = 0; k + 1 < states.size(); k += 2) {
    discrete_says[k / 2] = discrete.checkMotion(states[k].get(), states[k + 1].get()) ? 1 : 0;
  }
  const double discrete_seconds = std::chrono::duration<double>(Clock::now() - begin).count();
  std::vector<char> exact_says(states.size() / 2);
  begin = Clock::now();
  for (std::size_t k = 0; k + 1 < states.size(); k += 2) {
    exact_says[k / 2] = exact.checkMotion(states[k].get(), states[k + 1].get()) ? 1 : 0;
  }
  const double exact_seconds = std::chrono::duration<double>(Clock::now() - begin).count();
  for (std::size_t k = 0; k < exact_says.size(); ++k) {
    discrete_accepted += discrete_says[k];
    exact_accepted += exact_says[k];
    refused_by_exact_only += discrete_says[k] && !exact_says[k] ? 1 : 0;
    refused_by_discrete_only += !discrete_says[k] && exact_says[k] ? 1 : 0;
  }
  const double edges = static_cast<double>(exact_says.size());
  std::printf(
      "| edges | accepted, discrete at %.2f m | accepted, exact | accepted by the discrete, "
      "refused by the exact | refused by the discrete only | us per edge, discrete | us "
      "per edge, exact |\n|---:|---:|---:|---:|---:|---:|---:|\n",
      map.resolution());
  std::printf("| %.0f | %zu | %zu | %zu (%.2f %% of its accepted) | %zu | %.1f | %.1f |\n", edges,
              discrete_accepted, exact_accepted, refused_by_exact_only,
              100.0 * static_cast<double>(refused_by_exact_only) /
                  std::max<double>(1.0, static_cast<double>(discrete_accepted)),
              refused_by_discrete_only, 1e6 * discrete_seconds / edges,
              1e6 * exact_seconds / edges);
}

/// Whether some point of the path, sampled every 1/10 of the resolution, lies in an occupied
/// cell (the re-check independent of the planner's).
bool crossesOccupied(const mvog::Map& map, const std::vector<Eigen::Vector3d>& waypoints) {
  const double step = map.resolution() / 10.0;
  for (std::size_t k = 1; k < waypoints.size(); ++k) {
    const Eigen::Vector3d delta = waypoints[k] - waypoints[k - 1];
    const int steps = std::max(1, static_cast<int>(std::ceil(delta.norm() / step)));
    for (int s = 0; s <= steps; ++s) {
      const Eigen::Vector3d point = waypoints[k - 1] + delta * (static_cast<double>(s) / steps);
      if (map.occupancy(point).state(mvog::kDefaultOccupancyThreshold) ==
          mvog::OccupancyState::kOccupied) {
        return true;
      }
    }
  }
  return false;
}

void plan(const mvog::Map& map, const Options& options, const char* name) {
  mvog_ompl::PlanRequest request;
  request.start = options.start;
  request.goal = options.goal;
  request.robot = {options.radius, options.allow_unknown};
  request.time_limit = options.time_limit;
  std::vector<double> seconds;
  std::vector<double> lengths;
  int planned = 0;
  int crossing = 0;
  std::size_t edges_checked = 0;
  std::string last_message;
  for (int k = 0; k < options.plans; ++k) {
    const mvog_ompl::PlanResult result = mvog_ompl::planPath(map, request);
    seconds.push_back(result.seconds);
    edges_checked += result.edges_checked;
    if (result.status != mvog_ompl::PlanStatus::kPlanned) {
      last_message = result.message;
      continue;
    }
    if (options.print_path && planned == 0) {
      for (const Eigen::Vector3d& waypoint : result.waypoints) {
        std::printf("waypoint %.3f %.3f %.3f\n", waypoint.x(), waypoint.y(), waypoint.z());
      }
    }
    ++planned;
    crossing += crossesOccupied(map, result.waypoints) ? 1 : 0;
    double length = 0.0;
    for (std::size_t w = 1; w < result.waypoints.size(); ++w) {
      length += (result.waypoints[w] - result.waypoints[w - 1]).norm();
    }
    lengths.push_back(length);
  }
  std::printf("| %s | %d / %d | %.3f | %.3f | %.2f | %d | %.0f | %s |\n", name, planned,
              options.plans, median(seconds), *std::max_element(seconds.begin(), seconds.end()),
              median(lengths), crossing,
              static_cast<double>(edges_checked) / std::max(1, options.plans),
              last_message.empty() ? "" : last_message.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  try {
    for (int k = 1; k < argc; ++k) {
      const std::string arg = argv[k];
      const bool has_value = k + 1 < argc;
      if (arg == "--map" && has_value) {
        options.map_file = argv[++k];
      } else if (arg == "--graph" && has_value) {
        options.graph_file = argv[++k];
      } else if (arg == "--resolution" && has_value) {
        options.resolution = std::atof(argv[++k]);
      } else if (arg == "--start" && has_value) {
        options.start = parsePoint(argv[++k]);
      } else if (arg == "--goal" && has_value) {
        options.goal = parsePoint(argv[++k]);
      } else if (arg == "--radius" && has_value) {
        options.radius = std::atof(argv[++k]);
      } else if (arg == "--edges" && has_value) {
        options.edges = std::atoi(argv[++k]);
      } else if (arg == "--plans" && has_value) {
        options.plans = std::max(1, std::atoi(argv[++k]));
      } else if (arg == "--time-limit" && has_value) {
        options.time_limit = std::atof(argv[++k]);
      } else if (arg == "--close-box" && has_value) {
        options.close_box = parseBox(argv[++k]);
      } else if (arg == "--print-path") {
        options.print_path = true;
      } else if (arg == "--allow-unknown") {
        options.allow_unknown = true;
      } else if (arg == "--seed" && has_value) {
        options.seed = static_cast<unsigned>(std::atoi(argv[++k]));
      } else {
        std::fprintf(
            stderr,
            "usage: %s [--map FILE | --graph FILE [--resolution R]] [--start X,Y,Z "
            "--goal X,Y,Z] [--radius R] [--edges N] [--plans N] [--time-limit S] "
            "[--allow-unknown] [--print-path] [--close-box X0,Y0,Z0,X1,Y1,Z1] [--seed N]\n",
            argv[0]);
        return arg == "--help" || arg == "-h" ? 0 : 2;
      }
    }
    const auto begin = Clock::now();
    const std::string source = !options.map_file.empty()     ? options.map_file
                               : !options.graph_file.empty() ? options.graph_file
                                                             : "";
    const mvog::Map map = !options.map_file.empty()     ? mvog::loadMap(options.map_file)
                          : !options.graph_file.empty() ? graphMap(options)
                                                        : mapOf(officeWithDoor(false));
    std::printf("map: %s, %.3f m, built or loaded in %.1f s; radius %.2f m, unknown %s\n\n",
                source.empty() ? "the office with a wall and a door" : source.c_str(),
                map.resolution(), std::chrono::duration<double>(Clock::now() - begin).count(),
                options.radius, options.allow_unknown ? "allowed" : "not allowed");
    compareValidators(map, options);
    std::printf(
        "\n| map | planned | median s | max s | median length (m) | paths crossing an "
        "occupied cell | edges checked per plan | status of the last failure |\n"
        "|---|---:|---:|---:|---:|---:|---:|---|\n");
    plan(map, options, source.empty() ? "door open" : source.c_str());
    if (source.empty()) plan(mapOf(officeWithDoor(true)), options, "door closed");
    if (!source.empty() && options.close_box) {
      mvog::Map closed =
          !options.map_file.empty() ? mvog::loadMap(options.map_file) : graphMap(options);
      makeOccupied(closed, *options.close_box);
      plan(closed, options, "the box closed");
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mvog_ompl_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
