// OMPL on an mvog::Map (mvog_ompl/map_validity.h, mvog_ompl/sphere_planner.h): the state
// validity checker and the motion validator against brute force on random maps, and the planner
// on the scanned room with its door (test/core/planning_scene.h).
//
// The validity checker, against dense sampling of the sphere (Map::occupancy at points of a grid
// 1/4 of the resolution apart, 1/10 in z): where it says valid, no sample within the radius is
// impassable; where it says invalid, some sample within the radius grown by two steps is (the
// exact check sees what lies between samples, never farther than that).
// The motion validator, against the (tested) validity checker at positions along the segment
// 1/10 of the resolution apart: where it says valid, every such sphere is valid; where it says
// invalid, some sphere grown by one step is not (the swept sphere first meets what blocks it
// between two positions); its last valid state, and every sphere before it, are valid. Where it
// says valid, OMPL's DiscreteMotionValidator, which checks a subset, says so too.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <memory>
#include <random>
#include <vector>

#include <ompl/base/DiscreteMotionValidator.h>
#include <ompl/base/ScopedState.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/base/spaces/SE3StateSpace.h>

#include "../core/planning_scene.h"
#include "../core/test_util.h"
#include "mvog_ompl/map_validity.h"
#include "mvog_ompl/sphere_planner.h"

namespace mvog_ompl {
namespace {

namespace ob = ompl::base;
constexpr double kHalfExtent = 3.0;  // m: the random maps' readings, and the states sampled

ob::SpaceInformationPtr realVectorSpace() {
  auto space = std::make_shared<ob::RealVectorStateSpace>(3);
  space->setBounds(-kHalfExtent - 1.0, kHalfExtent + 1.0);
  auto space_information = std::make_shared<ob::SpaceInformation>(space);
  // The validity checker is set per test; OMPL wants one before setup.
  space_information->setStateValidityChecker([](const ob::State*) { return true; });
  space_information->setup();
  return space_information;
}

void setPosition(ob::State* state, const Eigen::Vector3d& position) {
  double* values = state->as<ob::RealVectorStateSpace::StateType>()->values;
  for (int axis = 0; axis < 3; ++axis) values[axis] = position[axis];
}

bool passableAt(const mvog::Map& map, const Eigen::Vector3d& point, bool allow_unknown) {
  return passable(map.occupancy(point).state(mvog::kDefaultOccupancyThreshold), allow_unknown);
}

/// Whether every sample of the grid (1/4 of the resolution apart, 1/10 in z) within `radius` of
/// `centre` is passable.
bool samplesPassable(const mvog::Map& map, const Eigen::Vector3d& centre, double radius,
                     bool allow_unknown) {
  const double step = map.resolution() / 4.0;
  const double z_step = map.resolution() / 10.0;
  const int n = static_cast<int>(std::ceil(radius / step));
  const int n_z = static_cast<int>(std::ceil(radius / z_step));
  for (int i = -n; i <= n; ++i) {
    for (int j = -n; j <= n; ++j) {
      for (int k = -n_z; k <= n_z; ++k) {
        const Eigen::Vector3d offset(i * step, j * step, k * z_step);
        if (offset.norm() > radius) continue;
        if (!passableAt(map, centre + offset, allow_unknown)) return false;
      }
    }
  }
  return true;
}

Eigen::Vector3d randomPosition(std::mt19937& rng) {
  std::uniform_real_distribution<double> coordinate(-kHalfExtent, kHalfExtent);
  return {coordinate(rng), coordinate(rng), coordinate(rng) / 2.0};
}

TEST(MapValidityChecker, AgreesWithDenseSamplingOnRandomMaps) {
  const double radii[] = {0.0, 0.12, 0.3};
  std::size_t valid = 0;
  std::size_t invalid = 0;
  for (unsigned seed = 1; seed <= 3; ++seed) {
    const mvog::Map map = mvog::test::randomMap(seed, 0.1, kHalfExtent, 4);
    std::mt19937 rng(seed);
    const ob::SpaceInformationPtr space_information = realVectorSpace();
    ob::ScopedState<> state(space_information);
    for (const bool allow_unknown : {false, true}) {
      for (const double radius : radii) {
        const MapValidityChecker checker(space_information, map, {radius, allow_unknown});
        const double grown = radius + 2.0 * map.resolution() / 4.0;
        for (int k = 0; k < 150; ++k) {
          const Eigen::Vector3d centre = randomPosition(rng);
          setPosition(state.get(), centre);
          if (checker.isValid(state.get())) {
            ++valid;
            EXPECT_TRUE(samplesPassable(map, centre, radius, allow_unknown))
                << "valid, yet a sample within " << radius << " m of " << centre.transpose()
                << " is not passable (allow_unknown " << allow_unknown << ")";
          } else {
            ++invalid;
            EXPECT_FALSE(samplesPassable(map, centre, grown, allow_unknown))
                << "invalid, yet every sample within " << grown << " m of " << centre.transpose()
                << " is passable (allow_unknown " << allow_unknown << ")";
          }
        }
      }
    }
  }
  // Both answers are common on these maps: the test says something either way.
  EXPECT_GT(valid, 300u);
  EXPECT_GT(invalid, 300u);
}

TEST(MapMotionValidator, AgreesWithSpheresAlongTheSegmentOnRandomMaps) {
  std::size_t valid = 0;
  std::size_t invalid = 0;
  for (unsigned seed = 4; seed <= 5; ++seed) {
    const mvog::Map map = mvog::test::randomMap(seed, 0.1, kHalfExtent, 4);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    const ob::SpaceInformationPtr space_information = realVectorSpace();
    const double step = map.resolution() / 10.0;
    for (const bool allow_unknown : {false, true}) {
      for (const double radius : {0.0, 0.2}) {
        const SphereRobot robot{radius, allow_unknown};
        space_information->setStateValidityChecker(
            std::make_shared<MapValidityChecker>(space_information, map, robot));
        const MapMotionValidator validator(space_information, map, robot);
        const MapValidityChecker grown(space_information, map, {radius + step, allow_unknown});
        ob::DiscreteMotionValidator discrete(space_information);
        ob::ScopedState<> from(space_information);
        ob::ScopedState<> to(space_information);
        ob::ScopedState<> along(space_information);
        ob::ScopedState<> last(space_information);
        for (int k = 0; k < 120; ++k) {
          // Starts where the sphere is valid, as OMPL's planners ask.
          Eigen::Vector3d start = randomPosition(rng);
          setPosition(from.get(), start);
          if (!space_information->isValid(from.get())) continue;
          const Eigen::Vector3d end =
              start + 1.5 * Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
          setPosition(to.get(), end);
          const int steps = static_cast<int>(std::ceil((end - start).norm() / step));
          const auto sphere_at = [&](int s, ob::State* state) {
            space_information->getStateSpace()->interpolate(from.get(), to.get(),
                                                            static_cast<double>(s) / steps, state);
          };
          std::pair<ob::State*, double> last_valid(last.get(), 0.0);
          if (validator.checkMotion(from.get(), to.get(), last_valid)) {
            ++valid;
            EXPECT_TRUE(validator.checkMotion(from.get(), to.get()));
            for (int s = 0; s <= steps; ++s) {
              sphere_at(s, along.get());
              EXPECT_TRUE(space_information->isValid(along.get()))
                  << "valid motion, invalid sphere at " << s << "/" << steps;
            }
            EXPECT_TRUE(discrete.checkMotion(from.get(), to.get()));
          } else {
            ++invalid;
            EXPECT_FALSE(validator.checkMotion(from.get(), to.get()));
            bool some_grown_invalid = false;
            for (int s = 0; s <= steps && !some_grown_invalid; ++s) {
              sphere_at(s, along.get());
              some_grown_invalid = !grown.isValid(along.get());
            }
            EXPECT_TRUE(some_grown_invalid) << "invalid motion, yet every grown sphere is valid";
            EXPECT_TRUE(space_information->isValid(last.get()));
            for (int s = 0; s <= steps && s < last_valid.second * steps; ++s) {
              sphere_at(s, along.get());
              EXPECT_TRUE(space_information->isValid(along.get()))
                  << "before the last valid state (" << last_valid.second << "), " << s << "/"
                  << steps << " is invalid";
            }
          }
        }
      }
    }
  }
  EXPECT_GT(valid, 50u);
  EXPECT_GT(invalid, 50u);
}

TEST(MapValidity, SE3StatesAreCheckedAtTheirPositionsWhateverTheirRotation) {
  const mvog::Map map = mvog::test::randomMap(6, 0.1, kHalfExtent, 4);
  auto se3 = std::make_shared<ob::SE3StateSpace>();
  ob::RealVectorBounds bounds(3);
  bounds.setLow(-kHalfExtent - 1.0);
  bounds.setHigh(kHalfExtent + 1.0);
  se3->setBounds(bounds);
  auto se3_information = std::make_shared<ob::SpaceInformation>(se3);
  const SphereRobot robot{0.2, false};
  useMap(se3_information, map, robot);
  const ob::SpaceInformationPtr r3_information = realVectorSpace();
  const MapValidityChecker r3_checker(r3_information, map, robot);
  const MapMotionValidator r3_validator(r3_information, map, robot);
  std::mt19937 rng(6);
  ob::ScopedState<ob::SE3StateSpace> pose_a(se3);
  ob::ScopedState<ob::SE3StateSpace> pose_b(se3);
  ob::ScopedState<> a(r3_information);
  ob::ScopedState<> b(r3_information);
  std::size_t differ = 0;
  for (int k = 0; k < 300; ++k) {
    pose_a.random();
    pose_b.random();
    const Eigen::Vector3d position_a = randomPosition(rng);
    const Eigen::Vector3d position_b = randomPosition(rng);
    pose_a->setXYZ(position_a.x(), position_a.y(), position_a.z());
    pose_b->setXYZ(position_b.x(), position_b.y(), position_b.z());
    EXPECT_EQ(positionOf(*se3, pose_a.get()), position_a);
    setPosition(a.get(), position_a);
    setPosition(b.get(), position_b);
    EXPECT_EQ(se3_information->isValid(pose_a.get()), r3_checker.isValid(a.get()));
    const bool se3_motion = se3_information->checkMotion(pose_a.get(), pose_b.get());
    EXPECT_EQ(se3_motion, r3_validator.checkMotion(a.get(), b.get()));
    differ += se3_information->isValid(pose_a.get()) != se3_motion ? 1 : 0;
  }
  EXPECT_GT(differ, 0u);  // motions were checked, not just their ends
}

TEST(MapValidity, RefusesWhatItCannotCheck) {
  const mvog::Map map = mvog::test::randomMap(7, 0.1, kHalfExtent, 1);
  const ob::SpaceInformationPtr space_information = realVectorSpace();
  EXPECT_THROW(MapValidityChecker(space_information, map, {-0.1, false}), mvog::ConfigError);
  EXPECT_THROW(MapMotionValidator(space_information, map, {std::nan(""), false}),
               mvog::ConfigError);
  auto plane = std::make_shared<ob::RealVectorStateSpace>(2);
  plane->setBounds(-1.0, 1.0);
  auto plane_information = std::make_shared<ob::SpaceInformation>(plane);
  EXPECT_THROW(MapValidityChecker(plane_information, map, {0.1, false}), mvog::ConfigError);
  // A state beyond max_coordinate, or not finite: nowhere the robot may be.
  const MapValidityChecker checker(space_information, map, {0.1, true});
  ob::ScopedState<> state(space_information);
  setPosition(state.get(), {2000.0, 0.0, 0.0});
  EXPECT_FALSE(checker.isValid(state.get()));
  setPosition(state.get(), {std::nan(""), 0.0, 0.0});
  EXPECT_FALSE(checker.isValid(state.get()));
}

// ---- The planner, in the scanned room: its door is x = 3, y in [-0.4, 0.4], up to z = 2.0 ----

PlanRequest throughTheDoor() {
  PlanRequest request;
  request.start = {1.5, 0.8, 1.2};
  request.goal = {3.8, 0.0, 1.0};  // beyond it, where the scans saw through it
  request.robot = {0.2, false};
  request.time_limit = 5.0;
  return request;
}

TEST(PlanPath, FindsAPathThroughTheDoorEveryEdgeFree) {
  const mvog::Map map = mvog::test::scannedRoomMap();
  const PlanResult result = planPath(map, throughTheDoor());
  ASSERT_EQ(result.status, PlanStatus::kPlanned) << result.message;
  ASSERT_GE(result.waypoints.size(), 2u);
  EXPECT_EQ(result.waypoints.front(), throughTheDoor().start);
  EXPECT_EQ(result.waypoints.back(), throughTheDoor().goal);
  bool crossed = false;
  for (std::size_t k = 1; k < result.waypoints.size(); ++k) {
    const Eigen::Vector3d& a = result.waypoints[k - 1];
    const Eigen::Vector3d& b = result.waypoints[k];
    EXPECT_EQ(mvog::checkSegments(map, {{a, b}}, 0.2).front().state, mvog::OccupancyState::kFree);
    if ((a.x() - 3.1) * (b.x() - 3.1) <= 0.0) {  // the edge crossing the wall's far face
      const double t = (3.1 - a.x()) / (b.x() - a.x());
      const Eigen::Vector3d at = a + t * (b - a);
      EXPECT_LT(std::abs(at.y()), 0.4 - 0.2) << "crossed the wall beside the door";
      EXPECT_LT(at.z(), 2.0 - 0.2) << "crossed the lintel";
      crossed = true;
    }
  }
  EXPECT_TRUE(crossed);
  EXPECT_GT(result.edges_checked, 0u);
}

TEST(PlanPath, SaysWhyWhenThereIsNoPath) {
  const mvog::Map map = mvog::test::scannedRoomMap();
  // The door closed by a box of occupied space (the wall's columns over its cells): the goal is
  // free, and out of reach.
  std::vector<mvog::Map::CellAssignment> door;
  for (int x = 30; x <= 31; ++x) {
    for (int y = -4; y <= 3; ++y) door.push_back({{x, y}, mvog::test::wallColumn()});
  }
  mvog::Map closed = mvog::test::scannedRoomMap();
  closed.setCellVolumes(door);
  PlanRequest shut_out = throughTheDoor();
  shut_out.time_limit = 0.5;
  const PlanResult none = planPath(closed, shut_out);
  EXPECT_EQ(none.status, PlanStatus::kNoPath);
  EXPECT_NE(none.message.find("no path found within"), std::string::npos) << none.message;
  EXPECT_TRUE(none.waypoints.empty());

  PlanRequest into_unknown = throughTheDoor();
  into_unknown.goal = {4.2, 2.5, 1.0};  // beyond the door, out of the scans' sight
  const PlanResult unknown = planPath(map, into_unknown);
  EXPECT_EQ(unknown.status, PlanStatus::kGoalBlocked);
  EXPECT_NE(unknown.message.find("unknown space not allowed"), std::string::npos)
      << unknown.message;

  PlanRequest in_wall = throughTheDoor();
  in_wall.start = {3.1, 1.0, 1.0};
  EXPECT_EQ(planPath(map, in_wall).status, PlanStatus::kStartBlocked);

  struct Bad {
    const char* field;
    std::function<void(PlanRequest&)> change;
  };
  const Bad bad_requests[] = {
      {"start", [](PlanRequest& r) { r.start.x() = std::nan(""); }},
      {"goal", [](PlanRequest& r) { r.goal.z() = 1e9; }},
      {"radius", [](PlanRequest& r) { r.robot.radius = -0.1; }},
      {"time_limit", [](PlanRequest& r) { r.time_limit = 0.0; }},
      {"time_limit", [](PlanRequest& r) { r.time_limit = kMaxPlanSeconds + 1.0; }},
  };
  for (const Bad& bad : bad_requests) {
    PlanRequest request = throughTheDoor();
    bad.change(request);
    const PlanResult refused = planPath(map, request);
    EXPECT_EQ(refused.status, PlanStatus::kInvalidRequest) << bad.field;
    EXPECT_EQ(refused.message.rfind(std::string(bad.field) + ":", 0), 0u) << refused.message;
  }
}

}  // namespace
}  // namespace mvog_ompl
