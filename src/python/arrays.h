// numpy arrays in and out of the core's types, without per-point Python work: an input array of
// float32 or float64 is read in place (copied only if it is not C-contiguous), and its points
// are read after the GIL is released.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "mvog/cell_index.h"
#include "mvog/grid2d.h"
#include "mvog/map.h"

namespace mvog_python {

namespace py = pybind11;

/// An (N, 3) array of points (m), float32 or float64, held while its points are read.
class PointArray {
 public:
  /// Throws TypeError unless `object` is an array (or a sequence numpy makes one of) of float32
  /// or float64, ValueError unless its shape is (N, 3); the message names `name`.
  PointArray(const py::handle& object, const char* name);

  std::size_t size() const { return size_; }
  /// Point k in double precision (may be called without the GIL).
  Eigen::Vector3d point(std::size_t k) const {
    return floats_ != nullptr
               ? Eigen::Vector3d(floats_[3 * k], floats_[3 * k + 1], floats_[3 * k + 2])
               : Eigen::Vector3d(doubles_[3 * k], doubles_[3 * k + 1], doubles_[3 * k + 2]);
  }
  /// The points in single precision, as the core's readings hold them (a copy of the bytes for
  /// float32; may be called without the GIL).
  std::vector<Eigen::Vector3f> floats() const;

 private:
  py::array array_;
  const float* floats_ = nullptr;
  const double* doubles_ = nullptr;
  std::size_t size_ = 0;
};

/// Throws ValueError naming `first_name` unless both arrays hold as many points.
void requireSameSize(const PointArray& first, const char* first_name, const PointArray& second,
                     const char* second_name);

/// A one-dimensional array of `size` values, written without the GIL through data().
template <class T>
py::array_t<T> newArray(std::size_t size) {
  return py::array_t<T>(static_cast<py::ssize_t>(size));
}

/// A 2D grid of the core as numpy: values (rows along +x, from the lowest y: values[j, i] is cell
/// (min_cell.x + i, min_cell.y + j)), the world coordinates of its first cell's corner, and its
/// resolution.
struct Grid {
  py::array values;
  double origin_x = 0.0;
  double origin_y = 0.0;
  double resolution = 0.0;
  mvog::CellIndex min_cell;
};

/// `grid` as a Grid of numpy values of type Out (the core's values cast).
template <class Out, class In>
Grid gridOf(const mvog::Grid2D<In>& grid) {
  py::array_t<Out> values(
      {static_cast<py::ssize_t>(grid.height()), static_cast<py::ssize_t>(grid.width())});
  Out* out = values.mutable_data();
  for (std::size_t k = 0; k < grid.values.size(); ++k) out[k] = static_cast<Out>(grid.values[k]);
  return {values, grid.originX(), grid.originY(), grid.resolution, grid.cells.min};
}

/// The cells of the world rectangle (min_x, min_y, max_x, max_y) (m) of `map`, or the map's
/// bounds() when none is given. Throws ValueError for a rectangle that is not finite or is
/// inverted; it is clipped to the map's max_coordinate.
mvog::CellRange cellsOf(const mvog::Map& map,
                        const std::optional<std::array<double, 4>>& rectangle);

}  // namespace mvog_python
