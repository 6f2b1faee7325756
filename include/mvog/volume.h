#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
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

/// Eq. (6): the volume spanning [z_a, z_b] (either order) with the minimum height enforced around
/// its centre. The mass is that of density 1 over the final height, times `unit_mass` (the map's
/// stored-mass unit, see Map::decay): every new volume starts at density 1 (Sec. III-B.2).
inline Volume makeVolume(float z_a, float z_b, float unit_mass) {
  Volume volume{std::min(z_a, z_b), std::max(z_a, z_b), 0.0f};
  if (volume.height() < kMinVolumeHeight) {
    const float centre = 0.5f * (volume.bottom + volume.top);  // eq. (6)
    volume.bottom = centre - 0.5f * kMinVolumeHeight;
    volume.top = centre + 0.5f * kMinVolumeHeight;
    // The float sums may round to just under the minimum height. Then raise the top to
    // bottom + 1, and one float further if that sum rounds down too (then it lies above it).
    // Nudging the top up one float at a time until the height is 1, as before, could take
    // billions of steps when the top lies just below zero (found by fuzzing).
    if (volume.height() < kMinVolumeHeight) {
      volume.top = std::max(volume.top, volume.bottom + kMinVolumeHeight);
      if (volume.height() < kMinVolumeHeight) volume.top = std::nextafter(volume.top, INFINITY);
    }
  }
  volume.mass = volume.height() * unit_mass;
  return volume;
}

/// The run list[first, last) of the volumes that `volume` merges with when it is inserted into
/// the sorted list `list[0, count)` (which satisfies the Sec. III-A constraints): those whose gap
/// to it is at most kMaxMergeGap (a gap <= 0 is an overlap, eq. 7; a gap in (0, 1] is "too close",
/// eq. 8). The list's own gaps exceed 1, so they are consecutive. first == last where it merges
/// with none: it then goes in at `first` and the list grows by one.
struct MergeRun {
  std::uint32_t first = 0;
  std::uint32_t last = 0;
  bool addsVolume() const { return first == last; }
};

inline MergeRun findMergeRun(const Volume* list, std::uint32_t count, const Volume& volume) {
  MergeRun run;
  if (count == 1) {
    // The commonest column, one volume (free space above a floor, say): no scan.
    if (volume.bottom - list[0].top > kMaxMergeGap) return {1, 1};
    return {0, list[0].bottom - volume.top <= kMaxMergeGap ? 1u : 0u};
  }
  // Columns hold a handful of volumes: a linear scan beats a binary search there.
  while (run.first != count && volume.bottom - list[run.first].top > kMaxMergeGap) ++run.first;
  run.last = run.first;
  while (run.last != count && list[run.last].bottom - volume.top <= kMaxMergeGap) ++run.last;
  return run;
}

/// `volume` merged with the volumes [first, last) of a list that it overlaps or comes within
/// kMaxMergeGap of: one volume spanning them all, with their summed mass (eq. 7) plus, for every
/// gap filled, the gap's mass at density 1 (times `unit_mass`, eq. 8b).
inline Volume mergedVolume(const Volume& volume, const Volume* first, const Volume* last,
                           float unit_mass) {
  Volume merged = volume;
  float covered = volume.height();  // length of the union of the merged volumes
  for (const Volume* v = first; v != last; ++v) {
    const float overlap = std::min(v->top, volume.top) - std::max(v->bottom, volume.bottom);
    covered += v->height() - std::max(0.0f, overlap);
    merged.mass += v->mass;
    merged.bottom = std::min(merged.bottom, v->bottom);
    merged.top = std::max(merged.top, v->top);
  }
  merged.mass += std::max(0.0f, merged.height() - covered) * unit_mass;
  return merged;
}

/// Inserts `volume` into `list[0, count)` at `run` (from findMergeRun on the same list) and
/// restores the constraints: the volumes of the run are merged with it (mergedVolume).
/// `list` must have room for count + 1 volumes when run.addsVolume(). Returns the new count.
inline std::uint32_t insertVolumeAt(Volume* list, std::uint32_t count, const MergeRun& run,
                                    const Volume& volume, float unit_mass) {
  Volume* const first = list + run.first;
  if (run.addsVolume()) {
    std::memmove(first + 1, first, std::size_t{count - run.first} * sizeof(Volume));
    *first = volume;
    return count + 1;
  }
  if (run.last == run.first + 1) {
    // The commonest merge, with one volume: the list keeps its length, nothing moves.
    *first = mergedVolume(volume, first, first + 1, unit_mass);
    return count;
  }
  *first = mergedVolume(volume, first, list + run.last, unit_mass);
  std::memmove(first + 1, list + run.last, std::size_t{count - run.last} * sizeof(Volume));
  return count - (run.last - run.first) + 1;
}

/// Inserts `volume` into the sorted list `list[0, count)` and restores the Sec. III-A
/// constraints (findMergeRun, then insertVolumeAt). `list` must have room for count + 1
/// volumes. Returns the new count.
inline std::uint32_t insertVolume(Volume* list, std::uint32_t count, const Volume& volume,
                                  float unit_mass) {
  return insertVolumeAt(list, count, findMergeRun(list, count, volume), volume, unit_mass);
}

/// The volume of `list[0, count)` that contains height z, or nullptr.
const Volume* findVolume(const Volume* list, std::uint32_t count, float z);

/// Empty if `list[0, count)` satisfies Sec. III-A (sorted, heights >= 1, gaps > 1, finite
/// non-negative masses), else what is wrong with it.
std::string checkVolumeList(const Volume* list, std::size_t count);

}  // namespace mvog
