// The extension mvog._mvog, loaded by the package mvog (python/mvog/__init__.py) beside the
// messages' mvog.msg and mvog.srv.
#include <pybind11/pybind11.h>

#include "bindings.h"

PYBIND11_MODULE(_mvog, module) {
  module.doc() =
      "Multi-Volume Occupancy Grids (the mvog core, C++) for numpy. Points are in the map "
      "frame, metres; a volume's heights are in grid units (z / resolution).";
  mvog_python::bindErrors(module);
  mvog_python::bindConfigs(module);
  mvog_python::bindMap(module);
  mvog_python::bindPlanning(module);
  mvog_python::bindFiles(module);
}
