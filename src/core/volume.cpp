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
