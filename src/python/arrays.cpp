#include "arrays.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace mvog_python {

namespace {

std::string shapeOf(const py::array& array) {
  std::string shape = "(";
  for (py::ssize_t axis = 0; axis < array.ndim(); ++axis) {
    if (axis > 0) shape += ", ";
    shape += std::to_string(array.shape(axis));
  }
  return shape + (array.ndim() == 1 ? ",)" : ")");
}

}  // namespace

PointArray::PointArray(const py::handle& object, const char* name) {
  py::array array = py::array::ensure(object);
  if (!array) {
    PyErr_Clear();
    throw py::type_error(std::string(name) +
                         ": expected a float32 or float64 array of shape (N, 3)");
  }
  using Floats = py::array_t<float, py::array::c_style>;
  using Doubles = py::array_t<double, py::array::c_style>;
  if (py::isinstance<py::array_t<float>>(array)) {
    Floats contiguous = Floats::ensure(array);  // the array itself unless it is not contiguous
    floats_ = contiguous.data();
    array_ = std::move(contiguous);
  } else if (py::isinstance<py::array_t<double>>(array)) {
    Doubles contiguous = Doubles::ensure(array);
    doubles_ = contiguous.data();
    array_ = std::move(contiguous);
  } else {
    throw py::type_error(std::string(name) + ": expected a float32 or float64 array, got dtype " +
                         py::str(array.dtype()).cast<std::string>());
  }
  if (array_.ndim() != 2 || array_.shape(1) != 3) {
    throw py::value_error(std::string(name) + ": expected shape (N, 3), got " + shapeOf(array_));
  }
  size_ = static_cast<std::size_t>(array_.shape(0));
}

std::vector<Eigen::Vector3f> PointArray::floats() const {
  std::vector<Eigen::Vector3f> points(size_);
  if (floats_ != nullptr) {
    static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float), "Vector3f is three packed floats");
    if (size_ > 0)
      std::memcpy(static_cast<void*>(points.data()), floats_, size_ * sizeof(Eigen::Vector3f));
  } else {
    for (std::size_t k = 0; k < size_; ++k) points[k] = point(k).cast<float>();
  }
  return points;
}

void requireSameSize(const PointArray& first, const char* first_name, const PointArray& second,
                     const char* second_name) {
  if (first.size() != second.size()) {
    throw py::value_error(std::string(first_name) + ": holds " + std::to_string(first.size()) +
                          " points, " + second_name + " " + std::to_string(second.size()));
  }
}

mvog::CellRange cellsOf(const mvog::Map& map,
                        const std::optional<std::array<double, 4>>& rectangle) {
  if (!rectangle) return map.bounds();
  const std::array<double, 4>& r = *rectangle;
  if (!std::all_of(r.begin(), r.end(), [](double v) { return std::isfinite(v); }) || r[0] > r[2] ||
      r[1] > r[3]) {
    throw py::value_error(
        "rectangle: expected finite (min_x, min_y, max_x, max_y) with min <= max");
  }
  // Clipped to the cells readings can reach, so that no coordinate overflows a cell index.
  const double limit = map.config().max_coordinate;
  const auto clip = [limit](double v) { return std::clamp(v, -limit, limit); };
  return map.cellsInRectangle(clip(r[0]), clip(r[1]), clip(r[2]), clip(r[3]));
}

}  // namespace mvog_python
