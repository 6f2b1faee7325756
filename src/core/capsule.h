// The space a sphere sweeps along a segment, against axis-aligned boxes (internal to the core):
// the exact geometry of the segment checks with a radius (mvog/checks.h).
#pragma once

#include <optional>

#include <Eigen/Core>

namespace mvog {
namespace detail {

/// An axis-aligned box, closed; bounds may be infinite.
struct AlignedBox {
  Eigen::Vector3d min;
  Eigen::Vector3d max;
};

/// A range of values.
struct Extent {
  double min = 0.0;
  double max = 0.0;
};

/// The points within `radius` (> 0) of the segment P(t) = start + t (end - start), t in [0, 1].
///
/// Where it first meets a box follows from the squared distance from P(t) to the box, a sum over
/// the axes of squared clamped differences: a quadratic in t between the (at most six) values of
/// t where P(t) crosses a face's plane, solved exactly on each piece.
class Capsule {
 public:
  Capsule(const Eigen::Vector3d& start, const Eigen::Vector3d& end, double radius)
      : start_(start), delta_(end - start), radius_(radius) {}

  /// The smallest t at which the sphere around P(t) meets `box`, if it ever does.
  std::optional<double> firstContact(const AlignedBox& box) const;

 private:
  /// q(t) = a t^2 + b t + c over [t0, t1].
  struct Piece {
    double t0, t1, a, b, c;
  };
  static constexpr int kMaxPieces = 7;
  /// The squared distance from P(t) to `box`, piece by piece in increasing t; returns the number
  /// of pieces.
  int squaredDistance(const AlignedBox& box, Piece* pieces) const;
  /// The part of the piece where q(t) <= radius^2, if any.
  std::optional<Extent> within(const Piece& piece) const;

  Eigen::Vector3d start_;
  Eigen::Vector3d delta_;
  double radius_;
};

}  // namespace detail
}  // namespace mvog
