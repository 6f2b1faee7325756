// libFuzzer target: the map-file reader, mvog::deserializeMap, on arbitrary bytes.
//
// Whatever the bytes, deserializeMap returns a complete map or throws MapFileError: no crash, no
// undefined behaviour, no allocation beyond what the size bounds. A map it accepts must behave:
// it serialises, its serialisation loads back to the same bytes, queries and decay work on it.
// Also replayed without libFuzzer by fuzz_replay (test/fuzz/corpus and test/fuzz/regressions).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <vector>

#include "mvog/map.h"
#include "mvog/map_io.h"

namespace {

void check(bool condition) {
  if (!condition) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  mvog::Map map;
  try {
    map = mvog::deserializeMap(data, size);
  } catch (const mvog::MapFileError&) {
    return 0;  // refused, with a message: the expected outcome for almost every input
  }
  const std::vector<std::uint8_t> bytes = mvog::serializeMap(map);
  const mvog::Map again = mvog::deserializeMap(bytes.data(), bytes.size());
  check(mvog::serializeMap(again) == bytes);

  const mvog::MemoryUsage usage = map.memoryUsage();
  check(usage.cells_with_volumes <= usage.minimal_grid_cells);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector3d& point :
       {Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector3d(nan, 0.0, 0.0),
        Eigen::Vector3d(0.0, inf, 0.0), Eigen::Vector3d(1e300, -1e300, 1e300)}) {
    const mvog::PointOccupancy occupancy = map.occupancy(point);
    if (occupancy.probability)
      check(*occupancy.probability >= 0.0f && *occupancy.probability <= 1.0f);
  }
  const mvog::CellRange bounds = map.bounds();
  if (!bounds.empty()) {
    // Every cell with a volume is inside the bounds; probe the corners and a small window.
    const mvog::CellRange window{bounds.min,
                                 {static_cast<std::int32_t>(std::min<std::int64_t>(
                                      bounds.max.x, std::int64_t{bounds.min.x} + 63)),
                                  static_cast<std::int32_t>(std::min<std::int64_t>(
                                      bounds.max.y, std::int64_t{bounds.min.y} + 63))}};
    const double z = map.resolution() * 0.5;
    const mvog::CrossSection section = map.crossSection(z, window);
    check(section.values.size() == static_cast<std::size_t>(window.width() * window.height()));
    map.projection(-inf, inf, 0.5, window);
    std::size_t visited = 0;
    map.forEachVolumeIn(window,
                        [&](const mvog::CellIndex& cell, mvog::VolumeSign, const mvog::Volume&) {
                          check(window.contains(cell));
                          ++visited;
                        });
    check(visited <= usage.positive_volumes + usage.negative_volumes);
  }
  map.decay(0.5);
  const std::vector<std::uint8_t> decayed = mvog::serializeMap(map);
  mvog::deserializeMap(decayed.data(), decayed.size());  // still a valid map: must not throw
  return 0;
}
