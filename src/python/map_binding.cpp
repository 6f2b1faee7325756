// mvog.Map: construction, insertion (points and depth images), the map's lifetime (decay,
// forgetting, clearing a box, merging, dropping far tiles) and bookkeeping. Every call into the
// core runs with the GIL released, under the map's lock (MapHandle).
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <shared_mutex>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "arrays.h"
#include "bindings.h"
#include "mvog/depth_image.h"
#include "mvog/map.h"

namespace mvog_python {

namespace {

/// The readings of one scan from (N, 3) arrays, inserted as Map::insertScan does.
mvog::InsertionResult insertScan(MapHandle& handle, const Eigen::Vector3d& origin,
                                 const py::handle& hits, const py::handle& out_of_range,
                                 const mvog::InsertionConfig& config) {
  const PointArray hit_points(hits, "hits");
  std::optional<PointArray> free_points;
  if (!out_of_range.is_none()) free_points.emplace(out_of_range, "out_of_range");
  py::gil_scoped_release no_gil;
  mvog::Scan scan;
  scan.origin = origin;
  scan.hits = hit_points.floats();
  if (free_points) scan.out_of_range = free_points->floats();
  auto [map, lock] = handle.write();
  return map.insertScan(scan, config);
}

/// A rigid 4 x 4 transform (m) as an isometry; ValueError naming `name` otherwise.
Eigen::Isometry3d isometryOf(const Eigen::Matrix4d& matrix, const char* name) {
  const Eigen::Matrix3d rotation = matrix.topLeftCorner<3, 3>();
  const bool rigid =
      matrix.allFinite() && matrix.row(3).isApprox(Eigen::RowVector4d(0, 0, 0, 1)) &&
      (rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).norm() < 1e-6 &&
      rotation.determinant() > 0.0;
  if (!rigid) {
    throw py::value_error(std::string(name) +
                          ": expected a finite rigid 4 x 4 transform (rotation and translation)");
  }
  Eigen::Isometry3d isometry = Eigen::Isometry3d::Identity();
  isometry.linear() = rotation;
  isometry.translation() = matrix.topRightCorner<3, 1>();
  return isometry;
}

/// A depth image (uint16 millimetres or float32 metres, REP-118) back-projected with the core's
/// depth_image.h and inserted; returns the insertion's result and the pixels skipped.
std::pair<mvog::InsertionResult, std::size_t> insertDepthImage(
    MapHandle& handle, const py::handle& depth, const mvog::PinholeCamera& camera,
    const Eigen::Matrix4d& pose, const mvog::InsertionConfig& config,
    const mvog::DepthImageConfig& depth_config) {
  py::array image = py::array::ensure(depth);
  if (!image) {
    PyErr_Clear();
    throw py::type_error("depth: expected a (H, W) array of uint16 or float32");
  }
  if (image.ndim() != 2) throw py::value_error("depth: expected a (H, W) array");
  mvog::DepthImageView view;
  if (py::isinstance<py::array_t<std::uint16_t>>(image)) {
    image = py::array_t<std::uint16_t, py::array::c_style>::ensure(image);
    view.encoding = mvog::DepthEncoding::kUint16Millimetres;
  } else if (py::isinstance<py::array_t<float>>(image)) {
    image = py::array_t<float, py::array::c_style>::ensure(image);
    view.encoding = mvog::DepthEncoding::kFloat32Metres;
  } else {
    throw py::type_error("depth: expected uint16 (millimetres) or float32 (metres), got dtype " +
                         py::str(image.dtype()).cast<std::string>());
  }
  if (image.shape(0) > UINT32_MAX || image.shape(1) > UINT32_MAX) {
    throw py::value_error("depth: more than 2^32 - 1 rows or columns");
  }
  view.data = static_cast<const std::uint8_t*>(image.data());
  view.size = static_cast<std::size_t>(image.nbytes());
  view.height = static_cast<std::uint32_t>(image.shape(0));
  view.width = static_cast<std::uint32_t>(image.shape(1));
  view.step = view.width * mvog::DepthImageView::bytesPerPixel(view.encoding);
  const Eigen::Isometry3d map_from_camera = isometryOf(pose, "pose");
  py::gil_scoped_release no_gil;
  auto [map, lock] = handle.write();
  const mvog::InsertionResult result =
      map.insertDepthImage({view, camera, map_from_camera, depth_config}, config);
  return {result, result.rejected_no_measurement};
}

/// Merges `other` into `handle`'s map, both locked (in one order, whoever merges which).
void merge(MapHandle& handle, const MapHandle& other, const mvog::GridTransform& transform) {
  py::gil_scoped_release no_gil;
  if (&handle == &other) {
    auto [map, lock] = handle.write();
    map.merge(map, transform);
    return;
  }
  std::unique_lock<std::shared_mutex> write(handle.mutex(), std::defer_lock);
  std::shared_lock<std::shared_mutex> read(other.mutex(), std::defer_lock);
  if (std::less<const MapHandle*>()(&handle, &other)) {
    write.lock();
    read.lock();
  } else {
    read.lock();
    write.lock();
  }
  handle.unlocked().merge(other.unlocked(), transform);
}

}  // namespace

void bindMap(py::module_& module) {
  py::class_<mvog::InsertionResult>(module, "InsertionResult",
                                    "What happened to the readings of an insertion; every "
                                    "reading is counted exactly once.")
      .def_readonly("obstacle_readings", &mvog::InsertionResult::obstacle_readings)
      .def_readonly("out_of_range_readings", &mvog::InsertionResult::out_of_range_readings)
      .def_readonly("truncated_to_max_range", &mvog::InsertionResult::truncated_to_max_range)
      .def_readonly("rejected_non_finite", &mvog::InsertionResult::rejected_non_finite,
                    "NaN or infinite coordinates")
      .def_readonly("rejected_out_of_bounds", &mvog::InsertionResult::rejected_out_of_bounds)
      .def_readonly("rejected_too_close", &mvog::InsertionResult::rejected_too_close)
      .def_readonly("ignored_out_of_range", &mvog::InsertionResult::ignored_out_of_range)
      .def_readonly("rejected_no_measurement", &mvog::InsertionResult::rejected_no_measurement,
                    "depth pixels without a measurement (0, NaN, negative, -Inf)")
      .def_readonly("rays_walked", &mvog::InsertionResult::rays_walked)
      .def_readonly("obstacle_seconds", &mvog::InsertionResult::obstacle_seconds,
                    "thread time rasterising the obstacle readings (s)")
      .def_readonly("out_of_range_seconds", &mvog::InsertionResult::out_of_range_seconds,
                    "thread time rasterising the out-of-range readings (s)")
      .def_property_readonly("inserted", &mvog::InsertionResult::inserted)
      .def_property_readonly("rejected", &mvog::InsertionResult::rejected)
      .def("__repr__", [](const mvog::InsertionResult& r) {
        return "InsertionResult(inserted=" + std::to_string(r.inserted()) +
               ", rejected=" + std::to_string(r.rejected()) + ")";
      });

  py::class_<mvog::MemoryUsage>(module, "MemoryUsage", "Memory held by the map.")
      .def_readonly("bytes_held", &mvog::MemoryUsage::bytes_held)
      .def_readonly("table_one_bytes", &mvog::MemoryUsage::table_one_bytes,
                    "The paper's Table I accounting: 12 bytes per volume plus 8 per cell of the "
                    "minimal 2D grid")
      .def_readonly("minimal_grid_cells", &mvog::MemoryUsage::minimal_grid_cells)
      .def_readonly("cells_with_volumes", &mvog::MemoryUsage::cells_with_volumes)
      .def_readonly("positive_volumes", &mvog::MemoryUsage::positive_volumes)
      .def_readonly("negative_volumes", &mvog::MemoryUsage::negative_volumes)
      .def_readonly("tiles", &mvog::MemoryUsage::tiles);

  py::class_<mvog::ForgetResult>(module, "ForgetResult", "What Map.forget removed.")
      .def_readonly("volumes_removed", &mvog::ForgetResult::volumes_removed)
      .def_readonly("cells_emptied", &mvog::ForgetResult::cells_emptied)
      .def_readonly("tiles_freed", &mvog::ForgetResult::tiles_freed);

  py::class_<MapHandle, MapPointer> map_class(
      module, "Map",
      "A Multi-Volume Occupancy Grid (C++ mvog::Map). Points are in the map frame, metres. "
      "Methods release the GIL; one Python Map may be used from several threads (changes are "
      "serialised against queries by the map's lock).");
  map_class
      .def(py::init([](const mvog::MapConfig& config) {
             return std::make_shared<MapHandle>(mvog::Map(config));
           }),
           py::arg("config") = mvog::MapConfig{})
      .def_property_readonly(
          "config",
          [](const MapHandle& h) {
            return reading(h, [](const mvog::Map& map) { return map.config(); });
          },
          "The MapConfig (a copy).")
      .def_property_readonly(
          "resolution",
          [](const MapHandle& h) {
            return reading(h, [](const mvog::Map& map) { return map.resolution(); });
          },
          "Edge of a cell (m).")
      .def(
          "insert_scan",
          [](MapHandle& handle, const Eigen::Vector3d& origin, const py::handle& hits,
             const py::handle& out_of_range, const mvog::InsertionConfig& config) {
            return insertScan(handle, origin, hits, out_of_range, config);
          },
          py::arg("origin"), py::arg("hits"), py::arg("out_of_range") = py::none(),
          py::arg("config") = mvog::InsertionConfig{},
          "Inserts one scan (Sec. III-B, Fig. 2), all in the map frame (m): `origin` the "
          "sensor's position (3,), `hits` the obstacle readings' ends, `out_of_range` the ends "
          "of readings without a return (free space only), each an (N, 3) float32 or float64 "
          "array (float32 is read in place). Readings with NaN or infinite coordinates, beyond "
          "max_coordinate or nearer than min_range are rejected and counted in the returned "
          "InsertionResult, as in C++. TypeError for another dtype, ValueError for another "
          "shape or an invalid config.")
      .def(
          "insert_reading",
          [](MapHandle& handle, const Eigen::Vector3d& origin, const Eigen::Vector3d& end,
             mvog::ReadingKind kind, const mvog::InsertionConfig& config) {
            return writing(handle, [&](mvog::Map& map) {
              return map.insertReading(origin, end, kind, config);
            });
          },
          py::arg("origin"), py::arg("end"), py::arg("kind") = mvog::ReadingKind::kObstacle,
          py::arg("config") = mvog::InsertionConfig{},
          "Inserts the scan of one reading from `origin` to `end` (m, map frame).")
      .def("insert_depth_image", &insertDepthImage, py::arg("depth"), py::arg("camera"),
           py::arg("pose"), py::arg("config") = mvog::InsertionConfig{},
           py::arg("depth_config") = mvog::DepthImageConfig{},
           "Inserts a depth image (REP-118): `depth` an (H, W) array of uint16 millimetres (0: "
           "no measurement) or float32 metres (0 and NaN: no measurement, +inf: no return, "
           "-inf: too close), depth along the optical axis; `camera` its PinholeCamera; `pose` "
           "the 4 x 4 transform map_from_camera (m) of the camera's optical frame (x right, y "
           "down, z forward). Returns (InsertionResult, skipped_pixels). TypeError for another "
           "dtype, ValueError for another shape, a pose that is not rigid or an invalid config.")
      .def(
          "decay",
          [](MapHandle& handle, double k_d) {
            writing(handle, [&](mvog::Map& map) {
              map.decay(k_d);
              return 0;
            });
          },
          py::arg("k_d"), "Multiplies every mass by k_d in (0, 1] (Sec. III-E), in O(1).")
      .def(
          "forget",
          [](MapHandle& handle, double min_mass) {
            return writing(handle, [&](mvog::Map& map) { return map.forget(min_mass); });
          },
          py::arg("min_mass"),
          "Removes positive volumes, and runs of touching negative ones, lighter than min_mass "
          "(>= 0); their space becomes unknown. Returns a ForgetResult.")
      .def(
          "clear_box",
          [](MapHandle& handle, const Eigen::Vector3d& min_corner,
             const Eigen::Vector3d& max_corner) {
            return writing(handle,
                           [&](mvog::Map& map) { return map.clearBox(min_corner, max_corner); });
          },
          py::arg("min_corner"), py::arg("max_corner"),
          "Makes the box [min_corner, max_corner] (m, map frame; infinite corners allowed) "
          "unknown. Returns the number of cells changed.")
      .def("merge", &merge, py::arg("other"), py::arg("this_from_other") = mvog::GridTransform{},
           "Adds `other` into this map (Sec. III-B.3), moved by a GridTransform. ValueError if "
           "the resolutions or mass counting differ.")
      .def(
          "merge",
          [](MapHandle& handle, const MapHandle& other, const Eigen::Matrix4d& this_from_other) {
            const double resolution =
                reading(handle, [](const mvog::Map& map) { return map.resolution(); });
            merge(handle, other, mvog::GridTransform::fromMatrix(this_from_other, resolution));
          },
          py::arg("other"), py::arg("this_from_other"),
          "The same with a 4 x 4 transform (m): a yaw by a multiple of 90 degrees and whole "
          "cells in x and y, else ValueError.")
      .def(
          "drop_tiles_farther_than",
          [](MapHandle& handle, const Eigen::Vector2d& centre, double radius) {
            return std::make_shared<MapHandle>(writing(
                handle, [&](mvog::Map& map) { return map.dropTilesFartherThan(centre, radius); }));
          },
          py::arg("centre"), py::arg("radius"),
          "Removes the tiles wholly farther than radius (m) in xy from centre (x, y) and returns "
          "them as a Map.")
      .def(
          "clear",
          [](MapHandle& handle) {
            writing(handle, [](mvog::Map& map) {
              map.clear();
              return 0;
            });
          },
          "Removes every volume.")
      .def(
          "memory_usage",
          [](const MapHandle& handle) {
            return reading(handle, [](const mvog::Map& map) { return map.memoryUsage(); });
          },
          "A MemoryUsage.")
      .def_property_readonly(
          "revision",
          [](const MapHandle& h) {
            return reading(h, [](const mvog::Map& map) { return map.revision(); });
          },
          "Increases with every change.")
      .def_property_readonly(
          "empty",
          [](const MapHandle& h) {
            return reading(h, [](const mvog::Map& map) { return map.empty(); });
          },
          "Whether no cell holds a volume.")
      .def_property_readonly(
          "bounds",
          [](const MapHandle& h) -> std::optional<std::array<std::int32_t, 4>> {
            const mvog::CellRange cells =
                reading(h, [](const mvog::Map& map) { return map.bounds(); });
            if (cells.empty()) return std::nullopt;
            return std::array<std::int32_t, 4>{cells.min.x, cells.min.y, cells.max.x, cells.max.y};
          },
          "The smallest rectangle of cells (min_i, min_j, max_i, max_j), inclusive, holding "
          "every cell with a volume; None for an empty map.")
      .def(
          "tiles_modified_since",
          [](const MapHandle& handle, std::uint64_t revision) {
            const std::vector<mvog::TileIndex> tiles = reading(
                handle, [&](const mvog::Map& map) { return map.tilesModifiedSince(revision); });
            py::array_t<std::int32_t> result(
                {static_cast<py::ssize_t>(tiles.size()), static_cast<py::ssize_t>(2)});
            auto out = result.mutable_unchecked<2>();
            for (std::size_t k = 0; k < tiles.size(); ++k) {
              out(k, 0) = tiles[k].x;
              out(k, 1) = tiles[k].y;
            }
            return result;
          },
          py::arg("revision"),
          "The tiles (16 x 16 cells) whose volumes changed after `revision`, as an (N, 2) "
          "int32 array of tile indices.");
  bindMapQueries(module, map_class);
}

}  // namespace mvog_python
