#include "backends.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include <Eigen/Geometry>

#include "mvog/map_io.h"

namespace mvog_bench {
namespace {

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// Where a ray ends once truncated to max_range (both backends truncate the same way).
Eigen::Vector3d rayEnd(const Eigen::Vector3d& origin, const Eigen::Vector3f& hit,
                       double max_range) {
  const Eigen::Vector3d ray = hit.cast<double>() - origin;
  const double length = ray.norm();
  return length > max_range ? Eigen::Vector3d(origin + ray * (max_range / length))
                            : hit.cast<double>();
}

octomap::point3d toOctomap(const Eigen::Vector3d& p) {
  return octomap::point3d(static_cast<float>(p.x()), static_cast<float>(p.y()),
                          static_cast<float>(p.z()));
}

std::size_t stateIndex(mvog::OccupancyState state) { return static_cast<std::size_t>(state); }

mvog::OccupancyState octomapState(const octomap::OcTree& tree, const Eigen::Vector3d& p) {
  const octomap::OcTreeNode* node = tree.search(toOctomap(p));
  if (node == nullptr) return mvog::OccupancyState::kUnknown;
  return tree.isNodeOccupied(node) ? mvog::OccupancyState::kOccupied : mvog::OccupancyState::kFree;
}

}  // namespace

MvogRun runMvog(const InputData& input, const RunOptions& options) {
  mvog::MapConfig map_config;
  map_config.resolution = options.resolution;
  mvog::InsertionConfig insertion;
  insertion.max_range = options.max_range;
  insertion.insertion_threads = options.threads;
  insertion.clear_conflicting_free_space = options.clear_conflicting_free_space;
  MvogRun run{mvog::Map(map_config), {}};
  MvogStats& stats = run.stats;
  stats.threads = options.threads;
  const auto start = std::chrono::steady_clock::now();
  for (const mvog::Scan& scan : input.scans) stats.insertion += run.map.insertScan(scan, insertion);
  stats.insert_seconds = secondsSince(start);
  stats.memory = run.map.memoryUsage();
  const std::vector<std::uint8_t> file = mvog::serializeMap(run.map);
  stats.file_bytes = file.size();
  for (std::size_t k = 0; k < 8; ++k) {  // the format's trailing little-endian checksum
    stats.checksum |= std::uint64_t{file[file.size() - 8 + k]} << (8 * k);
  }
  return run;
}

OctomapRun runOctomap(const InputData& input, const RunOptions& options) {
  std::vector<octomap::Pointcloud> clouds(input.scans.size());
  for (std::size_t k = 0; k < input.scans.size(); ++k) {
    clouds[k].reserve(input.scans[k].hits.size());
    for (const Eigen::Vector3f& hit : input.scans[k].hits) {
      clouds[k].push_back(hit.x(), hit.y(), hit.z());
    }
  }
  const double max_range = std::isfinite(options.max_range) ? options.max_range : -1.0;
  OctomapRun run;
  run.tree = std::make_unique<octomap::OcTree>(options.resolution);
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t k = 0; k < clouds.size(); ++k) {
    run.tree->insertPointCloud(clouds[k], toOctomap(input.scans[k].origin), max_range);
  }
  OctomapStats& stats = run.stats;
  stats.insert_seconds = secondsSince(start);
  run.tree->prune();
  stats.memory_bytes = run.tree->memoryUsage();
  stats.tree_nodes = run.tree->size();
  stats.leaf_nodes = run.tree->getNumLeafNodes();
  std::ostringstream full;
  if (!run.tree->write(full)) throw std::runtime_error("octomap: OcTree::write failed");
  stats.full_file_bytes = full.str().size();
  return run;
}

std::size_t octomapBinaryFileBytes(octomap::OcTree& tree) {
  std::ostringstream binary;
  if (!tree.writeBinary(binary)) throw std::runtime_error("octomap: OcTree::writeBinary failed");
  return binary.str().size();
}

std::size_t boundingBoxVoxels(const InputData& input, const RunOptions& options) {
  Eigen::AlignedBox3d box;
  for (const mvog::Scan& scan : input.scans) {
    box.extend(scan.origin);
    for (const Eigen::Vector3f& hit : scan.hits) {
      box.extend(rayEnd(scan.origin, hit, options.max_range));
    }
  }
  std::size_t voxels = 1;
  for (int axis = 0; axis < 3; ++axis) {
    const double first = std::floor(box.min()[axis] / options.resolution);
    const double last = std::floor(box.max()[axis] / options.resolution);
    voxels *= static_cast<std::size_t>(last - first) + 1;
  }
  return voxels;
}

std::size_t StateAgreement::points() const {
  std::size_t total = 0;
  for (const auto& row : counts) {
    for (std::size_t count : row) total += count;
  }
  return total;
}

std::size_t StateAgreement::agreeing() const { return counts[0][0] + counts[1][1] + counts[2][2]; }

Agreement compareMaps(const InputData& input, const RunOptions& options, const mvog::Map& map,
                      const octomap::OcTree& tree, std::size_t max_rays) {
  constexpr double kFractions[] = {0.1, 0.3, 0.5, 0.7, 0.9};
  const std::size_t stride = std::max<std::size_t>(1, (input.readings() + max_rays - 1) / max_rays);
  Agreement agreement;
  auto compare = [&](const Eigen::Vector3d& p, StateAgreement& into) {
    ++into.counts[stateIndex(map.occupancy(p).state(0.5))][stateIndex(octomapState(tree, p))];
  };
  std::size_t index = 0;
  for (const mvog::Scan& scan : input.scans) {
    for (const Eigen::Vector3f& hit : scan.hits) {
      if (index++ % stride != 0) continue;
      ++agreement.sampled_rays;
      const Eigen::Vector3d end = rayEnd(scan.origin, hit, options.max_range);
      compare(end, agreement.endpoints);
      for (double fraction : kFractions) {
        compare(scan.origin + fraction * (end - scan.origin), agreement.along_rays);
      }
    }
  }
  return agreement;
}

}  // namespace mvog_bench
