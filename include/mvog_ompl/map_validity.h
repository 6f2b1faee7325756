#pragma once

#include <utility>

#include <ompl/base/MotionValidator.h>
#include <ompl/base/SpaceInformation.h>
#include <ompl/base/StateValidityChecker.h>
#include <Eigen/Core>

#include "mvog/checks.h"
#include "mvog/map.h"
#include "mvog/planning_config.h"

// OMPL on an mvog::Map, for anyone with a map (ROS-free; library mvog_ompl, built when OMPL is
// found). The robot is a sphere: a state is valid where the sphere around its position is free
// in the map, a motion where the sphere swept along the straight segment between two states is,
// both checked exactly against the map's volumes (mvog::checkSegments), not by sampling points.
// The states are those of OMPL's RealVectorStateSpace(3) and SE3StateSpace (whose rotation a
// sphere ignores). The map must not change while they are used: the caller holds its lock.
namespace mvog_ompl {

/// The robot: a sphere, and what it may do in unknown space.
struct SphereRobot {
  double radius = 0.3;  // m: finite, >= 0, at most the map's max_coordinate
  // Unknown space: blocked (the default: only space seen free is flown through), or passable (an
  // explorer's optimism; occupied space still blocks).
  bool allow_unknown = false;

  /// Throws mvog::ConfigError naming the first invalid field.
  void validate(const mvog::MapConfig& map) const;
};

/// Whether the sphere may be where a check found `state`.
bool passable(mvog::OccupancyState state, bool allow_unknown);

/// The position (m, map frame) of `state`, a state of `space`. Throws mvog::ConfigError unless
/// `space` is a RealVectorStateSpace of 3 dimensions or an SE3StateSpace.
Eigen::Vector3d positionOf(const ompl::base::StateSpace& space, const ompl::base::State* state);

/// A state is valid if the sphere around its position is passable (a position that is not
/// finite or lies beyond the map's max_coordinate is not).
class MapValidityChecker : public ompl::base::StateValidityChecker {
 public:
  /// Keeps a reference to `map`. Throws mvog::ConfigError if `robot` or `planning` is invalid
  /// or the space is neither of the two.
  MapValidityChecker(const ompl::base::SpaceInformationPtr& space_information, const mvog::Map& map,
                     const SphereRobot& robot, const mvog::PlanningConfig& planning = {});

  bool isValid(const ompl::base::State* state) const override;

 private:
  const mvog::Map& map_;
  const SphereRobot robot_;
  const mvog::PlanningConfig planning_;
};

/// A motion is valid if the sphere swept along the straight segment between the two positions
/// is passable, ends included: exact where OMPL's DiscreteMotionValidator checks states at a
/// resolution and may step over a thin obstacle or cut a corner.
class MapMotionValidator : public ompl::base::MotionValidator {
 public:
  /// As MapValidityChecker's.
  MapMotionValidator(const ompl::base::SpaceInformationPtr& space_information, const mvog::Map& map,
                     const SphereRobot& robot, const mvog::PlanningConfig& planning = {});

  bool checkMotion(const ompl::base::State* from, const ompl::base::State* to) const override;
  /// If the motion is invalid, `last_valid` gets a state short of where the swept sphere first
  /// meets space it may not enter (with unknown space allowed: where it first meets occupied or
  /// unknown space, which is valid but conservative), and the fraction of the motion it lies at.
  bool checkMotion(const ompl::base::State* from, const ompl::base::State* to,
                   std::pair<ompl::base::State*, double>& last_valid) const override;

 private:
  /// The exact check of the segment between the two states' positions; a segment the core
  /// refuses (a point beyond max_coordinate, not finite) is occupied from its start.
  mvog::SegmentCheck check(const ompl::base::State* from, const ompl::base::State* to) const;

  const mvog::Map& map_;
  const SphereRobot robot_;
  const mvog::PlanningConfig planning_;
};

/// Gives `space_information` a MapValidityChecker and a MapMotionValidator on `map`, and sets it
/// up.
void useMap(const ompl::base::SpaceInformationPtr& space_information, const mvog::Map& map,
            const SphereRobot& robot, const mvog::PlanningConfig& planning = {});

}  // namespace mvog_ompl
