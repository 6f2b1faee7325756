#include "mvog/column.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace mvog {

std::vector<ColumnSegment> columnProfile(const CellVolumes& volumes) {
  std::vector<ColumnSegment> segments;
  columnProfile(
      ColumnView{volumes.positive.data(), static_cast<std::uint32_t>(volumes.positive.size()),
                 volumes.negative.data(), static_cast<std::uint32_t>(volumes.negative.size())},
      segments);
  return segments;
}

void columnProfile(const ColumnView& column, std::vector<ColumnSegment>& segments) {
  segments.clear();
  if (column.empty()) return;
  constexpr float kNone = std::numeric_limits<float>::infinity();
  const Volume* positive = column.positive;
  const Volume* const positive_end = positive + column.num_positive;
  const Volume* negative = column.negative;
  const Volume* const negative_end = negative + column.num_negative;
  // One upward sweep over the boundaries of both lists (each sorted): between two consecutive
  // boundaries every point lies in the same volumes.
  float z = std::min(positive != positive_end ? positive->bottom : kNone,
                     negative != negative_end ? negative->bottom : kNone);
  while (true) {
    while (positive != positive_end && positive->top <= z) ++positive;
    while (negative != negative_end && negative->top <= z) ++negative;
    // The next boundary above z: a list's next bottom, or the top of its volume holding z.
    auto next_of = [z](const Volume* v, const Volume* end) {
      return v == end ? kNone : (v->bottom > z ? v->bottom : v->top);
    };
    const float next = std::min(next_of(positive, positive_end), next_of(negative, negative_end));
    if (next == kNone) return;
    auto density_over = [z](const Volume* v, const Volume* end) {
      return v != end && v->bottom <= z ? v->density() : 0.0f;
    };
    const float probability = occupancyProbability(density_over(positive, positive_end),
                                                   density_over(negative, negative_end));
    if (!std::isnan(probability)) {  // NaN: a gap between volumes, unknown
      if (!segments.empty() && segments.back().top == z &&
          segments.back().probability == probability) {
        segments.back().top = next;
      } else {
        segments.push_back({z, next, probability});
      }
    }
    z = next;
  }
}

}  // namespace mvog
