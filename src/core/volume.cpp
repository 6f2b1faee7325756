#include "mvog/volume.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace mvog {

std::uint32_t insertVolume(Volume* list, std::uint32_t count, const Volume& volume,
                           float unit_mass) {
  // Volumes to merge are those whose gap to `volume` is at most kMaxMergeGap (a gap <= 0 is an
  // overlap, eq. 7; a gap in (0, 1] is "too close", eq. 8). The list is sorted and its own gaps
  // exceed 1, so they form one run [first, last) and the merged volume is within 1 of no other.
  Volume* const end = list + count;
  // Columns hold a handful of volumes: a linear scan beats a binary search there.
  Volume* first = list;
  while (first != end && volume.bottom - first->top > kMaxMergeGap) ++first;
  Volume* last = first;
  while (last != end && last->bottom - volume.top <= kMaxMergeGap) ++last;
  if (first == last) {
    std::memmove(first + 1, first, static_cast<std::size_t>(end - first) * sizeof(Volume));
    *first = volume;
    return count + 1;
  }
  Volume merged = volume;
  float covered = volume.height();  // length of the union of the merged volumes
  for (const Volume* v = first; v != last; ++v) {
    const float overlap = std::min(v->top, volume.top) - std::max(v->bottom, volume.bottom);
    covered += v->height() - std::max(0.0f, overlap);
    merged.mass += v->mass;
    merged.bottom = std::min(merged.bottom, v->bottom);
    merged.top = std::max(merged.top, v->top);
  }
  // Every gap that the merge fills is added at density 1 (eq. 8b).
  merged.mass += std::max(0.0f, merged.height() - covered) * unit_mass;
  *first = merged;
  if (last != first + 1) {
    std::memmove(first + 1, last, static_cast<std::size_t>(end - last) * sizeof(Volume));
  }
  return count - static_cast<std::uint32_t>(last - first) + 1;
}

const Volume* findVolume(const Volume* list, std::uint32_t count, float z) {
  const Volume* end = list + count;
  const Volume* candidate =
      std::partition_point(list, end, [z](const Volume& v) { return v.top < z; });
  return candidate != end && candidate->bottom <= z ? candidate : nullptr;
}

std::string checkVolumeList(const Volume* list, std::size_t count) {
  for (std::size_t k = 0; k < count; ++k) {
    const Volume& v = list[k];
    const std::string where = "volume " + std::to_string(k) + ": ";
    if (!std::isfinite(v.bottom) || !std::isfinite(v.top)) return where + "non-finite height";
    if (!(v.height() >= kMinVolumeHeight)) return where + "height below 1";
    if (!std::isfinite(v.mass) || v.mass < 0.0f) return where + "mass not finite and >= 0";
    if (k > 0 && !(v.bottom - list[k - 1].top > kMaxMergeGap)) {
      return where + "not above the previous volume by a gap > 1";
    }
  }
  return {};
}

}  // namespace mvog
