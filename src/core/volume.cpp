#include "mvog/volume.h"

#include <algorithm>
#include <cmath>

namespace mvog {

const Volume* findVolume(const Volume* list, std::uint32_t count, float z) {
  const Volume* end = list + count;
  const Volume* candidate =
      std::partition_point(list, end, [z](const Volume& v) { return v.top < z; });
  return candidate != end && candidate->bottom <= z ? candidate : nullptr;
}

namespace {

/// Whether z is the bottom or the top of a volume of the sorted list `list[0, count)`.
bool isBoundaryOf(const Volume* list, std::size_t count, float z) {
  const Volume* end = list + count;
  const Volume* candidate =
      std::partition_point(list, end, [z](const Volume& v) { return v.top < z; });
  return candidate != end && (candidate->bottom == z || candidate->top == z);
}

std::string checkList(const Volume* list, std::size_t count, const Volume* positive,
                      std::size_t num_positive, bool may_touch_at_positive_boundaries) {
  for (std::size_t k = 0; k < count; ++k) {
    const Volume& v = list[k];
    const std::string where = "volume " + std::to_string(k) + ": ";
    if (!std::isfinite(v.bottom) || !std::isfinite(v.top)) return where + "non-finite height";
    if (!(v.height() >= kMinVolumeHeight)) return where + "height below 1";
    if (!std::isfinite(v.mass) || v.mass < 0.0f) return where + "mass not finite and >= 0";
    if (k == 0 || !mustMerge(list[k - 1].top, v.bottom)) continue;
    if (may_touch_at_positive_boundaries && v.bottom == list[k - 1].top &&
        isBoundaryOf(positive, num_positive, v.bottom)) {
      continue;
    }
    return where + "not above the previous volume by a gap > 1";
  }
  return {};
}

}  // namespace

std::string checkColumn(const Volume* positive, std::size_t num_positive, const Volume* negative,
                        std::size_t num_negative, bool split_free_space_at_obstacles) {
  std::string problem = checkList(positive, num_positive, nullptr, 0, false);
  if (!problem.empty()) return "positive " + problem;
  problem =
      checkList(negative, num_negative, positive, num_positive, split_free_space_at_obstacles);
  if (!problem.empty()) return "negative " + problem;
  return {};
}

}  // namespace mvog
