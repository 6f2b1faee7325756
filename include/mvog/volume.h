#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>

namespace mvog {

/// One vertical volume of a cell's column (paper Sec. III-A): heights in grid units (z * s, where
/// s = 1 / resolution) and an occupancy mass. A cell's area is 1 in grid units, so eq. (2) reads
/// density = mass / height, and a new volume of density 1 has a mass equal to its height.
struct Volume {
  float bottom = 0.0f;
  float top = 0.0f;
  float mass = 0.0f;

  float height() const { return top - bottom; }
  /// Eq. (2).
  float density() const { return mass / height(); }
  bool contains(float z) const { return bottom <= z && z <= top; }
};
static_assert(sizeof(Volume) == 12, "the Table I accounting assumes 12-byte volumes");

/// Which of a cell's two lists a volume belongs to.
enum class VolumeSign : std::uint8_t { kPositive, kNegative };

/// The constraints of Sec. III-A: minimum height, and the gap under which two volumes merge.
constexpr float kMinVolumeHeight = 1.0f;
constexpr float kMaxMergeGap = 1.0f;

/// Whether two volumes of one list, one above the other, must merge (Sec. III-A: they overlap,
/// touch, or leave a gap of at most kMaxMergeGap). The one test every part of the model uses, in
/// float arithmetic, so that what the merge produces the checks accept.
inline bool mustMerge(float lower_top, float upper_bottom) {
  return upper_bottom - lower_top <= kMaxMergeGap;
}

/// A volume from `bottom` to `top` of at least kMinVolumeHeight: the float sums of eq. (6) may
/// round to just under the minimum height. Then the top is raised to bottom + 1, and one float
/// further if that sum rounds down too (then it lies above it). Nudging the top up one float at a
/// time until the height is 1, as before, could take billions of steps when the top lies just
/// below zero (found by fuzzing). Its mass is that of density 1 over its final height: every new
/// volume starts at density 1 (Sec. III-B.2).
inline Volume volumeOfMinimumHeight(float bottom, float top) {
  Volume volume{bottom, top, 0.0f};
  if (volume.height() < kMinVolumeHeight) {
    volume.top = std::max(volume.top, volume.bottom + kMinVolumeHeight);
    if (volume.height() < kMinVolumeHeight) volume.top = std::nextafter(volume.top, INFINITY);
  }
  volume.mass = volume.height();
  return volume;
}

/// Eq. (6): the volume spanning [z_a, z_b] (either order) with the minimum height enforced around
/// its centre.
inline Volume makeVolume(float z_a, float z_b) {
  const float low = std::min(z_a, z_b);
  const float high = std::max(z_a, z_b);
  // Both candidates are computed and one selected: whether a ray's crossing of a cell is lower
  // than 1 follows no pattern a branch predictor could learn, and this runs for every cell.
  const float centre = 0.5f * (low + high);  // eq. (6)
  const bool lift = high - low < kMinVolumeHeight;
  return volumeOfMinimumHeight(lift ? centre - 0.5f * kMinVolumeHeight : low,
                               lift ? centre + 0.5f * kMinVolumeHeight : high);
}

/// makeVolume(z_a, z_b) for a span known to be lower than kMinVolumeHeight, from its centre
/// 0.5f * (z_a + z_b).
inline Volume makeVolumeAround(float centre) {
  return volumeOfMinimumHeight(centre - 0.5f * kMinVolumeHeight, centre + 0.5f * kMinVolumeHeight);
}

/// The volume of `list[0, count)` that contains height z, or nullptr.
const Volume* findVolume(const Volume* list, std::uint32_t count, float z);

/// Eq. (9) from the densities of the positive and negative volumes holding a point (0 where
/// none does): p = rho+ / (rho+ + rho-), or NaN where both are 0 (unknown).
inline float occupancyProbability(float rho_plus, float rho_minus) {
  const float sum = rho_plus + rho_minus;
  return sum > 0.0f ? rho_plus / sum : std::numeric_limits<float>::quiet_NaN();
}

/// Empty if the two lists of a column satisfy Sec. III-A (each sorted, heights >= 1, gaps > 1,
/// finite non-negative masses), else what is wrong with them. With
/// `split_free_space_at_obstacles` (ModelRules), two negative volumes may also touch where a
/// positive volume begins or ends.
std::string checkColumn(const Volume* positive, std::size_t num_positive, const Volume* negative,
                        std::size_t num_negative, bool split_free_space_at_obstacles);

}  // namespace mvog
