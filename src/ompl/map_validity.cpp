#include "mvog_ompl/map_validity.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/base/spaces/SE3StateSpace.h>

namespace mvog_ompl {
namespace ob = ompl::base;
namespace {

/// Refuses what the checks could not use, before any planning.
void requireUsable(const ob::SpaceInformationPtr& space_information, const mvog::Map& map,
                   const SphereRobot& robot, const mvog::PlanningConfig& planning) {
  robot.validate(map.config());
  planning.validate();
  const ob::StateSpace& space = *space_information->getStateSpace();
  const bool real_vector_3 =
      space.getType() == ob::STATE_SPACE_REAL_VECTOR && space.getDimension() == 3;
  if (!real_vector_3 && space.getType() != ob::STATE_SPACE_SE3) {
    throw mvog::ConfigError("state space: must be RealVectorStateSpace(3) or SE3StateSpace, not '" +
                            space.getName() + "'");
  }
}

/// The check of the sphere swept from `from` to `to` (a sphere where they are equal).
mvog::SegmentCheck checkSweep(const mvog::Map& map, const Eigen::Vector3d& from,
                              const Eigen::Vector3d& to, double radius,
                              const mvog::PlanningConfig& planning) {
  try {
    return mvog::checkSegments(map, {{from, to}}, radius, planning).front();
  } catch (const mvog::ConfigError&) {
    // Not finite, or beyond max_coordinate: nowhere the robot may be.
    mvog::SegmentCheck outside;
    outside.state = mvog::OccupancyState::kOccupied;
    outside.blocked_at = 0.0;
    return outside;
  }
}

}  // namespace

void SphereRobot::validate(const mvog::MapConfig& map) const {
  if (!(std::isfinite(radius) && radius >= 0.0 && radius <= map.max_coordinate)) {
    throw mvog::ConfigError("radius: must be finite, >= 0 and at most the map's max_coordinate");
  }
}

bool passable(mvog::OccupancyState state, bool allow_unknown) {
  return state == mvog::OccupancyState::kFree ||
         (allow_unknown && state == mvog::OccupancyState::kUnknown);
}

Eigen::Vector3d positionOf(const ob::StateSpace& space, const ob::State* state) {
  if (space.getType() == ob::STATE_SPACE_SE3) {
    const auto* pose = state->as<ob::SE3StateSpace::StateType>();
    return {pose->getX(), pose->getY(), pose->getZ()};
  }
  if (space.getType() == ob::STATE_SPACE_REAL_VECTOR && space.getDimension() == 3) {
    const double* values = state->as<ob::RealVectorStateSpace::StateType>()->values;
    return {values[0], values[1], values[2]};
  }
  throw mvog::ConfigError("state space: must be RealVectorStateSpace(3) or SE3StateSpace, not '" +
                          space.getName() + "'");
}

MapValidityChecker::MapValidityChecker(const ob::SpaceInformationPtr& space_information,
                                       const mvog::Map& map, const SphereRobot& robot,
                                       const mvog::PlanningConfig& planning)
    : ob::StateValidityChecker(space_information), map_(map), robot_(robot), planning_(planning) {
  requireUsable(space_information, map, robot, planning);
}

bool MapValidityChecker::isValid(const ob::State* state) const {
  const Eigen::Vector3d position = positionOf(*si_->getStateSpace(), state);
  return passable(checkSweep(map_, position, position, robot_.radius, planning_).state,
                  robot_.allow_unknown);
}

MapMotionValidator::MapMotionValidator(const ob::SpaceInformationPtr& space_information,
                                       const mvog::Map& map, const SphereRobot& robot,
                                       const mvog::PlanningConfig& planning)
    : ob::MotionValidator(space_information), map_(map), robot_(robot), planning_(planning) {
  requireUsable(space_information, map, robot, planning);
}

mvog::SegmentCheck MapMotionValidator::check(const ob::State* from, const ob::State* to) const {
  const ob::StateSpace& space = *si_->getStateSpace();
  return checkSweep(map_, positionOf(space, from), positionOf(space, to), robot_.radius, planning_);
}

bool MapMotionValidator::checkMotion(const ob::State* from, const ob::State* to) const {
  const bool valid = passable(check(from, to).state, robot_.allow_unknown);
  if (valid) {
    ++valid_;
  } else {
    ++invalid_;
  }
  return valid;
}

bool MapMotionValidator::checkMotion(const ob::State* from, const ob::State* to,
                                     std::pair<ob::State*, double>& last_valid) const {
  const mvog::SegmentCheck result = check(from, to);
  if (passable(result.state, robot_.allow_unknown)) {
    ++valid_;
    return true;
  }
  ++invalid_;
  const ob::StateSpace& space = *si_->getStateSpace();
  const double length = (positionOf(space, to) - positionOf(space, from)).norm();
  // The sphere touches what blocks it at blocked_at: a micrometre short of it is clear.
  constexpr double kBackOff = 1e-6;
  const double fraction =
      length > 0.0 ? std::clamp((result.blocked_at - kBackOff) / length, 0.0, 1.0) : 0.0;
  last_valid.second = std::isfinite(fraction) ? fraction : 0.0;
  if (last_valid.first != nullptr) {
    space.interpolate(from, to, last_valid.second, last_valid.first);
  }
  return false;
}

void useMap(const ob::SpaceInformationPtr& space_information, const mvog::Map& map,
            const SphereRobot& robot, const mvog::PlanningConfig& planning) {
  space_information->setStateValidityChecker(
      std::make_shared<MapValidityChecker>(space_information, map, robot, planning));
  space_information->setMotionValidator(
      std::make_shared<MapMotionValidator>(space_information, map, robot, planning));
  space_information->setup();
}

}  // namespace mvog_ompl
