#include "mvog/column.h"

#include <algorithm>
#include <cmath>

namespace mvog {

std::vector<ColumnSegment> columnProfile(const CellVolumes& volumes) {
  std::vector<float> heights;
  heights.reserve(2 * (volumes.positive.size() + volumes.negative.size()));
  for (const std::vector<Volume>* list : {&volumes.positive, &volumes.negative}) {
    for (const Volume& v : *list) {
      heights.push_back(v.bottom);
      heights.push_back(v.top);
    }
  }
  std::sort(heights.begin(), heights.end());
  heights.erase(std::unique(heights.begin(), heights.end()), heights.end());

  std::vector<ColumnSegment> segments;
  for (std::size_t k = 0; k + 1 < heights.size(); ++k) {
    // Between two consecutive boundaries every point lies in the same volumes as the middle.
    const float middle = 0.5f * (heights[k] + heights[k + 1]);
    const Volume* positive = findVolume(
        volumes.positive.data(), static_cast<std::uint32_t>(volumes.positive.size()), middle);
    const Volume* negative = findVolume(
        volumes.negative.data(), static_cast<std::uint32_t>(volumes.negative.size()), middle);
    const float probability =
        occupancyProbability(positive != nullptr ? positive->density() : 0.0f,
                             negative != nullptr ? negative->density() : 0.0f);
    if (std::isnan(probability)) continue;  // a gap between volumes: unknown
    if (!segments.empty() && segments.back().top == heights[k] &&
        segments.back().probability == probability) {
      segments.back().top = heights[k + 1];
    } else {
      segments.push_back({heights[k], heights[k + 1], probability});
    }
  }
  return segments;
}

}  // namespace mvog
