#include "mvog_ompl/sphere_planner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>
#include <string>

#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/geometric/SimpleSetup.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/util/Console.h>

namespace mvog_ompl {
namespace ob = ompl::base;
namespace og = ompl::geometric;
namespace {

/// `value` as printf's %g writes it (0.25, not 0.250000).
std::string shortNumber(double value) {
  std::ostringstream text;
  text << value;
  return text.str();
}

/// What the request gets wrong, or "" (the field named first).
std::string requestError(const mvog::Map& map, const PlanRequest& request) {
  const double max_coordinate = map.config().max_coordinate;
  for (const auto& [name, point] :
       {std::pair<const char*, const Eigen::Vector3d&>{"start", request.start},
        {"goal", request.goal}}) {
    if (!point.allFinite() || (point.array().abs() > max_coordinate).any()) {
      return std::string(name) + ": must be finite and within the map's max_coordinate";
    }
  }
  try {
    request.robot.validate(map.config());
  } catch (const mvog::ConfigError& e) {
    return e.what();
  }
  if (!(std::isfinite(request.time_limit) && request.time_limit > 0.0 &&
        request.time_limit <= kMaxPlanSeconds)) {
    return "time_limit: must be in (0, " + shortNumber(kMaxPlanSeconds) + "] s";
  }
  return "";
}

const char* stateName(mvog::OccupancyState state) {
  return state == mvog::OccupancyState::kOccupied ? "occupied" : "unknown";
}

/// Why the sphere may not be at `point`, or "" if it may.
std::string blockedAt(const mvog::Map& map, const Eigen::Vector3d& point, const SphereRobot& robot,
                      const mvog::PlanningConfig& planning, const char* name) {
  const mvog::OccupancyState state =
      mvog::checkSegments(map, {{point, point}}, robot.radius, planning).front().state;
  if (passable(state, robot.allow_unknown)) return "";
  return std::string(name) + ": the sphere of radius " + shortNumber(robot.radius) +
         " m there meets " + stateName(state) + " space" +
         (robot.allow_unknown ? "" : " (unknown space not allowed)");
}

}  // namespace

PlanBounds planBounds(const mvog::Map& map, const PlanRequest& request) {
  Eigen::Vector3d min = request.start.cwiseMin(request.goal);
  Eigen::Vector3d max = request.start.cwiseMax(request.goal);
  const double resolution = map.resolution();
  if (!map.empty()) {
    const mvog::CellRange cells = map.bounds();
    min.x() = std::min(min.x(), cells.min.x * resolution);
    min.y() = std::min(min.y(), cells.min.y * resolution);
    max.x() = std::max(max.x(), (cells.max.x + 1.0) * resolution);
    max.y() = std::max(max.y(), (cells.max.y + 1.0) * resolution);
    float bottom = std::numeric_limits<float>::infinity();
    float top = -std::numeric_limits<float>::infinity();
    map.forEachVolume([&](const mvog::CellIndex&, mvog::VolumeSign, const mvog::Volume& volume) {
      bottom = std::min(bottom, volume.bottom);
      top = std::max(top, volume.top);
    });
    min.z() = std::min(min.z(), bottom * resolution);
    max.z() = std::max(max.z(), top * resolution);
  }
  const double margin = request.robot.radius + resolution;
  const double max_coordinate = map.config().max_coordinate;
  return {(min.array() - margin).max(-max_coordinate), (max.array() + margin).min(max_coordinate)};
}

std::shared_ptr<ob::RealVectorStateSpace> boundedSpace(const PlanBounds& bounds) {
  auto space = std::make_shared<ob::RealVectorStateSpace>(3);
  ob::RealVectorBounds box(3);
  for (int axis = 0; axis < 3; ++axis) {
    box.setLow(axis, bounds.min[axis]);
    box.setHigh(axis, bounds.max[axis]);
  }
  space->setBounds(box);
  return space;
}

PlanResult planPath(const mvog::Map& map, const PlanRequest& request,
                    const mvog::PlanningConfig& planning) {
  const auto begin = std::chrono::steady_clock::now();
  PlanResult result;
  const auto finish = [&](PlanStatus status, std::string message) {
    result.status = status;
    result.message = std::move(message);
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
    return result;
  };
  if (std::string error = requestError(map, request); !error.empty()) {
    return finish(PlanStatus::kInvalidRequest, std::move(error));
  }
  if (std::string blocked = blockedAt(map, request.start, request.robot, planning, "start");
      !blocked.empty()) {
    return finish(PlanStatus::kStartBlocked, std::move(blocked));
  }
  if (std::string blocked = blockedAt(map, request.goal, request.robot, planning, "goal");
      !blocked.empty()) {
    return finish(PlanStatus::kGoalBlocked, std::move(blocked));
  }

  const std::shared_ptr<ob::RealVectorStateSpace> space = boundedSpace(planBounds(map, request));
  og::SimpleSetup setup(space);
  useMap(setup.getSpaceInformation(), map, request.robot, planning);
  const auto motion_validator = setup.getSpaceInformation()->getMotionValidator();
  ob::ScopedState<ob::RealVectorStateSpace> start(space);
  ob::ScopedState<ob::RealVectorStateSpace> goal(space);
  for (int axis = 0; axis < 3; ++axis) {
    start[axis] = request.start[axis];
    goal[axis] = request.goal[axis];
  }
  setup.setStartAndGoalStates(start, goal);
  setup.setPlanner(std::make_shared<og::RRTConnect>(setup.getSpaceInformation()));
  // OMPL reports on the console; the status and the message say what matters.
  ompl::msg::setLogLevel(ompl::msg::LOG_WARN);
  const ob::PlannerStatus solved = setup.solve(request.time_limit);
  result.edges_checked =
      motion_validator->getValidMotionCount() + motion_validator->getInvalidMotionCount();
  if (solved != ob::PlannerStatus::EXACT_SOLUTION) {
    return finish(PlanStatus::kNoPath,
                  "no path found within " + shortNumber(request.time_limit) +
                      " s: the start and the goal may not be joined through space a sphere of "
                      "radius " +
                      shortNumber(request.robot.radius) + " m may pass" +
                      (request.robot.allow_unknown ? "" : " (unknown space not allowed)"));
  }
  setup.simplifySolution(request.time_limit);
  result.edges_checked =
      motion_validator->getValidMotionCount() + motion_validator->getInvalidMotionCount();
  const og::PathGeometric& path = setup.getSolutionPath();
  std::vector<mvog::Segment> edges;
  for (unsigned k = 0; k < path.getStateCount(); ++k) {
    const auto* state = path.getState(k)->as<ob::RealVectorStateSpace::StateType>();
    result.waypoints.emplace_back(state->values[0], state->values[1], state->values[2]);
    if (k > 0) edges.push_back({result.waypoints[k - 1], result.waypoints[k]});
  }
  // Every edge once more, exactly: what is returned is what was checked.
  const std::vector<mvog::SegmentCheck> checks =
      mvog::checkSegments(map, edges, request.robot.radius, planning);
  for (std::size_t k = 0; k < checks.size(); ++k) {
    if (!passable(checks[k].state, request.robot.allow_unknown)) {
      result.waypoints.clear();
      return finish(PlanStatus::kPathRefused,
                    "edge " + std::to_string(k) + " of the simplified path meets " +
                        stateName(checks[k].state) + " space on its final check");
    }
  }
  return finish(PlanStatus::kPlanned, "");
}

}  // namespace mvog_ompl
