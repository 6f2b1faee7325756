// Bounded evidence (InsertionConfig::evidence_limit, boundEvidence): a height remembers at most
// the limit's scans of evidence, so that a wall crossed in many scans is occupied again after a
// few hits, and a place that many scans saw occupied clears after a few crossings; scaling both
// lists alike keeps p (eq. 9). The map with a limit equals the plain reference (test_insertion.cpp,
// Insertion.EveryRuleSetEqualsThePlainReference and its neighbours run with a limit of 3).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "mvog/constraints.h"
#include "mvog/map.h"

namespace mvog {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

Volume volume(float bottom, float top, float density) {
  return {bottom, top, density * (top - bottom)};
}

// ---- boundEvidence ------------------------------------------------------------------------------

TEST(BoundEvidence, VolumesWithinTheLimitKeepTheirMassesBitForBit) {
  std::vector<Volume> positive{volume(1.0f, 2.0f, 3.0f), volume(5.0f, 6.5f, 6.0f)};
  std::vector<Volume> negative{volume(0.0f, 1.5f, 4.0f), volume(2.5f, 9.0f, 2.7f)};
  const std::vector<Volume> positive_before = positive;
  const std::vector<Volume> negative_before = negative;
  std::vector<double> factors;
  boundEvidence(positive.data(), positive.size(), negative.data(), negative.size(), 10.0, factors);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(std::memcmp(&positive[k], &positive_before[k], sizeof(Volume)), 0) << k;
    EXPECT_EQ(std::memcmp(&negative[k], &negative_before[k], sizeof(Volume)), 0) << k;
  }
}

TEST(BoundEvidence, TwoVolumesOverlappingOnlyEachOtherSumToTheLimitAndKeepP) {
  std::vector<Volume> positive{volume(4.7f, 5.7f, 6.0f)};
  std::vector<Volume> negative{volume(4.7f, 5.7f, 12.0f)};
  std::vector<double> factors;
  boundEvidence(positive.data(), 1, negative.data(), 1, 9.0, factors);
  EXPECT_NEAR(positive[0].density(), 3.0, 1e-5);
  EXPECT_NEAR(negative[0].density(), 6.0, 1e-5);
  EXPECT_NEAR(positive[0].density() / (positive[0].density() + negative[0].density()), 1.0 / 3.0,
              1e-6);
  // Bounds never move.
  EXPECT_EQ(positive[0].bottom, 4.7f);
  EXPECT_EQ(negative[0].top, 5.7f);
}

TEST(BoundEvidence, AVolumeWithNothingOppositeIsCappedAtTheLimit) {
  std::vector<Volume> negative{volume(0.0f, 20.0f, 50.0f), volume(22.0f, 23.0f, 2.0f)};
  std::vector<double> factors;
  boundEvidence(nullptr, 0, negative.data(), negative.size(), 14.0, factors);
  EXPECT_NEAR(negative[0].density(), 14.0, 1e-5);
  EXPECT_NEAR(negative[1].density(), 2.0, 1e-6);
}

TEST(BoundEvidence, TheDensestOverlappingVolumeSetsTheFactorAndTouchingIsNoOverlap) {
  // The free volume overlaps two obstacles (densities 2 and 8) and touches a third (density 30).
  std::vector<Volume> positive{volume(1.0f, 2.0f, 2.0f), volume(4.0f, 5.0f, 8.0f),
                               volume(10.0f, 11.0f, 30.0f)};
  std::vector<Volume> negative{volume(0.0f, 10.0f, 4.0f)};
  std::vector<double> factors;
  boundEvidence(positive.data(), positive.size(), negative.data(), 1, 10.0, factors);
  EXPECT_NEAR(negative[0].density(), 4.0 * 10.0 / 12.0, 1e-5);  // 4 + 8 > 10
  EXPECT_NEAR(positive[0].density(), 2.0, 1e-6);                // 2 + 4 <= 10
  EXPECT_NEAR(positive[1].density(), 8.0 * 10.0 / 12.0, 1e-5);  // 8 + 4 > 10
  EXPECT_NEAR(positive[2].density(), 10.0, 1e-5);               // alone: 30 capped
}

TEST(EvidenceLimit, ValidateRefusesALimitUnderOneOrNaNNamingIt) {
  for (double limit : {0.999, 0.0, -5.0, std::nan("")}) {
    InsertionConfig config;
    config.evidence_limit = limit;
    try {
      config.validate();
      ADD_FAILURE() << "validate() accepted evidence_limit " << limit;
    } catch (const ConfigError& error) {
      EXPECT_NE(std::strstr(error.what(), "evidence_limit"), nullptr) << error.what();
    }
  }
  InsertionConfig unbounded;
  unbounded.evidence_limit = kInfinity;
  EXPECT_NO_THROW(unbounded.validate());
}

// ---- In a map: a level laser's cell (the same heights in both lists) ----------------------------

/// A map at 0.1 m, and a level laser's readings from (0, 0.05, 0.05): crossing cell (10, 0) on
/// the way to x = 2.05, or hitting it at x = 1.05.
struct LevelCell {
  Map map{MapConfig{0.1, 10000.0, ModelRules{}}};
  InsertionConfig insertion;
  const Eigen::Vector3d origin{0.0, 0.05, 0.05};
  const Eigen::Vector3d in_cell{1.05, 0.05, 0.05};

  /// Each scan a group of its own (hit_memory_scans 0): the counts below are the evidence
  /// limit's alone; with the default a crossing clears hits only once the line scans that hit
  /// are out of the group (Rules.HitMemory*).
  explicit LevelCell(double evidence_limit) {
    insertion.evidence_limit = evidence_limit;
    insertion.hit_memory_scans = 0;
  }
  void cross(int scans) {
    for (int k = 0; k < scans; ++k) {
      map.insertReading(origin, {2.05, 0.05, 0.05}, ReadingKind::kObstacle, insertion);
    }
  }
  void hit(int scans) {
    for (int k = 0; k < scans; ++k) {
      map.insertReading(origin, in_cell, ReadingKind::kObstacle, insertion);
    }
  }
  double probability() const { return *map.occupancy(in_cell).probability; }
  OccupancyState state() const { return map.occupancy(in_cell).state(kDefaultOccupancyThreshold); }
};

TEST(EvidenceLimit, AWallCrossedInManyScansIsOccupiedAfterAFewHits) {
  // With a limit W, h hits after any number of crossings leave p = 1 - (W / (W + 1))^h: with
  // W = 14, 5 hits give 0.292 and 6 give 0.339, over the default threshold 0.324.
  LevelCell bounded(14.0);
  bounded.cross(100);
  bounded.hit(5);
  EXPECT_NEAR(bounded.probability(), 1.0 - std::pow(14.0 / 15.0, 5), 1e-5);
  EXPECT_EQ(bounded.state(), OccupancyState::kFree);
  bounded.hit(1);
  EXPECT_NEAR(bounded.probability(), 1.0 - std::pow(14.0 / 15.0, 6), 1e-5);
  EXPECT_EQ(bounded.state(), OccupancyState::kOccupied);
  // Unbounded, the same 6 hits weigh against all 100 crossings.
  LevelCell unbounded(kInfinity);
  unbounded.cross(100);
  unbounded.hit(6);
  EXPECT_NEAR(unbounded.probability(), 6.0 / 106.0, 1e-6);
  EXPECT_EQ(unbounded.state(), OccupancyState::kFree);
}

TEST(EvidenceLimit, APlaceSeenOccupiedInManyScansClearsAfterAFewCrossings) {
  // m crossings after any number of hits leave p = (W / (W + 1))^m: with W = 14, 16 give 0.332
  // (occupied) and 17 give 0.310 (free).
  LevelCell bounded(14.0);
  bounded.hit(100);
  bounded.cross(16);
  EXPECT_NEAR(bounded.probability(), std::pow(14.0 / 15.0, 16), 1e-5);
  EXPECT_EQ(bounded.state(), OccupancyState::kOccupied);
  bounded.cross(1);
  EXPECT_EQ(bounded.state(), OccupancyState::kFree);
  LevelCell unbounded(kInfinity);
  unbounded.hit(100);
  unbounded.cross(17);
  EXPECT_EQ(unbounded.state(), OccupancyState::kOccupied);
}

TEST(EvidenceLimit, TheDefaultIsOctomapsClampingRangeInMisses) {
  // (logit(0.971) - logit(0.1192)) / |logit(0.4)|: the misses that take an OctoMap voxel from
  // its upper clamp to its lower one, OctoMap's defaults.
  auto logit = [](double p) { return std::log(p / (1.0 - p)); };
  EXPECT_NEAR(InsertionConfig{}.evidence_limit,
              (logit(0.971) - logit(0.1192)) / std::fabs(logit(0.4)), 0.5);
}

}  // namespace
}  // namespace mvog
