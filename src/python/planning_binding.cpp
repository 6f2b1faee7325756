// What planners and explorers ask the map (mvog/checks.h, mvog/frontiers.h, mvog/surfaces.h), as
// arrays: segment and box checks, frontiers, surfaces and the traversable map.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <cstdint>
#include <mutex>
#include <optional>
#include <tuple>
#include <utility>
#include <vector>

#include "arrays.h"
#include "bindings.h"
#include "mvog/checks.h"
#include "mvog/frontiers.h"
#include "mvog/surfaces.h"

namespace mvog_python {

namespace {

/// A core object kept from call to call (Frontiers, Surfaces), with a lock: its calls run
/// without the GIL, so two Python threads could otherwise update it at once.
template <class Core>
struct Guarded {
  explicit Guarded(const mvog::PlanningConfig& config) : core(config) {}
  Core core;
  std::mutex mutex;
};

/// `items` copied into a numpy array of their own structured dtype.
template <class Item>
py::array_t<Item> arrayOf(const std::vector<Item>& items) {
  return py::array_t<Item>(static_cast<py::ssize_t>(items.size()), items.data());
}

/// The segments starts[k] -> ends[k] checked by `check(map, segments)` on the map locked for
/// reading, without the GIL: (states, blocked_at).
template <class Check>
std::pair<py::array_t<std::uint8_t>, py::array_t<double>> segmentChecks(const MapHandle& handle,
                                                                        const py::handle& starts,
                                                                        const py::handle& ends,
                                                                        Check&& check) {
  const PointArray start_points(starts, "starts");
  const PointArray end_points(ends, "ends");
  requireSameSize(start_points, "starts", end_points, "ends");
  auto states = newArray<std::uint8_t>(start_points.size());
  auto blocked_at = newArray<double>(start_points.size());
  std::uint8_t* state = states.mutable_data();
  double* blocked = blocked_at.mutable_data();
  reading(handle, [&](const mvog::Map& map) {
    std::vector<mvog::Segment> segments(start_points.size());
    for (std::size_t k = 0; k < segments.size(); ++k) {
      segments[k] = {start_points.point(k), end_points.point(k)};
    }
    const std::vector<mvog::SegmentCheck> checks = check(map, segments);
    for (std::size_t k = 0; k < checks.size(); ++k) {
      state[k] = static_cast<std::uint8_t>(checks[k].state);
      blocked[k] = checks[k].blocked_at;
    }
    return 0;
  });
  return {states, blocked_at};
}

std::pair<py::array_t<std::uint8_t>, py::array_t<double>> checkSegments(
    const MapHandle& handle, const py::handle& starts, const py::handle& ends, double radius,
    const mvog::PlanningConfig& config) {
  return segmentChecks(handle, starts, ends,
                       [&](const mvog::Map& map, const std::vector<mvog::Segment>& segments) {
                         return mvog::checkSegments(map, segments, radius, config);
                       });
}

std::tuple<py::array_t<std::uint8_t>, py::array_t<double>, py::array_t<double>> checkBoxes(
    const MapHandle& handle, const py::handle& mins, const py::handle& maxs,
    const mvog::PlanningConfig& config) {
  const PointArray min_corners(mins, "mins");
  const PointArray max_corners(maxs, "maxs");
  requireSameSize(min_corners, "mins", max_corners, "maxs");
  auto states = newArray<std::uint8_t>(min_corners.size());
  auto known = newArray<double>(min_corners.size());
  auto highest = newArray<double>(min_corners.size());
  std::uint8_t* state = states.mutable_data();
  double* known_fraction = known.mutable_data();
  double* max_probability = highest.mutable_data();
  reading(handle, [&](const mvog::Map& map) {
    std::vector<mvog::Box> boxes(min_corners.size());
    for (std::size_t k = 0; k < boxes.size(); ++k) {
      boxes[k] = {min_corners.point(k), max_corners.point(k)};
    }
    const std::vector<mvog::BoxCheck> checks = mvog::checkBoxes(map, boxes, config);
    for (std::size_t k = 0; k < checks.size(); ++k) {
      state[k] = static_cast<std::uint8_t>(checks[k].state);
      known_fraction[k] = checks[k].known_fraction;
      max_probability[k] = checks[k].max_probability;
    }
    return 0;
  });
  return {states, known, highest};
}

/// Brings `guarded` up to date with the map, without the GIL, and returns its items.
template <class Core, class Items>
Items updated(Guarded<Core>& guarded, const MapHandle& handle, Items (*items)(const Core&)) {
  py::gil_scoped_release no_gil;
  const std::lock_guard<std::mutex> own(guarded.mutex);
  auto [map, lock] = handle.read();
  guarded.core.update(map);
  return items(guarded.core);
}

std::vector<mvog::FrontierPoint> frontierPoints(const mvog::Frontiers& frontiers) {
  return frontiers.points();
}
std::vector<mvog::Surface> surfaceList(const mvog::Surfaces& surfaces) {
  return surfaces.surfaces();
}

/// The class of a result kept tile by tile (Frontiers, Surfaces): its constructor from a
/// PlanningConfig, update(map) returning `items` as a structured array, and clear().
template <class Core, class Item>
py::class_<Guarded<Core>> trackedClass(py::module_& module, const char* name, const char* doc,
                                       std::vector<Item> (*items)(const Core&),
                                       const char* update_doc) {
  py::class_<Guarded<Core>> tracked(module, name, doc);
  tracked.def(py::init<const mvog::PlanningConfig&>(), py::arg("config") = mvog::PlanningConfig{})
      .def(
          "update",
          [items](Guarded<Core>& guarded, const MapHandle& handle) {
            return arrayOf(updated(guarded, handle, items));
          },
          py::arg("map"), update_doc)
      .def(
          "clear",
          [](Guarded<Core>& guarded) {
            const std::lock_guard<std::mutex> own(guarded.mutex);
            guarded.core.clear();
          },
          "Forgets everything (call it after the map is replaced by another).");
  return tracked;
}

}  // namespace

void bindPlanning(py::module_& module) {
  PYBIND11_NUMPY_DTYPE(mvog::FrontierPoint, x, y, z, cluster);
  PYBIND11_NUMPY_DTYPE(mvog::Surface, x, y, z, clearance, capped, probability);

  py::enum_<mvog::Traversability>(module, "Traversability",
                                  "Values of the traversable map (int8, as nav_msgs/"
                                  "OccupancyGrid).")
      .value("UNKNOWN", mvog::Traversability::kUnknown)
      .value("TRAVERSABLE", mvog::Traversability::kTraversable)
      .value("BLOCKED", mvog::Traversability::kBlocked);

  module.def("check_segments", &checkSegments, py::arg("map"), py::arg("starts"), py::arg("ends"),
             py::arg("radius") = 0.0, py::arg("config") = mvog::PlanningConfig{},
             "Checks the segments starts[k] -> ends[k] ((N, 3) float arrays, m, map frame) "
             "against the map's volumes exactly, with the points within `radius` (m) of them. "
             "Returns (states, blocked_at): uint8 OccupancyState values (occupied if some point "
             "is, free if every point is known and free, else unknown) and the distance (m) from "
             "the start to the first occupied or unknown point, NaN where free. ValueError for a "
             "point that is not finite or beyond max_coordinate, an invalid radius or config, or "
             "more than config.max_query_cells cells in all.");
  module.def("check_boxes", &checkBoxes, py::arg("map"), py::arg("mins"), py::arg("maxs"),
             py::arg("config") = mvog::PlanningConfig{},
             "Checks the axis-aligned boxes [mins[k], maxs[k]] ((N, 3) float arrays, m, map "
             "frame) against the map's volumes exactly. Returns (states, known_fraction, "
             "max_probability): uint8 OccupancyState values, the share of each box's volume the "
             "map knows, and the highest p in it (NaN if nothing is known).");
  module.def(
      "traversable_map",
      [](const MapHandle& handle, const mvog::PlanningConfig& config,
         const std::optional<std::array<double, 4>>& rectangle) {
        const mvog::TraversableMap grid = reading(handle, [&](const mvog::Map& map) {
          return mvog::traversableMap(map, cellsOf(map, rectangle), config);
        });
        return gridOf<std::int8_t>(grid);
      },
      py::arg("map"), py::arg("config") = mvog::PlanningConfig{}, py::arg("rectangle") = py::none(),
      "Where a ground robot of config.robot_height that climbs steps up to config.max_step can "
      "go, over rectangle (min_x, min_y, max_x, max_y) (m; default the map's bounds): a Grid of "
      "int8 Traversability values (-1 unknown, 0 traversable, 100 blocked). ValueError for an "
      "empty map or rectangle.");

  trackedClass<mvog::Frontiers>(
      module, "Frontiers",
      "The frontiers of a map (known-free space that touches unknown space) within "
      "[config.frontier_min_z, config.frontier_max_z], kept tile by tile: update(map) recomputes "
      "the tiles that changed since the previous update.",
      &frontierPoints,
      "Brings the frontiers up to date with `map`; returns its frontier voxels as a structured "
      "array: x, y, z (float32, the voxel's centre, m, map frame) and cluster (uint32, its "
      "connected piece).")
      .def_property_readonly("num_clusters", [](Guarded<mvog::Frontiers>& frontiers) {
        const std::lock_guard<std::mutex> own(frontiers.mutex);
        return frontiers.core.numClusters();
      });
  trackedClass<mvog::Surfaces>(
      module, "Surfaces",
      "The surfaces (tops of occupied space) of every column of a map, kept tile by tile: "
      "update(map) recomputes the tiles that changed.",
      &surfaceList,
      "Brings the surfaces up to date with `map`; returns them as a structured array: x, y "
      "(float32, the cell's centre, m), z (the top's height, m), clearance (m of known free "
      "space above it), capped (bool: occupied space ends the clearance) and probability (eq. 9 "
      "just below the top).");

  py::class_<Guarded<mvog::SegmentChecker>>(
      module, "SegmentChecker",
      "Checks segments as check_segments does, keeping from call to call what it found about "
      "blocks of 4 x 4 cells (forgotten for the tiles that change): repeated checks on a map "
      "pass open and unknown space without looking at each of its columns. Call clear() after "
      "the map is replaced by another.")
      .def(py::init<const mvog::PlanningConfig&>(), py::arg("config") = mvog::PlanningConfig{})
      .def(
          "check",
          [](Guarded<mvog::SegmentChecker>& checker, const MapHandle& handle,
             const py::handle& starts, const py::handle& ends, double radius) {
            return segmentChecks(
                handle, starts, ends,
                [&](const mvog::Map& map, const std::vector<mvog::Segment>& segments) {
                  const std::lock_guard<std::mutex> own(checker.mutex);
                  return checker.core.check(map, segments, radius);
                });
          },
          py::arg("map"), py::arg("starts"), py::arg("ends"), py::arg("radius") = 0.0,
          "As check_segments(map, starts, ends, radius, config): (states, blocked_at).")
      .def(
          "clear",
          [](Guarded<mvog::SegmentChecker>& checker) {
            const std::lock_guard<std::mutex> own(checker.mutex);
            checker.core.clear();
          },
          "Forgets the blocks (for a map replaced by another).");
}

}  // namespace mvog_python
