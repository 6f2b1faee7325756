// mvog.Map's queries (Sec. III-C): occupancy of points, cross-sections and projections as 2D
// arrays, and the volumes as one structured array. The core runs without the GIL, under the
// map's read lock; results are written into numpy arrays allocated before.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "arrays.h"
#include "bindings.h"
#include "mvog/map.h"
#include "mvog/planning_config.h"

namespace mvog_python {

namespace {

/// One volume of the map: its cell (i, j), its list (+1 positive, -1 negative), its heights in
/// grid units (z / resolution) and its mass (as of now).
struct VolumeRecord {
  std::int32_t x;
  std::int32_t y;
  std::int8_t sign;
  float bottom;
  float top;
  float mass;
};

/// ValueError (ConfigError, naming occupancy_threshold) unless it is in [0, 1), as PlanningConfig
/// checks it.
void requireThreshold(double occupancy_threshold) {
  mvog::PlanningConfig config;
  config.occupancy_threshold = occupancy_threshold;
  config.validate();
}

std::pair<py::array_t<std::uint8_t>, py::array_t<float>> occupancy(const MapHandle& handle,
                                                                   const py::handle& points,
                                                                   double occupancy_threshold) {
  requireThreshold(occupancy_threshold);
  const PointArray query(points, "points");
  auto states = newArray<std::uint8_t>(query.size());
  auto probabilities = newArray<float>(query.size());
  std::uint8_t* state = states.mutable_data();
  float* probability = probabilities.mutable_data();
  {
    py::gil_scoped_release no_gil;
    auto [map, lock] = handle.read();
    for (std::size_t k = 0; k < query.size(); ++k) {
      const mvog::PointOccupancy at = map.occupancy(query.point(k));
      state[k] = static_cast<std::uint8_t>(at.state(occupancy_threshold));
      probability[k] = at.probability.value_or(std::numeric_limits<float>::quiet_NaN());
    }
  }
  return {states, probabilities};
}

py::array_t<VolumeRecord> volumes(const MapHandle& handle) {
  // Gathered under the lock without the GIL, then handed to numpy without a copy: the GIL is
  // never taken while the map is locked.
  auto records = std::make_unique<std::vector<VolumeRecord>>();
  {
    py::gil_scoped_release no_gil;
    auto [map, lock] = handle.read();
    const mvog::MemoryUsage memory = map.memoryUsage();
    records->reserve(memory.positive_volumes + memory.negative_volumes);
    map.forEachVolume([&records](const mvog::CellIndex& cell, mvog::VolumeSign sign,
                                 const mvog::Volume& volume) {
      records->push_back({cell.x, cell.y,
                          static_cast<std::int8_t>(sign == mvog::VolumeSign::kPositive ? 1 : -1),
                          volume.bottom, volume.top, volume.mass});
    });
  }
  const VolumeRecord* data = records->data();
  const auto size = static_cast<py::ssize_t>(records->size());
  py::capsule owner(records.release(),
                    [](void* pointer) { delete static_cast<std::vector<VolumeRecord>*>(pointer); });
  return py::array_t<VolumeRecord>(size, data, owner);
}

/// The volumes of a list as an (N, 3) float32 array: bottom, top (grid units), mass.
py::array_t<float> volumeArray(const std::vector<mvog::Volume>& list) {
  py::array_t<float> array({static_cast<py::ssize_t>(list.size()), static_cast<py::ssize_t>(3)});
  auto out = array.mutable_unchecked<2>();
  for (std::size_t k = 0; k < list.size(); ++k) {
    out(k, 0) = list[k].bottom;
    out(k, 1) = list[k].top;
    out(k, 2) = list[k].mass;
  }
  return array;
}

}  // namespace

void bindMapQueries(py::module_& module, py::class_<MapHandle, MapPointer>& map_class) {
  PYBIND11_NUMPY_DTYPE(VolumeRecord, x, y, sign, bottom, top, mass);
  py::class_<Grid>(module, "Grid",
                   "A 2D grid of cells as numpy: values[j, i] belongs to cell (min_cell[0] + i, "
                   "min_cell[1] + j), rows along +x from the lowest y (so an image shown with "
                   "origin='lower' has +x right and +y up); origin (x, y) is the map-frame corner "
                   "(m) of the first cell; resolution its cells' edge (m).")
      .def_readonly("values", &Grid::values)
      .def_property_readonly("origin",
                             [](const Grid& grid) {
                               return std::array<double, 2>{grid.origin_x, grid.origin_y};
                             })
      .def_readonly("resolution", &Grid::resolution)
      .def_property_readonly("min_cell",
                             [](const Grid& grid) {
                               return std::array<std::int32_t, 2>{grid.min_cell.x, grid.min_cell.y};
                             })
      .def_property_readonly(
          "extent",
          [](const Grid& grid) {
            const auto rows = static_cast<double>(grid.values.shape(0));
            const auto columns = static_cast<double>(grid.values.shape(1));
            return std::array<double, 4>{grid.origin_x, grid.origin_x + columns * grid.resolution,
                                         grid.origin_y, grid.origin_y + rows * grid.resolution};
          },
          "(left, right, bottom, top) in metres, for matplotlib's imshow.");

  map_class
      .def("occupancy", &occupancy, py::arg("points"),
           py::arg("occupancy_threshold") = mvog::kDefaultOccupancyThreshold,
           "Eq. (9) at each point of an (N, 3) float32 or float64 array (m, map frame). Returns "
           "(states, probabilities): states as uint8 OccupancyState values (occupied where p > "
           "occupancy_threshold), probabilities float32, NaN where unknown (as at NaN or "
           "infinite points).")
      .def(
          "cross_section",
          [](const MapHandle& handle, double z,
             const std::optional<std::array<double, 4>>& rectangle) {
            const mvog::CrossSection grid = reading(handle, [&](const mvog::Map& map) {
              return map.crossSection(z, cellsOf(map, rectangle));
            });
            return gridOf<float>(grid);
          },
          py::arg("z"), py::arg("rectangle") = py::none(),
          "Eq. (9) at height z (m) over the cells of rectangle (min_x, min_y, max_x, max_y) (m; "
          "default: the map's bounds), Fig. 5: a Grid of float32 probabilities, NaN where "
          "unknown.")
      .def(
          "projection",
          [](const MapHandle& handle, double z_min, double z_max, double occupancy_threshold,
             const std::optional<std::array<double, 4>>& rectangle) {
            requireThreshold(occupancy_threshold);
            const mvog::Projection grid = reading(handle, [&](const mvog::Map& map) {
              return map.projection(z_min, z_max, occupancy_threshold, cellsOf(map, rectangle));
            });
            return gridOf<std::uint8_t>(grid);
          },
          py::arg("z_min") = -std::numeric_limits<double>::infinity(),
          py::arg("z_max") = std::numeric_limits<double>::infinity(),
          py::arg("occupancy_threshold") = mvog::kDefaultOccupancyThreshold,
          py::arg("rectangle") = py::none(),
          "Occupancy over the height band [z_min, z_max] (m; infinite bounds allowed), a top "
          "view: a Grid of uint8 OccupancyState values (occupied where some point of the band "
          "has p > occupancy_threshold, free where the band is known and none is, 0 unknown).")
      .def("volumes", &volumes,
           "Every volume of the map as one structured array with fields x, y (int32: the cell "
           "(i, j), i <= x / resolution < i + 1), sign (int8: +1 positive, -1 negative), bottom, "
           "top (float32, grid units: z / resolution) and mass (float32, as of now).")
      .def(
          "cell_volumes",
          [](const MapHandle& handle, std::int32_t i, std::int32_t j) {
            const mvog::CellVolumes cell = reading(handle, [&](const mvog::Map& map) {
              return map.cellVolumes({i, j});
            });
            return std::make_pair(volumeArray(cell.positive), volumeArray(cell.negative));
          },
          py::arg("i"), py::arg("j"),
          "The lists of cell (i, j) as (positive, negative), each an (N, 3) float32 array of "
          "bottom, top (grid units) and mass, upwards.")
      .def(
          "cell_at",
          [](const MapHandle& handle, double x, double y) {
            const mvog::CellIndex cell =
                reading(handle, [&](const mvog::Map& map) { return map.cellAtPoint(x, y); });
            return std::array<std::int32_t, 2>{cell.x, cell.y};
          },
          py::arg("x"), py::arg("y"), "The cell (i, j) holding the point (x, y) (m).");
}

}  // namespace mvog_python
