// Map files (mvog/map_io.h: the binary format, saved atomically), map updates and MapMirror.
// Paths are str or os.PathLike (pathlib.Path); bytes in are any contiguous buffer.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "bindings.h"
#include "mvog/map_io.h"

namespace mvog_python {

namespace {

/// The bytes of a buffer (bytes, bytearray, a uint8 array), held while they are read.
struct Bytes {
  explicit Bytes(const py::buffer& buffer) : info(buffer.request()) {
    if (info.ndim > 1 || (info.ndim == 1 && info.strides[0] != info.itemsize)) {
      throw py::value_error("data: expected contiguous bytes");
    }
  }
  const std::uint8_t* data() const { return static_cast<const std::uint8_t*>(info.ptr); }
  std::size_t size() const { return static_cast<std::size_t>(info.size * info.itemsize); }
  py::buffer_info info;
};

py::bytes bytesOf(const std::vector<std::uint8_t>& data) {
  return {reinterpret_cast<const char*>(data.data()), data.size()};
}

/// A MapMirror whose map is a Python Map: apply() swaps the map in under its lock, applies the
/// update and swaps it back out (MapMirror::swapMap), so that the map is read and locked like
/// any other.
struct Mirror {
  mvog::MapMirror mirror;
  MapPointer map = std::make_shared<MapHandle>(mvog::Map());
  std::mutex mutex;

  mvog::MapUpdateResult apply(const Bytes& update) {
    py::gil_scoped_release no_gil;
    const std::lock_guard<std::mutex> own(mutex);
    auto [target, lock] = map->write();
    mirror.swapMap(target);
    mvog::MapUpdateResult result;
    try {
      result = mirror.apply(update.data(), update.size());
    } catch (...) {
      mirror.swapMap(target);  // the map as it was: apply() changes nothing when it throws
      throw;
    }
    mirror.swapMap(target);
    return result;
  }
};

}  // namespace

void bindFiles(py::module_& module) {
  module.attr("MAP_FORMAT_VERSION") = mvog::kMapFormatVersion;

  module.def(
      "load_map",
      [](const std::filesystem::path& path) {
        py::gil_scoped_release no_gil;
        return std::make_shared<MapHandle>(mvog::loadMap(path.string()));
      },
      py::arg("path"),
      "Loads a map file (str or pathlib.Path). MapFileError (an OSError) if it cannot be read "
      "or is not a complete, valid map (truncated, wrong checksum); nothing is half-loaded.");
  module.def(
      "save_map",
      [](const MapHandle& handle, const std::filesystem::path& path) {
        py::gil_scoped_release no_gil;
        // Serialised under the lock, written after releasing it (saveMapBytes).
        const std::vector<std::uint8_t> bytes = [&] {
          auto [map, lock] = handle.read();
          return mvog::serializeMap(map);
        }();
        mvog::saveMapBytes(bytes, path.string());
      },
      py::arg("map"), py::arg("path"),
      "Saves the map to `path` (str or pathlib.Path) atomically: a previous file there stays "
      "whole until the new one replaces it. MapFileError on failure.");
  module.def(
      "serialize_map",
      [](const MapHandle& handle) {
        return bytesOf(
            reading(handle, [](const mvog::Map& map) { return mvog::serializeMap(map); }));
      },
      py::arg("map"), "The map file's bytes (the binary format of mvog/map_io.h).");
  module.def(
      "deserialize_map",
      [](const py::buffer& data) {
        const Bytes bytes(data);
        py::gil_scoped_release no_gil;
        return std::make_shared<MapHandle>(mvog::deserializeMap(bytes.data(), bytes.size()));
      },
      py::arg("data"), "A map from a map file's bytes. MapFileError if they are not a valid map.");

  py::class_<mvog::MapUpdateInfo>(module, "MapUpdateInfo", "What an update says about itself.")
      .def_readonly("full", &mvog::MapUpdateInfo::full, "Holds every tile of the source.")
      .def_readonly("source", &mvog::MapUpdateInfo::source)
      .def_readonly("from_revision", &mvog::MapUpdateInfo::from_revision)
      .def_readonly("to_revision", &mvog::MapUpdateInfo::to_revision)
      .def_readonly("resolution", &mvog::MapUpdateInfo::resolution)
      .def_readonly("tiles_changed", &mvog::MapUpdateInfo::tiles_changed)
      .def_readonly("tiles_removed", &mvog::MapUpdateInfo::tiles_removed);
  py::enum_<mvog::MapUpdateStatus>(module, "MapUpdateStatus", "What MapMirror.apply did.")
      .value("APPLIED", mvog::MapUpdateStatus::kApplied)
      .value("MISSED", mvog::MapUpdateStatus::kMissed,
             "not applied: updates were missed or it comes from another source; a full update "
             "is needed")
      .value("OUTDATED", mvog::MapUpdateStatus::kOutdated, "not applied: older than the mirror");
  py::class_<mvog::MapUpdateResult>(module, "MapUpdateResult")
      .def_readonly("status", &mvog::MapUpdateResult::status)
      .def_readonly("update", &mvog::MapUpdateResult::update);

  module.def(
      "map_update",
      [](const MapHandle& handle, std::uint64_t since_revision) {
        return bytesOf(reading(handle, [&](const mvog::Map& map) {
          return mvog::serializeMapUpdate(map, since_revision);
        }));
      },
      py::arg("map"), py::arg("since_revision") = 0,
      "An update (bytes) with what changed in `map` after since_revision (its revision at the "
      "previous update); a full update for 0.");
  module.def(
      "read_map_update_info",
      [](const py::buffer& data) {
        const Bytes bytes(data);
        return mvog::readMapUpdateInfo(bytes.data(), bytes.size());
      },
      py::arg("data"), "The header of an update, checked with its checksum. MapFileError.");

  py::class_<Mirror>(module, "MapMirror",
                     "A map rebuilt from another map's updates (map_update), equal to it bit for "
                     "bit after each. Its map is an ordinary Map; changing it otherwise makes the "
                     "next updates describe another map than the one they are applied to.")
      .def(py::init<>())
      .def(
          "apply", [](Mirror& mirror, const py::buffer& data) { return mirror.apply(Bytes(data)); },
          py::arg("data"),
          "Applies an update if it follows what the mirror holds; returns a MapUpdateResult. "
          "MapFileError, changing nothing, for bytes that are not a valid update.")
      .def_property_readonly(
          "map", [](const Mirror& mirror) { return mirror.map; }, "The mirror's Map.")
      .def_property_readonly(
          "source_revision",
          [](Mirror& mirror) {
            const std::lock_guard<std::mutex> own(mirror.mutex);
            return mirror.mirror.sourceRevision();
          },
          "The source's revision the map equals (0: no full update applied yet).");
}

}  // namespace mvog_python
