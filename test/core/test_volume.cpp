// Volume lists (Sec. III-A) and the constraint application of Sec. III-B.3: eqs. (2), (6), (7),
// (8), through volume.h and ListMerger (constraints.h), with the model's departures from the
// paper's text for free space next to obstacles (Sec. V.B, V.C).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <initializer_list>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include "mvog/constraints.h"
#include "mvog/volume.h"
#include "test_util.h"

namespace mvog {
namespace {

using test::kFloatInf;
using test::kFloatNaN;
using test::satisfiesConstraints;
using test::volumeIs;

/// `list` with the volumes `added` merged in at once (Fig. 2), as a positive list merges.
std::vector<Volume> merged(const std::vector<Volume>& list, const std::vector<Volume>& added,
                           float unit_mass = 1.0f) {
  ListMerger merger;
  std::vector<Volume> out;
  merger.merge(list, added, {}, {}, unit_mass, out);
  return out;
}

/// The same with one volume.
std::vector<Volume> inserted(const std::vector<Volume>& list, const Volume& volume,
                             float unit_mass = 1.0f) {
  return merged(list, {volume}, unit_mass);
}

/// A new volume of density 1 (mass = height) spanning [bottom, top].
Volume fresh(float bottom, float top) { return Volume{bottom, top, top - bottom}; }

// ---- Eq. (2) ----------------------------------------------------------------------------------

TEST(Volume, DensityIsMassPerHeight) {
  // Eq. (2) with A = 1 (grid units): rho = m / (top - bottom).
  EXPECT_FLOAT_EQ((Volume{1.0f, 5.0f, 2.0f}.density()), 0.5f);
  EXPECT_FLOAT_EQ((Volume{-2.0f, 1.0f, 9.0f}.density()), 3.0f);
  EXPECT_FLOAT_EQ((Volume{0.0f, 1.0f, 0.0f}.density()), 0.0f);
  EXPECT_FLOAT_EQ((Volume{0.0f, 2.5f, 2.5f}.height()), 2.5f);
}

TEST(Volume, ContainsIsAClosedInterval) {
  const Volume v{1.0f, 3.0f, 2.0f};
  EXPECT_TRUE(v.contains(1.0f));
  EXPECT_TRUE(v.contains(2.0f));
  EXPECT_TRUE(v.contains(3.0f));
  EXPECT_FALSE(v.contains(0.999f));
  EXPECT_FALSE(v.contains(3.001f));
  EXPECT_FALSE(v.contains(std::numeric_limits<float>::quiet_NaN()));
}

// ---- Eq. (6) and new volumes at density 1 -----------------------------------------------------

TEST(MakeVolume, TallVolumeKeepsItsExtentAtDensityOne) {
  EXPECT_TRUE(volumeIs(makeVolume(1.5f, 5.0f), 1.5, 5.0, 3.5));
  EXPECT_TRUE(volumeIs(makeVolume(5.0f, 1.5f), 1.5, 5.0, 3.5));  // either order
  EXPECT_TRUE(volumeIs(makeVolume(-3.0f, -1.0f), -3.0, -1.0, 2.0));
}

TEST(MakeVolume, HeightExactlyOneIsKept) {
  EXPECT_TRUE(volumeIs(makeVolume(2.0f, 3.0f), 2.0, 3.0, 1.0));
}

TEST(MakeVolume, ShortVolumeIsCentredToHeightOne) {
  // Eq. (6): [2.2, 2.6] has centre 2.4, so V* = [2.4 - 0.5, 2.4 + 0.5] = [1.9, 2.9], mass 1.
  EXPECT_TRUE(volumeIs(makeVolume(2.2f, 2.6f), 1.9, 2.9, 1.0));
  EXPECT_TRUE(volumeIs(makeVolume(2.6f, 2.2f), 1.9, 2.9, 1.0));
  // A single point (a horizontal ray over a cell) becomes [z - 0.5, z + 0.5].
  EXPECT_TRUE(volumeIs(makeVolume(-4.25f, -4.25f), -4.75, -3.75, 1.0));
}

TEST(MakeVolume, MassIsTheFinalHeight) {
  // Density 1: mass = final height.
  EXPECT_TRUE(volumeIs(makeVolume(0.0f, 2.0f), 0.0, 2.0, 2.0));
  EXPECT_TRUE(volumeIs(makeVolume(0.0f, 0.2f), -0.4, 0.6, 1.0));
}

TEST(MakeVolume, MinimumHeightHoldsFarFromZero) {
  // Around 2^22 a float resolves half units only; the minimum height must still hold.
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> centre(-4194304.0f, 4194304.0f);
  std::uniform_real_distribution<float> half_span(0.0f, 0.5f);
  for (int k = 0; k < 10000; ++k) {
    const float c = centre(rng);
    const float h = half_span(rng);
    const Volume v = makeVolume(c - h, c + h);
    ASSERT_GE(v.top - v.bottom, 1.0f) << "around " << c;
    ASSERT_FLOAT_EQ(v.mass, v.top - v.bottom);
  }
}

TEST(MakeVolume, MinimumHeightHoldsNearZero) {
  // Centres just below -0.5 put the top just below zero, where floats are dense: a top nudged up
  // one float at a time needed billions of steps there (a fuzzer's input hung the server). The
  // volume is still at least 1 high, and as short as the rounding allows.
  for (float c : {-0.50000006f, -0.5000001f, -0.49999997f, 0.49999997f, -0.5f}) {
    const Volume v = makeVolume(c, c);
    EXPECT_GE(v.top - v.bottom, 1.0f) << "centre " << c;
    EXPECT_LT(v.top - v.bottom, 1.0f + 1e-6f) << "centre " << c;
    EXPECT_LE(v.bottom, c) << "centre " << c;
    EXPECT_GE(v.top, c) << "centre " << c;
  }
  // Every centre between -0.5 - 2^-20 and -0.5 + 2^-20, float by float.
  for (float c = -0.5f - 9.5367431640625e-07f; c < -0.5f + 9.5367431640625e-07f;
       c = std::nextafter(c, 1.0f)) {
    const Volume v = makeVolume(c, c);
    ASSERT_GE(v.top - v.bottom, 1.0f) << "centre " << c;
    ASSERT_LT(v.top - v.bottom, 1.0f + 1e-6f) << "centre " << c;
  }
}

// ---- Eq. (7): overlapping volumes merge with summed masses -----------------------------------

TEST(ListMerger, IntoEmptyList) {
  const std::vector<Volume> list = inserted({}, fresh(1.0f, 2.0f));
  ASSERT_EQ(list.size(), 1u);
  EXPECT_TRUE(volumeIs(list[0], 1.0, 2.0, 1.0));
}

TEST(ListMerger, DistantVolumesStaySeparateAndSorted) {
  std::vector<Volume> list;
  for (float bottom : {10.0f, 0.0f, 20.0f, 5.0f}) list = inserted(list, fresh(bottom, bottom + 1));
  ASSERT_EQ(list.size(), 4u);
  EXPECT_TRUE(volumeIs(list[0], 0.0, 1.0, 1.0));
  EXPECT_TRUE(volumeIs(list[1], 5.0, 6.0, 1.0));
  EXPECT_TRUE(volumeIs(list[2], 10.0, 11.0, 1.0));
  EXPECT_TRUE(volumeIs(list[3], 20.0, 21.0, 1.0));
  EXPECT_TRUE(satisfiesConstraints(list));
}

TEST(ListMerger, PartialOverlapMergesIntoTheUnionWithSummedMass) {
  // Eq. (7): [0, 2] (mass 2) u [1.5, 3.5] (mass 2) = [0, 3.5], mass 2 + 2 = 4.
  const std::vector<Volume> list = inserted({fresh(0.0f, 2.0f)}, fresh(1.5f, 3.5f));
  ASSERT_EQ(list.size(), 1u);
  EXPECT_TRUE(volumeIs(list[0], 0.0, 3.5, 4.0));
}

TEST(ListMerger, OverlapFromBelow) {
  const std::vector<Volume> list = inserted({fresh(5.0f, 7.0f)}, fresh(4.0f, 5.5f));
  ASSERT_EQ(list.size(), 1u);
  EXPECT_TRUE(volumeIs(list[0], 4.0, 7.0, 3.5));
}

TEST(ListMerger, TouchingVolumesOverlap) {
  // Closed intervals: z_B^bot = 2 lies in [z_A^bot, z_A^top] = [0, 2], so they overlap (eq. 7).
  std::vector<Volume> list = inserted({fresh(0.0f, 2.0f)}, fresh(2.0f, 4.0f));
  ASSERT_EQ(list.size(), 1u);
  EXPECT_TRUE(volumeIs(list[0], 0.0, 4.0, 4.0));
  list = inserted({fresh(2.0f, 4.0f)}, fresh(0.0f, 2.0f));
  ASSERT_EQ(list.size(), 1u);
  EXPECT_TRUE(volumeIs(list[0], 0.0, 4.0, 4.0));
}

TEST(ListMerger, ContainedVolumeAddsItsMassOnly) {
  // [3, 4] inside [0, 10]: the union is [0, 10], the masses add: 10 + 1 = 11 (density 1.1).
  std::vector<Volume> list = inserted({fresh(0.0f, 10.0f)}, fresh(3.0f, 4.0f));
  ASSERT_EQ(list.size(), 1u);
  EXPECT_TRUE(volumeIs(list[0], 0.0, 10.0, 11.0));
  // And the other way round: a new volume swallowing an old one.
  list = inserted({fresh(3.0f, 4.0f)}, fresh(0.0f, 10.0f));
  ASSERT_EQ(list.size(), 1u);
  EXPECT_TRUE(volumeIs(list[0], 0.0, 10.0, 11.0));
}

TEST(ListMerger, MergeKeepsTheDensitiesMasses) {
  // Old [0, 2] at density 3 (mass 6), new [1, 3] at density 1: union [0, 3], mass 6 + 2 = 8.
  const std::vector<Volume> list = inserted({Volume{0.0f, 2.0f, 6.0f}}, fresh(1.0f, 3.0f));
  ASSERT_EQ(list.size(), 1u);
  EXPECT_TRUE(volumeIs(list[0], 0.0, 3.0, 8.0));
}

TEST(ListMerger, OneVolumeOverlappingSeveralMergesThemAll) {
  // [0.5, 6.5] overlaps [0, 1], [3, 4] and [6, 7]: union [0, 7], masses 1 + 1 + 1 + 6 = 9; the
  // union has no gap left, so nothing is added for gaps.
  const std::vector<Volume> list =
      inserted({fresh(0.0f, 1.0f), fresh(3.0f, 4.0f), fresh(6.0f, 7.0f), fresh(20.0f, 21.0f)},
               fresh(0.5f, 6.5f));
  ASSERT_EQ(list.size(), 2u);
  EXPECT_TRUE(volumeIs(list[0], 0.0, 7.0, 9.0));
  EXPECT_TRUE(volumeIs(list[1], 20.0, 21.0, 1.0));
}

// ---- Eq. (8): gaps in (0, 1] are filled at density 1 ------------------------------------------

TEST(ListMerger, GapBelowOneMergesAndAddsTheGapMass) {
  // Gap [1, 1.5] of 0.5: V* = [0, 2.5], m = 1 + 0.5 (gap at density 1) + 1 = 2.5.
  std::vector<Volume> list = inserted({fresh(0.0f, 1.0f)}, fresh(1.5f, 2.5f));
  ASSERT_EQ(list.size(), 1u);
  EXPECT_TRUE(volumeIs(list[0], 0.0, 2.5, 2.5));
  // Same with the new volume below.
  list = inserted({fresh(1.5f, 2.5f)}, fresh(0.0f, 1.0f));
  ASSERT_EQ(list.size(), 1u);
  EXPECT_TRUE(volumeIs(list[0], 0.0, 2.5, 2.5));
}

TEST(ListMerger, GapOfExactlyOneMerges) {
  // z_B^bot - z_A^top = 1 lies in (0, 1]: merge, m = 1 + 1 + 1 = 3, the new volume above...
  std::vector<Volume> list = inserted({fresh(0.0f, 1.0f)}, fresh(2.0f, 3.0f));
  ASSERT_EQ(list.size(), 1u);
  EXPECT_TRUE(volumeIs(list[0], 0.0, 3.0, 3.0));
  // ...or below.
  list = inserted({fresh(2.0f, 3.0f)}, fresh(0.0f, 1.0f));
  ASSERT_EQ(list.size(), 1u);
  EXPECT_TRUE(volumeIs(list[0], 0.0, 3.0, 3.0));
}

TEST(ListMerger, GapAboveOneDoesNotMerge) {
  const std::vector<Volume> list = inserted({fresh(0.0f, 1.0f)}, fresh(2.001f, 3.001f));
  ASSERT_EQ(list.size(), 2u);
  EXPECT_TRUE(volumeIs(list[0], 0.0, 1.0, 1.0));
  EXPECT_TRUE(volumeIs(list[1], 2.001, 3.001, 1.0));
  // The smallest float gap above 1.
  const float bottom = std::nextafter(2.0f, 3.0f);
  EXPECT_EQ(inserted({fresh(0.0f, 1.0f)}, fresh(bottom, bottom + 1.0f)).size(), 2u);
}

TEST(ListMerger, GapMassFollowsTheUnit) {
  // Stored masses in a unit of 0.5: the new volumes have mass 0.5 (density 1 real), and so does
  // the gap per unit height: 0.5 + 0.5 * 0.5 + 0.5 = 1.25.
  const std::vector<Volume> list =
      inserted({Volume{0.0f, 1.0f, 0.5f}}, Volume{1.5f, 2.5f, 0.5f}, 0.5f);
  ASSERT_EQ(list.size(), 1u);
  EXPECT_TRUE(volumeIs(list[0], 0.0, 2.5, 1.25));
}

TEST(ListMerger, VolumeBetweenTwoFillsBothGaps) {
  // [1.5, 2.5] sits 0.5 above [0, 1] and 0.5 below [3, 4]: one volume [0, 4],
  // m = 1 + 1 + 1 + 0.5 + 0.5 = 4.
  const std::vector<Volume> list =
      inserted({fresh(0.0f, 1.0f), fresh(3.0f, 4.0f)}, fresh(1.5f, 2.5f));
  ASSERT_EQ(list.size(), 1u);
  EXPECT_TRUE(volumeIs(list[0], 0.0, 4.0, 4.0));
}

TEST(ListMerger, OverlapOnOneSideAndGapOnTheOther) {
  // [1, 2.5] touches [0, 1] and is 0.5 below [3, 4]: [0, 4], m = 1 + 1.5 + 1 + 0.5 = 4.
  const std::vector<Volume> list =
      inserted({fresh(0.0f, 1.0f), fresh(3.0f, 4.0f)}, fresh(1.0f, 2.5f));
  ASSERT_EQ(list.size(), 1u);
  EXPECT_TRUE(volumeIs(list[0], 0.0, 4.0, 4.0));
}

TEST(ListMerger, ChainOfMergesAcrossManyVolumes) {
  // Volumes [3k, 3k + 1] for k = 0..4 (gaps of 2, so they stay apart), then [1.5, 11.5]: it
  // contains [3, 4], [6, 7], [9, 10] (eq. 7) and lies 0.5 from [0, 1] and [12, 13] (eq. 8).
  std::vector<Volume> list;
  for (float bottom : {0.0f, 3.0f, 6.0f, 9.0f, 12.0f})
    list = inserted(list, fresh(bottom, bottom + 1));
  ASSERT_EQ(list.size(), 5u);
  list = inserted(list, fresh(1.5f, 11.5f));
  ASSERT_EQ(list.size(), 1u);
  // The union is [0, 13]; the gaps left in it are [1, 1.5] and [11.5, 12], filled at density 1.
  // m = 5 * 1 (old) + 10 (new) + 0.5 + 0.5 (gaps) = 16.
  EXPECT_TRUE(volumeIs(list[0], 0.0, 13.0, 16.0));
}

TEST(ListMerger, MergedVolumeIsFarFromItsNeighbours) {
  // The merged volume [2.5, 6] keeps a gap > 1 to [0, 1] (1.5) and to [7.25, 8.25] (1.25).
  const std::vector<Volume> list =
      inserted({fresh(0.0f, 1.0f), fresh(2.5f, 4.0f), fresh(7.25f, 8.25f)}, fresh(4.5f, 6.0f));
  ASSERT_EQ(list.size(), 3u);
  EXPECT_TRUE(volumeIs(list[1], 2.5, 6.0, 1.5 + 0.5 + 1.5));
  EXPECT_TRUE(satisfiesConstraints(list));
}

TEST(ListMerger, RandomInsertionsKeepTheConstraintsAndConserveMass) {
  // Mass conservation: inserting v (density 1, so m_v = its height) adds m_v plus the gaps it
  // fills at density 1. The covered length grows by |v| - overlap(v, list) + gaps, hence
  //   mass_after - mass_before = covered_after - covered_before + overlap(v, list).
  std::mt19937 rng(42);
  std::uniform_real_distribution<float> bottom(-50.0f, 50.0f);
  std::uniform_real_distribution<float> height(0.0f, 3.0f);
  std::vector<Volume> list;
  const auto mass_and_length = [](const std::vector<Volume>& l) {
    double mass = 0.0;
    double length = 0.0;
    for (const Volume& v : l) {
      mass += v.mass;
      length += v.height();
    }
    return std::make_pair(mass, length);
  };
  for (int k = 0; k < 5000; ++k) {
    const float b = bottom(rng);
    const Volume v = makeVolume(b, b + height(rng));
    double overlap = 0.0;
    for (const Volume& old : list) {
      overlap += std::max(0.0, double{std::min(old.top, v.top)} - std::max(old.bottom, v.bottom));
    }
    const auto [mass_before, length_before] = mass_and_length(list);
    list = inserted(list, v);
    const auto [mass_after, length_after] = mass_and_length(list);
    ASSERT_TRUE(satisfiesConstraints(list)) << "after insertion " << k;
    ASSERT_EQ(checkColumn(list.data(), list.size(), nullptr, 0, false), "")
        << "after insertion " << k;
    ASSERT_NEAR(mass_after - mass_before, length_after - length_before + overlap, 1e-5 * mass_after)
        << "after insertion " << k;
    ASSERT_GE(mass_after, mass_before + v.mass - 1e-5 * mass_after) << "after insertion " << k;
  }
}

// ---- Fig. 2: a scan's new volumes go in at once ------------------------------------------------

TEST(ListMerger, OverlapsMergeBeforeGapsClose) {
  // Eq. (7) before eq. (8), over all the scan's volumes and those already there: [1, 1.5] covers
  // the gap between [0, 1] and [1.5, 2.5], so no gap mass is added. Inserted one after the other
  // ([1.5, 2.5] first), the gap would have been filled at density 1 before [1, 1.5] arrived.
  const std::vector<Volume> list =
      merged({fresh(0.0f, 1.0f)}, {fresh(1.5f, 2.5f), fresh(1.0f, 1.5f)});
  ASSERT_EQ(list.size(), 1u);
  EXPECT_TRUE(volumeIs(list[0], 0.0, 2.5, 2.5));
}

TEST(ListMerger, ScanVolumesCloseTheirGapsToo) {
  // [0, 1], [1.5, 2.5], [3, 4] arrive together: gaps of 0.5 are closed at density 1.
  const std::vector<Volume> list =
      merged({}, {fresh(3.0f, 4.0f), fresh(0.0f, 1.0f), fresh(1.5f, 2.5f)});
  ASSERT_EQ(list.size(), 1u);
  EXPECT_TRUE(volumeIs(list[0], 0.0, 4.0, 4.0));
}

TEST(ListMerger, TheResultDependsOnTheSetOfVolumesNotTheirOrder) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> bottom(-20.0f, 20.0f);
  std::uniform_real_distribution<float> height(0.0f, 4.0f);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<Volume> existing;
    for (int k = 0; k < 5; ++k) {
      const float b = bottom(rng);
      existing = inserted(existing, makeVolume(b, b + height(rng)));
    }
    std::vector<Volume> added;
    for (int k = 0; k < 12; ++k) {
      const float b = bottom(rng);
      added.push_back(makeVolume(b, b + height(rng)));
    }
    const std::vector<Volume> reference = merged(existing, added);
    ASSERT_TRUE(satisfiesConstraints(reference));
    for (int shuffle = 0; shuffle < 5; ++shuffle) {
      std::shuffle(added.begin(), added.end(), rng);
      const std::vector<Volume> again = merged(existing, added);
      ASSERT_EQ(again.size(), reference.size());
      for (std::size_t k = 0; k < again.size(); ++k) {
        ASSERT_EQ(std::memcmp(&again[k], &reference[k], sizeof(Volume)), 0) << "trial " << trial;
      }
    }
  }
}

/// Whether `existing` and `added` merge without obstacles (one pass) bit for bit as they do
/// beside an obstacle out of their reach (the sweep), under every FreeSpaceRules.
::testing::AssertionResult mergesAsBesideAFarObstacle(const std::vector<Volume>& existing,
                                                      const std::vector<Volume>& added,
                                                      float unit_mass) {
  const std::vector<Volume> alone = merged(existing, added, unit_mass);
  const std::vector<Volume> far_obstacle = {fresh(1000.0f, 1001.0f)};
  for (const bool split : {false, true}) {
    for (const bool no_gap_mass : {false, true}) {
      ListMerger merger;
      std::vector<Volume> beside;
      merger.merge(existing, added, far_obstacle, {split, no_gap_mass}, unit_mass, beside);
      if (beside.size() != alone.size() ||
          (!alone.empty() &&
           std::memcmp(beside.data(), alone.data(), alone.size() * sizeof(Volume)) != 0)) {
        return ::testing::AssertionFailure()
               << "split " << split << ", no gap mass " << no_gap_mass << ": " << beside.size()
               << " volumes beside the obstacle, " << alone.size() << " without";
      }
    }
  }
  return ::testing::AssertionSuccess();
}

TEST(ListMerger, AListWithoutObstaclesMergesAsOneBesideAnObstacleItDoesNotReach) {
  // A list without obstacles takes a one-pass merge; beside an obstacle it takes the sweep. Where
  // the obstacle lies out of reach, both must give the same list bit for bit.
  const Volume negative_zero{0.0f, 1.0f, -0.0f};
  const std::vector<std::pair<std::vector<Volume>, std::vector<Volume>>> cases = {
      {{}, {}},
      {{fresh(0.0f, 1.0f)}, {}},
      {{}, {fresh(0.0f, 1.0f), fresh(3.0f, 4.0f)}},
      {{fresh(0.0f, 1.0f)}, {fresh(1.0f, 2.0f)}},                     // touching
      {{fresh(0.0f, 1.0f)}, {fresh(2.0f, 3.0f)}},                     // a gap of exactly 1
      {{fresh(0.0f, 1.0f)}, {fresh(2.5f, 3.5f)}},                     // a gap above 1
      {{fresh(0.0f, 2.0f)}, {fresh(0.0f, 1.0f), fresh(0.5f, 3.0f)}},  // equal bottoms
      {{fresh(0.0f, 1.0f)}, {fresh(0.0f, 1.0f)}},                     // the same volume
      {{fresh(0.0f, 1.0f), fresh(2.5f, 3.5f)}, {fresh(1.5f, 2.0f)}},  // two gaps closed
      {{}, {negative_zero}},                                          // a mass of -0
      {{negative_zero}, {Volume{0.5f, 1.5f, -0.0f}}},
  };
  for (const float unit_mass : {1.0f, 0.5f, 0.8314f}) {
    for (std::size_t c = 0; c < cases.size(); ++c) {
      EXPECT_TRUE(mergesAsBesideAFarObstacle(cases[c].first, cases[c].second, unit_mass))
          << "case " << c << ", unit mass " << unit_mass;
    }
  }
  // And many lists of decayed masses (not whole heights).
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> bottom(-20.0f, 20.0f);
  std::uniform_real_distribution<float> height(0.0f, 4.0f);
  std::uniform_real_distribution<float> density(0.1f, 3.0f);
  const auto decayed = [&](float b) {
    Volume v = makeVolume(b, b + height(rng));
    v.mass = v.height() * density(rng);
    return v;
  };
  for (int trial = 0; trial < 500; ++trial) {
    std::vector<Volume> existing;
    for (int k = 0; k < 6; ++k) existing = inserted(existing, decayed(bottom(rng)), 0.8314f);
    std::vector<Volume> added;
    for (int k = 0; k < 10; ++k) added.push_back(decayed(bottom(rng)));
    ASSERT_TRUE(mergesAsBesideAFarObstacle(existing, added, 0.8314f)) << "trial " << trial;
  }
}

// ---- Sec. V.C: free space split at obstacles (ModelRules::split_free_space_at_obstacles) ------

/// `negative` with `added` merged in next to the obstacles `positive`, with the model's rules.
std::vector<Volume> mergedFree(const std::vector<Volume>& negative,
                               const std::vector<Volume>& added,
                               const std::vector<Volume>& positive, bool split,
                               bool no_gap_mass_over_obstacles = false) {
  ListMerger merger;
  std::vector<Volume> out;
  merger.merge(negative, added, positive, {split, no_gap_mass_over_obstacles}, 1.0f, out);
  EXPECT_EQ(checkColumn(positive.data(), positive.size(), out.data(), out.size(), split), "");
  return out;
}

TEST(ListMerger, FreeSpaceIsCutAtTheObstacleItReaches) {
  // Free space [0, 10] at density 1 through an obstacle [4, 6]: three pieces, the middle one
  // holding exactly the obstacle's heights and the mass that fell within them (2 of 10).
  const std::vector<Volume> pieces =
      mergedFree({}, {fresh(0.0f, 10.0f)}, {fresh(4.0f, 6.0f)}, true);
  ASSERT_EQ(pieces.size(), 3u);
  EXPECT_TRUE(volumeIs(pieces[0], 0.0, 4.0, 4.0));
  EXPECT_TRUE(volumeIs(pieces[1], 4.0, 6.0, 2.0));
  EXPECT_TRUE(volumeIs(pieces[2], 6.0, 10.0, 4.0));
  // The paper's rule averages it over the whole volume.
  const std::vector<Volume> paper =
      mergedFree({}, {fresh(0.0f, 10.0f)}, {fresh(4.0f, 6.0f)}, false);
  ASSERT_EQ(paper.size(), 1u);
  EXPECT_TRUE(volumeIs(paper[0], 0.0, 10.0, 10.0));
}

TEST(ListMerger, DenseFreeSpaceAboveAnObstacleDoesNotAverageItAway) {
  // A floor [-0.5, 0.5] below free space seen many times ([0.5, 10] at density 5) and grazed
  // once at its own height ([-0.3, 0.7]): its piece keeps the grazing ray's density, not 5.
  const std::vector<Volume> floor{fresh(-0.5f, 0.5f)};
  const std::vector<Volume> pieces =
      mergedFree({Volume{0.5f, 10.0f, 47.5f}}, {fresh(-0.3f, 0.7f)}, floor, true);
  ASSERT_EQ(pieces.size(), 2u);
  EXPECT_TRUE(volumeIs(pieces[0], -0.5, 0.5, 0.8));  // the part of [-0.3, 0.7] below 0.5
  EXPECT_TRUE(volumeIs(pieces[1], 0.5, 10.0, 47.5 + 0.2));
  EXPECT_LT(pieces[0].density(), pieces[1].density() / 5.0f);
}

TEST(ListMerger, AShortPieceBesideAnObstacleJoinsIt) {
  // Free space [2.6, 5] reaches into an obstacle [3, 5.5] from below: the part below it,
  // [2.6, 3], is 0.4 high, too low for a volume, so it joins the obstacle's piece.
  const std::vector<Volume> pieces = mergedFree({}, {fresh(2.6f, 5.0f)}, {fresh(3.0f, 5.5f)}, true);
  ASSERT_EQ(pieces.size(), 1u);
  EXPECT_TRUE(volumeIs(pieces[0], 2.6, 5.5, 2.4));
}

TEST(ListMerger, PiecesFollowAnObstacleThatGrows) {
  // Pieces cut at [4, 6] become pieces cut at [3, 6] when the obstacle grows downwards: the
  // piece below gives the part it loses to the obstacle's piece, in proportion (density kept).
  const std::vector<Volume> before =
      mergedFree({}, {fresh(0.0f, 10.0f)}, {fresh(4.0f, 6.0f)}, true);
  const std::vector<Volume> after = mergedFree(before, {}, {fresh(3.0f, 6.0f)}, true);
  ASSERT_EQ(after.size(), 3u);
  EXPECT_TRUE(volumeIs(after[0], 0.0, 3.0, 3.0));
  EXPECT_TRUE(volumeIs(after[1], 3.0, 6.0, 3.0));
  EXPECT_TRUE(volumeIs(after[2], 6.0, 10.0, 4.0));
}

TEST(ListMerger, AGapAnObstacleFillsGetsNoFreeMass) {
  // Free space clipped around a hit [4, 5] (Sec. V.B) leaves [0, 4] and [5, 9]: eq. (8) closes
  // the gap of 1, but with clip_free_space_at_hits adds no free mass where the hit is.
  const std::vector<Volume> hit{fresh(4.0f, 5.0f)};
  const std::vector<Volume> pieces =
      mergedFree({}, {fresh(0.0f, 4.0f), fresh(5.0f, 9.0f)}, hit, true, true);
  ASSERT_EQ(pieces.size(), 3u);
  EXPECT_TRUE(volumeIs(pieces[1], 4.0, 5.0, 0.0));  // p = 1 at the hit
  const std::vector<Volume> paper_gap =
      mergedFree({}, {fresh(0.0f, 4.0f), fresh(5.0f, 9.0f)}, hit, true, false);
  EXPECT_TRUE(volumeIs(paper_gap[1], 4.0, 5.0, 1.0));  // eq. (8b): the gap at density 1
}

TEST(ListMerger, SplitMergesConserveMass) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> bottom(-20.0f, 20.0f);
  std::uniform_real_distribution<float> height(0.0f, 4.0f);
  for (int trial = 0; trial < 300; ++trial) {
    std::vector<Volume> positive;
    std::vector<Volume> negative;
    for (int step = 0; step < 6; ++step) {
      std::vector<Volume> hits;
      std::vector<Volume> free;
      for (int k = 0; k < 2; ++k) {
        const float b = bottom(rng);
        hits.push_back(makeVolume(b, b));
      }
      for (int k = 0; k < 4; ++k) {
        const float b = bottom(rng);
        free.push_back(makeVolume(b, b + height(rng)));
      }
      positive = merged(positive, hits);
      double before = 0.0;
      for (const Volume& v : negative) before += v.mass;
      for (const Volume& v : free) before += v.mass;
      ListMerger merger;
      std::vector<Volume> out;
      merger.merge(negative, free, positive, {true, false}, 1.0f, out);
      ASSERT_EQ(checkColumn(positive.data(), positive.size(), out.data(), out.size(), true), "")
          << "trial " << trial;
      double after = 0.0;
      double covered = 0.0;
      for (const Volume& v : out) {
        after += v.mass;
        covered += v.height();
      }
      // Mass is conserved, plus at most the gaps filled at density 1.
      ASSERT_GE(after, before - 1e-4 * after) << "trial " << trial;
      ASSERT_LE(after, before + covered + 1e-4 * after) << "trial " << trial;
      negative = out;
    }
  }
}

TEST(ListMerger, KeepsUnchangedExactlyWhatAMergeWithNothingAddedKeeps) {
  // keepsUnchanged lets the scan update add masses in place. It must hold for every list a merge
  // returns, and exactly where merging the list again with nothing added returns it bit for bit:
  // also under obstacles dropped, shortened or grown since (as under a list given whole).
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> bottom(-20.0f, 20.0f);
  std::uniform_real_distribution<float> height(0.0f, 4.0f);
  auto same = [](const std::vector<Volume>& a, const std::vector<Volume>& b) {
    return a.size() == b.size() &&
           std::equal(a.begin(), a.end(), b.begin(), [](const Volume& x, const Volume& y) {
             return std::memcmp(&x, &y, sizeof(Volume)) == 0;
           });
  };
  int kept = 0;
  int changed = 0;
  for (const FreeSpaceRules rules :
       {FreeSpaceRules{false, false}, FreeSpaceRules{true, false}, FreeSpaceRules{true, true}}) {
    for (int trial = 0; trial < 300; ++trial) {
      ListMerger merger;
      std::vector<Volume> positive;
      std::vector<Volume> negative;
      for (int step = 0; step < 4; ++step) {
        std::vector<Volume> hits;
        std::vector<Volume> free;
        for (int k = 0; k < 2; ++k) {
          const float b = bottom(rng);
          hits.push_back(makeVolume(b, b + 0.5f * height(rng)));
        }
        for (int k = 0; k < 4; ++k) {
          const float b = bottom(rng);
          free.push_back(makeVolume(b, b + height(rng)));
        }
        positive = merged(positive, hits);
        std::vector<Volume> out;
        merger.merge(negative, free, positive, rules, 1.0f, out);
        negative.swap(out);
        ASSERT_TRUE(merger.keepsUnchanged(negative, positive, rules)) << "trial " << trial;
      }
      std::vector<std::vector<Volume>> obstacle_sets{positive};
      if (!positive.empty()) {
        obstacle_sets.emplace_back(positive.begin() + 1, positive.end());
        std::vector<Volume> shortened = positive;
        Volume& last = shortened.back();
        last.top = std::max(last.bottom + kMinVolumeHeight, last.top - 0.5f * height(rng));
        obstacle_sets.push_back(shortened);
        std::vector<Volume> grown = positive;
        grown.back().top += height(rng);
        obstacle_sets.push_back(grown);
      }
      for (const std::vector<Volume>& obstacles : obstacle_sets) {
        std::vector<Volume> again;
        merger.merge(negative, {}, obstacles, rules, 1.0f, again);
        const bool keeps = merger.keepsUnchanged(negative, obstacles, rules);
        ASSERT_EQ(keeps, same(again, negative)) << "trial " << trial;
        ++(keeps ? kept : changed);
      }
    }
  }
  EXPECT_GT(kept, 1000);
  EXPECT_GT(changed, 100);
}

// ---- findVolume ---------------------------------------------------------------------------------

TEST(FindVolume, FindsTheVolumeContainingAHeight) {
  const std::vector<Volume> list{fresh(0.0f, 1.0f), fresh(3.0f, 5.0f), fresh(7.0f, 8.0f)};
  const auto find = [&](float z) { return findVolume(list.data(), 3, z); };
  EXPECT_EQ(find(0.0f), &list[0]);  // closed intervals: both faces belong to the volume
  EXPECT_EQ(find(1.0f), &list[0]);
  EXPECT_EQ(find(3.0f), &list[1]);
  EXPECT_EQ(find(4.0f), &list[1]);
  EXPECT_EQ(find(5.0f), &list[1]);
  EXPECT_EQ(find(8.0f), &list[2]);
  EXPECT_EQ(find(-0.01f), nullptr);
  EXPECT_EQ(find(2.0f), nullptr);
  EXPECT_EQ(find(6.0f), nullptr);
  EXPECT_EQ(find(8.01f), nullptr);
  EXPECT_EQ(find(std::numeric_limits<float>::quiet_NaN()), nullptr);
  EXPECT_EQ(findVolume(list.data(), 0, 0.5f), nullptr);
}

// ---- checkColumn ------------------------------------------------------------------------------

TEST(CheckColumn, AcceptsValidLists) {
  EXPECT_EQ(checkColumn(nullptr, 0, nullptr, 0, false), "");
  const std::vector<Volume> list{fresh(0.0f, 1.0f), Volume{2.5f, 4.0f, 0.0f}};
  EXPECT_EQ(checkColumn(list.data(), list.size(), nullptr, 0, false), "");
  EXPECT_EQ(checkColumn(nullptr, 0, list.data(), list.size(), false), "");
}

TEST(CheckColumn, RefusesEveryViolation) {
  const std::vector<std::vector<Volume>> bad{
      {Volume{0.0f, 0.5f, 0.5f}},                     // height below 1
      {Volume{1.0f, 0.0f, 1.0f}},                     // upside down
      {fresh(0.0f, 1.0f), fresh(2.0f, 3.0f)},         // gap of exactly 1
      {fresh(0.0f, 2.0f), fresh(1.0f, 3.0f)},         // overlap
      {fresh(5.0f, 6.0f), fresh(0.0f, 1.0f)},         // unsorted
      {Volume{0.0f, 1.0f, -1.0f}},                    // negative mass
      {Volume{0.0f, 1.0f, kFloatNaN}},                // NaN mass
      {Volume{0.0f, 1.0f, kFloatInf}},                // infinite mass
      {Volume{kFloatNaN, 1.0f, 1.0f}},                // NaN bottom
      {Volume{0.0f, kFloatInf, 1.0f}},                // infinite top
      {Volume{-kFloatInf, 0.0f, 1.0f}},               // infinite bottom
      {fresh(0.0f, 1.0f), Volume{5.0f, 5.5f, 0.5f}},  // second volume too short
  };
  for (const std::vector<Volume>& list : bad) {
    for (bool split : {false, true}) {
      EXPECT_NE(checkColumn(list.data(), list.size(), nullptr, 0, split), "")
          << "accepted [" << list.back().bottom << ", " << list.back().top << "] mass "
          << list.back().mass << " as positive volumes";
      EXPECT_NE(checkColumn(nullptr, 0, list.data(), list.size(), split), "")
          << "accepted it as negative volumes";
    }
    EXPECT_FALSE(satisfiesConstraints(list));  // the tests' own check agrees
  }
}

TEST(CheckColumn, NegativeVolumesTouchOnlyAtObstacleBoundariesAndOnlyWhenSplit) {
  // split_free_space_at_obstacles keeps the free space within an obstacle's heights as its own
  // piece: the pieces touch at the obstacle's bottom and top, nowhere else.
  const std::vector<Volume> positive{fresh(4.0f, 6.0f)};
  const std::vector<Volume> pieces{fresh(0.0f, 4.0f), Volume{4.0f, 6.0f, 0.5f}, fresh(6.0f, 9.0f)};
  EXPECT_EQ(checkColumn(positive.data(), 1, pieces.data(), 3, true), "");
  EXPECT_NE(checkColumn(positive.data(), 1, pieces.data(), 3, false), "");
  const std::vector<Volume> elsewhere{fresh(0.0f, 3.0f), fresh(3.0f, 9.0f)};
  EXPECT_NE(checkColumn(positive.data(), 1, elsewhere.data(), 2, true), "");
  // Positive volumes never touch.
  const std::vector<Volume> touching{fresh(0.0f, 1.0f), fresh(1.0f, 2.0f)};
  EXPECT_NE(checkColumn(touching.data(), 2, nullptr, 0, true), "");
}

TEST(ListMerger, APieceBesideAnObstacleExactlyOneHighStaysApart) {
  // Free space [0, 4] through an obstacle [1, 3]: the parts outside it, [0, 1] and [3, 4], are
  // exactly kMinVolumeHeight high, not lower: each stays a piece of its own (constraints.h: only
  // a piece lower than kMinVolumeHeight joins the obstacle's piece), each with the mass within
  // its heights.
  const std::vector<Volume> pieces = mergedFree({}, {fresh(0.0f, 4.0f)}, {fresh(1.0f, 3.0f)}, true);
  ASSERT_EQ(pieces.size(), 3u);
  EXPECT_TRUE(volumeIs(pieces[0], 0.0, 1.0, 1.0));
  EXPECT_TRUE(volumeIs(pieces[1], 1.0, 3.0, 2.0));
  EXPECT_TRUE(volumeIs(pieces[2], 3.0, 4.0, 1.0));
}

}  // namespace
}  // namespace mvog
