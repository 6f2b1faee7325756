#include "bonxai_backend.h"

#include <chrono>
#include <utility>

#include <bonxai_map/probabilistic_map.hpp>

namespace mvog_bench {

BonxaiRun runBonxai(const InputData& input, const RunOptions& options) {
  auto map = std::make_shared<Bonxai::ProbabilisticMap>(options.resolution);
  // An infinite max_range truncates nothing: Bonxai compares squared lengths with its square.
  const auto start = std::chrono::steady_clock::now();
  for (const mvog::Scan& scan : input.scans) {
    map->insertPointCloud(scan.hits, Eigen::Vector3f(scan.origin.cast<float>()), options.max_range);
  }
  BonxaiRun run;
  run.stats.insert_seconds = secondsSince(start);
  run.stats.memory_bytes = map->grid().memUsage();
  run.stats.active_cells = map->grid().activeCellsCount();
  run.map = std::move(map);
  return run;
}

mvog::OccupancyState bonxaiState(const Bonxai::ProbabilisticMap& map,
                                 const Eigen::Vector3d& point) {
  const Bonxai::CoordT voxel = map.grid().posToCoord(point.x(), point.y(), point.z());
  if (map.isOccupied(voxel)) return mvog::OccupancyState::kOccupied;
  return map.isFree(voxel) ? mvog::OccupancyState::kFree : mvog::OccupancyState::kUnknown;
}

Quality bonxaiQuality(const Bonxai::ProbabilisticMap& map, const SamplePoints& points) {
  return qualityOf(points, [&](const Eigen::Vector3d& p) { return bonxaiState(map, p); });
}

}  // namespace mvog_bench
