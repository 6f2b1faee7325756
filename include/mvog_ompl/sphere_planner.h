#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <Eigen/Core>

#include "mvog/map.h"
#include "mvog/planning_config.h"
#include "mvog_ompl/map_validity.h"

namespace mvog_ompl {

/// How a planning request ended (the values of mvog/PlanPath's status).
enum class PlanStatus : std::uint8_t {
  kPlanned = 0,         // a path, every edge checked exactly once more
  kInvalidRequest = 1,  // a field out of its range (the message names it)
  kStartBlocked = 2,    // the sphere at the start is not passable
  kGoalBlocked = 3,     // the sphere at the goal is not passable
  kNoPath = 4,          // none found within the time limit
  kPathRefused = 5,     // the simplified path failed its final check (a bug: never expected)
};

/// A path for a sphere from `start` to `goal` (m, map frame).
struct PlanRequest {
  Eigen::Vector3d start = Eigen::Vector3d::Zero();
  Eigen::Vector3d goal = Eigen::Vector3d::Zero();
  SphereRobot robot;
  double time_limit = 1.0;  // s for the search (the simplification gets as much at most)
};

struct PlanResult {
  PlanStatus status = PlanStatus::kInvalidRequest;
  std::string message;                     // why, for anything but kPlanned
  std::vector<Eigen::Vector3d> waypoints;  // from start to goal, kPlanned only
  double seconds = 0.0;                    // spent planning, simplifying and checking
  std::size_t edges_checked = 0;           // swept-sphere checks the planner made
};

/// s: the longest search planPath accepts (the map must not change meanwhile).
constexpr double kMaxPlanSeconds = 60.0;

/// The box planPath searches: the map's known cells and heights (every volume's), with the
/// start and the goal, grown by the robot's radius and one cell.
struct PlanBounds {
  Eigen::Vector3d min;
  Eigen::Vector3d max;
};
PlanBounds planBounds(const mvog::Map& map, const PlanRequest& request);

/// OMPL's RealVectorStateSpace(3) over `bounds`.
std::shared_ptr<ompl::base::RealVectorStateSpace> boundedSpace(const PlanBounds& bounds);

/// Plans with OMPL's RRT-Connect in RealVectorStateSpace(3) within planBounds, each state and
/// motion checked exactly (MapValidityChecker, MapMotionValidator); simplifies the path
/// (shortcuts and smoothing, checked the same way), then checks every edge of the result once
/// more (mvog::checkSegments). The map must not change meanwhile (the caller holds its lock).
/// Never throws for a bad request: the status and the message say what was wrong.
PlanResult planPath(const mvog::Map& map, const PlanRequest& request,
                    const mvog::PlanningConfig& planning = {});

}  // namespace mvog_ompl
