// The Python module mvog._mvog (pybind11): the core's public API for numpy. Each part of the API
// is bound by one function, in its own source; module.cpp calls them in order.
#pragma once

#include <pybind11/pybind11.h>

#include <memory>

#include "map_handle.h"

namespace mvog_python {

namespace py = pybind11;

/// The exceptions: ConfigError (a ValueError) and MapFileError (an OSError).
void bindErrors(py::module_& module);
/// MapConfig, ModelRules, InsertionConfig, PlanningConfig, DepthImageConfig, PinholeCamera,
/// GridTransform and the enums.
void bindConfigs(py::module_& module);
/// Map: insertion, edits, bookkeeping (map_binding.cpp), and its queries (map_queries.cpp).
void bindMap(py::module_& module);
void bindMapQueries(py::module_& module, py::class_<MapHandle, MapPointer>& map_class);
/// checkSegments, checkBoxes, Frontiers, Surfaces, traversableMap.
void bindPlanning(py::module_& module);
/// Map files, map updates and MapMirror.
void bindFiles(py::module_& module);

}  // namespace mvog_python
