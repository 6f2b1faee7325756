#include "capsule.h"

#include <algorithm>
#include <cmath>

namespace mvog {
namespace detail {

int Capsule::squaredDistance(const AlignedBox& box, unsigned bounded, Piece* pieces) const {
  double cuts[8];
  int num_cuts = 0;
  cuts[num_cuts++] = 0.0;
  for (int axis = 0; axis < 3; ++axis) {
    if ((bounded >> axis & 1u) == 0 || delta_[axis] == 0.0) continue;
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
      if ((bounded >> axis & 1u) == 0) continue;
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
  const int count = squaredDistance(box, 0b111u, pieces);
  for (int k = 0; k < count; ++k) {
    if (const std::optional<Extent> touching = within(pieces[k])) return touching->min;
  }
  return std::nullopt;
}

std::optional<Extent> Capsule::extent(int axis, const AlignedBox& box, unsigned bounded) const {
  Piece pieces[kMaxPieces];
  const int count = squaredDistance(box, bounded & ~(1u << axis), pieces);
  const double r2 = radius_ * radius_;
  std::optional<Extent> result;
  for (int k = 0; k < count; ++k) {
    const Piece& piece = pieces[k];
    const std::optional<Extent> t = within(piece);
    if (!t) continue;
    // Over the sphere around P(t), the points within the box reach P(t)[axis] +- the half chord
    // sqrt(r^2 - q(t)). Both ends are concave in t (q is convex): their extremes lie at the ends
    // of the part within reach or where the derivative vanishes, 2 w sqrt(r^2 - q) = q'(t) for
    // w = +-delta[axis], i.e. with K the minimum of q: q'^2 = 4 w^2 a (r^2 - K) / (a + w^2).
    // Every candidate is a t within reach, so taking both extremes over all of them is exact.
    double candidates[4] = {t->min, t->max, t->min, t->max};
    const double w = delta_[axis];
    if (piece.a > 0.0) {
      const double minimum = piece.c - piece.b * piece.b / (4.0 * piece.a);
      const double slope = 2.0 * std::abs(w) *
                           std::sqrt(std::max(0.0, piece.a * (r2 - minimum) / (piece.a + w * w)));
      candidates[2] = std::clamp((slope - piece.b) / (2.0 * piece.a), t->min, t->max);
      candidates[3] = std::clamp((-slope - piece.b) / (2.0 * piece.a), t->min, t->max);
    }
    for (int c = 0; c < 4; ++c) {
      const double s = candidates[c];
      const double q = (piece.a * s + piece.b) * s + piece.c;
      const double half_chord = std::sqrt(std::max(0.0, r2 - q));
      const double centre = start_[axis] + s * w;
      if (!result) result = Extent{centre - half_chord, centre + half_chord};
      result->min = std::min(result->min, centre - half_chord);
      result->max = std::max(result->max, centre + half_chord);
    }
  }
  return result;
}

}  // namespace detail
}  // namespace mvog
