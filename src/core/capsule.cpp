#include "capsule.h"

#include <algorithm>
#include <cmath>

namespace mvog {
namespace detail {

int Capsule::squaredDistance(const AlignedBox& box, Piece* pieces) const {
  double cuts[8];
  int num_cuts = 0;
  cuts[num_cuts++] = 0.0;
  for (int axis = 0; axis < 3; ++axis) {
    if (delta_[axis] == 0.0) continue;
    for (double bound : {box.min[axis], box.max[axis]}) {
      const double t = (bound - start_[axis]) / delta_[axis];  // infinite bounds: never in (0, 1)
      if (!(t > 0.0 && t < 1.0)) continue;
      int k = num_cuts++;  // insertion keeps the cuts sorted
      for (; cuts[k - 1] > t; --k) cuts[k] = cuts[k - 1];
      cuts[k] = t;
    }
  }
  cuts[num_cuts++] = 1.0;
  int count = 0;
  for (int k = 0; k + 1 < num_cuts; ++k) {
    Piece piece{cuts[k], cuts[k + 1], 0.0, 0.0, 0.0};
    // Within a piece each axis stays on one side of the box (or within it): that of its middle.
    const double middle = 0.5 * (piece.t0 + piece.t1);
    for (int axis = 0; axis < 3; ++axis) {
      const double x = start_[axis] + middle * delta_[axis];
      double slope;
      double offset;  // the clamped difference is slope * t + offset
      if (x < box.min[axis]) {
        slope = -delta_[axis];
        offset = box.min[axis] - start_[axis];
      } else if (x > box.max[axis]) {
        slope = delta_[axis];
        offset = start_[axis] - box.max[axis];
      } else {
        continue;
      }
      piece.a += slope * slope;
      piece.b += 2.0 * slope * offset;
      piece.c += offset * offset;
    }
    pieces[count++] = piece;
  }
  return count;
}

std::optional<Extent> Capsule::within(const Piece& piece) const {
  const double c = piece.c - radius_ * radius_;
  if (piece.a == 0.0) {  // then b = 0 too: q is constant
    if (c > 0.0) return std::nullopt;
    return Extent{piece.t0, piece.t1};
  }
  const double discriminant = piece.b * piece.b - 4.0 * piece.a * c;
  if (discriminant < 0.0) return std::nullopt;
  // The roots without cancellation: q = -(b + sign(b) sqrt(disc)) / 2, roots q / a and c / q.
  const double q = -0.5 * (piece.b + std::copysign(std::sqrt(discriminant), piece.b));
  double low = q / piece.a;
  double high = q != 0.0 ? c / q : low;
  if (low > high) std::swap(low, high);
  low = std::max(low, piece.t0);
  high = std::min(high, piece.t1);
  if (low > high) return std::nullopt;
  return Extent{low, high};
}

std::optional<double> Capsule::firstContact(const AlignedBox& box) const {
  Piece pieces[kMaxPieces];
  const int count = squaredDistance(box, pieces);
  for (int k = 0; k < count; ++k) {
    if (const std::optional<Extent> touching = within(pieces[k])) return touching->min;
  }
  return std::nullopt;
}

}  // namespace detail
}  // namespace mvog
