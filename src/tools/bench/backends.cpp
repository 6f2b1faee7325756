#include "backends.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <sstream>
#include <unordered_set>

#include <Eigen/Geometry>

#include "mvog/map_io.h"
#include "mvog/raster.h"

namespace mvog_bench {

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

namespace {

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

}  // namespace

mvog::OccupancyState octomapState(const octomap::OcTree& tree, const Eigen::Vector3d& p) {
  const octomap::OcTreeNode* node = tree.search(toOctomap(p));
  if (node == nullptr) return mvog::OccupancyState::kUnknown;
  return tree.isNodeOccupied(node) ? mvog::OccupancyState::kOccupied : mvog::OccupancyState::kFree;
}

MvogRun runMvog(const InputData& input, const RunOptions& options) {
  mvog::MapConfig map_config;
  map_config.resolution = options.resolution;
  map_config.rules = options.rules;
  mvog::InsertionConfig insertion;
  insertion.max_range = options.max_range;
  insertion.insertion_threads = options.threads;
  insertion.free_space_rays = options.free_space_rays;
  insertion.evidence_limit = options.evidence_limit;
  insertion.hit_memory_scans = options.hit_memory_scans;
  insertion.hit_memory_scope = options.hit_memory_scope;
  MvogRun run{mvog::Map(map_config), {}};
  MvogStats& stats = run.stats;
  stats.threads = options.threads;
  std::vector<mvog::Scan> with_out_of_range;
  if (options.out_of_range) {
    with_out_of_range = input.scans;
    for (std::size_t k = 0; k < input.scans.size(); ++k) {
      with_out_of_range[k].out_of_range = input.out_of_range[k];
    }
  }
  const std::vector<mvog::Scan>& scans = options.out_of_range ? with_out_of_range : input.scans;
  const auto start = std::chrono::steady_clock::now();
  for (const mvog::Scan& scan : scans) stats.insertion += run.map.insertScan(scan, insertion);
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
  if (!options.octomap_clamping) {  // logodds of 0 and 1: -inf and +inf, no bound
    run.tree->setClampingThresMin(0.0);
    run.tree->setClampingThresMax(1.0);
  }
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

namespace {

constexpr double kFarMargin = 3.0;    // m
constexpr double kFarDistance = 1.0;  // m: the voxel edge of the ray coverage
constexpr std::size_t kFarCandidates = 200000;
constexpr std::size_t kFarPoints = 20000;

}  // namespace

std::uint64_t voxelKey(const Eigen::Vector3i& voxel) {
  return (std::uint64_t{static_cast<std::uint16_t>(voxel.x())} << 32) |
         (std::uint64_t{static_cast<std::uint16_t>(voxel.y())} << 16) |
         std::uint64_t{static_cast<std::uint16_t>(voxel.z())};
}

std::size_t RayCoverage::bitInBlock(const Eigen::Vector3i& voxel) {
  constexpr int kMask = (1 << kBlockShift) - 1;
  return static_cast<std::size_t>(
      (((voxel.z() & kMask) << kBlockShift | (voxel.y() & kMask)) << kBlockShift) |
      (voxel.x() & kMask));
}

RayCoverage::RayCoverage(const InputData& input, double max_range, double voxel_edge)
    : voxel_edge_(voxel_edge) {
  // The block of the voxel before: a ray's next voxel is in it mostly.
  std::uint64_t block_key = ~std::uint64_t{0};
  Block* block = nullptr;
  auto mark = [&](const Eigen::Vector3i& voxel) {
    // An arithmetic shift: blocks of negative voxels too.
    const std::uint64_t key = voxelKey(voxel.unaryExpr([](int v) { return v >> kBlockShift; }));
    if (key != block_key) {
      block_key = key;
      block = &blocks_[key];
    }
    block->set(bitInBlock(voxel));
  };
  for (const mvog::Scan& scan : input.scans) {
    const Eigen::Vector3d start = scan.origin / voxel_edge;
    for (const Eigen::Vector3f& hit : scan.hits) {
      const Eigen::Vector3d end = rayEnd(scan.origin, hit, max_range) / voxel_edge;
      const Eigen::Vector3d delta = end - start;
      Eigen::Vector3i voxel = start.array().floor().cast<int>();
      const Eigen::Vector3i last = end.array().floor().cast<int>();
      Eigen::Vector3i step;
      Eigen::Vector3d t_next, t_delta;
      for (int axis = 0; axis < 3; ++axis) {
        step[axis] = delta[axis] > 0 ? 1 : -1;
        const double wall = voxel[axis] + (delta[axis] > 0 ? 1.0 : 0.0);
        t_next[axis] = delta[axis] != 0.0 ? (wall - start[axis]) / delta[axis] : INFINITY;
        t_delta[axis] = delta[axis] != 0.0 ? 1.0 / std::fabs(delta[axis]) : INFINITY;
      }
      mark(voxel);
      const int steps = (last - voxel).cwiseAbs().sum();
      for (int k = 0; k < steps; ++k) {
        int axis = 0;
        t_next.minCoeff(&axis);
        voxel[axis] += step[axis];
        t_next[axis] += t_delta[axis];
        mark(voxel);
      }
    }
  }
}

bool RayCoverage::crossed(const Eigen::Vector3i& voxel) const {
  const auto block =
      blocks_.find(voxelKey(voxel.unaryExpr([](int v) { return v >> kBlockShift; })));
  return block != blocks_.end() && block->second.test(bitInBlock(voxel));
}

bool RayCoverage::near(const Eigen::Vector3d& point, int reach) const {
  const Eigen::Vector3i voxel = (point / voxel_edge_).array().floor().cast<int>();
  for (int dx = -reach; dx <= reach; ++dx) {
    for (int dy = -reach; dy <= reach; ++dy) {
      for (int dz = -reach; dz <= reach; ++dz) {
        if (crossed(voxel + Eigen::Vector3i(dx, dy, dz))) return true;
      }
    }
  }
  return false;
}

WalkStats runWalk(const InputData& input, const RunOptions& options) {
  const double s = 1.0 / options.resolution;
  mvog::CellRange cells = mvog::kNoCells;
  auto include = [&](const Eigen::Vector3d& p) {
    cells.extend(mvog::cellAt(p.x() * s, p.y() * s));
  };
  std::vector<std::vector<Eigen::Vector3d>> ends(input.scans.size());
  for (std::size_t k = 0; k < input.scans.size(); ++k) {
    include(input.scans[k].origin);
    for (const Eigen::Vector3f& hit : input.scans[k].hits) {
      ends[k].push_back(rayEnd(input.scans[k].origin, hit, options.max_range) * s);
      include(ends[k].back() / s);
    }
  }
  struct Column {
    float min = INFINITY;
    float max = -INFINITY;
    float sum = 0.0f;
  };
  const auto width = static_cast<std::size_t>(cells.width());
  std::vector<Column> columns(width * static_cast<std::size_t>(cells.height()));
  WalkStats stats;
  const auto start_time = std::chrono::steady_clock::now();
  for (std::size_t k = 0; k < input.scans.size(); ++k) {
    const Eigen::Vector3d start = input.scans[k].origin * s;
    for (const Eigen::Vector3d& end : ends[k]) {
      mvog::walkRay(start.x(), start.y(), start.z(), end.x(), end.y(), end.z(),
                    [&](const mvog::CellIndex& cell, double z_enter, double z_exit, bool) {
                      Column& column =
                          columns[static_cast<std::size_t>(cell.y - cells.min.y) * width +
                                  static_cast<std::size_t>(cell.x - cells.min.x)];
                      const auto low = static_cast<float>(std::min(z_enter, z_exit));
                      const auto high = static_cast<float>(std::max(z_enter, z_exit));
                      column.min = std::min(column.min, low);
                      column.max = std::max(column.max, high);
                      column.sum += high - low;
                      ++stats.cell_visits;
                    });
    }
  }
  stats.insert_seconds = secondsSince(start_time);
  // Keep the array alive and read, so that the walk is not optimised away.
  double total = 0.0;
  for (const Column& column : columns) total += column.sum;
  if (!std::isfinite(total)) stats.cell_visits = 0;
  return stats;
}

SamplePoints samplePoints(const InputData& input, const RunOptions& options, std::size_t max_rays) {
  constexpr double kFractions[] = {0.1, 0.3, 0.5, 0.7, 0.9};
  const std::size_t stride = std::max<std::size_t>(1, (input.readings() + max_rays - 1) / max_rays);
  SamplePoints points;
  Eigen::AlignedBox3d box;
  std::size_t index = 0;
  for (const mvog::Scan& scan : input.scans) {
    box.extend(scan.origin);
    for (const Eigen::Vector3f& hit : scan.hits) {
      const Eigen::Vector3d end = rayEnd(scan.origin, hit, options.max_range);
      box.extend(end);
      if (index++ % stride != 0) continue;
      ++points.sampled_rays;
      points.endpoints.push_back(end);
      for (double fraction : kFractions) {
        points.along_rays.push_back(scan.origin + fraction * (end - scan.origin));
      }
    }
  }
  const RayCoverage coverage(input, options.max_range, kFarDistance);
  const Eigen::Vector3d low = box.min().array() - kFarMargin;
  const Eigen::Vector3d high = box.max().array() + kFarMargin;
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (std::size_t k = 0; k < kFarCandidates && points.far_from_data.size() < kFarPoints; ++k) {
    const Eigen::Vector3d p(low.x() + unit(rng) * (high.x() - low.x()),
                            low.y() + unit(rng) * (high.y() - low.y()),
                            low.z() + unit(rng) * (high.z() - low.z()));
    if (!coverage.near(p, 1)) points.far_from_data.push_back(p);
  }
  return points;
}

double StateCounts::percent(mvog::OccupancyState state) const {
  return points() == 0 ? std::nan("")
                       : 100.0 * static_cast<double>(counts[stateIndex(state)]) /
                             static_cast<double>(points());
}

Quality mvogQuality(const mvog::Map& map, double occupancy_threshold, const SamplePoints& points) {
  return qualityOf(points, [&](const Eigen::Vector3d& p) {
    return map.occupancy(p).state(occupancy_threshold);
  });
}

Quality octomapQuality(const octomap::OcTree& tree, const SamplePoints& points) {
  return qualityOf(points, [&](const Eigen::Vector3d& p) { return octomapState(tree, p); });
}

std::size_t StateAgreement::points() const {
  std::size_t total = 0;
  for (const auto& row : counts) {
    for (std::size_t count : row) total += count;
  }
  return total;
}

std::size_t StateAgreement::agreeing() const { return counts[0][0] + counts[1][1] + counts[2][2]; }

namespace {

/// The states two maps give at `at` (`state_of(map, p)` for each), into `into`.
template <class StateOfFirst, class StateOfSecond>
void countStates(const std::vector<Eigen::Vector3d>& at, const StateOfFirst& first,
                 const StateOfSecond& second, StateAgreement& into) {
  for (const Eigen::Vector3d& p : at) ++into.counts[stateIndex(first(p))][stateIndex(second(p))];
}

}  // namespace

Agreement compareMaps(const SamplePoints& points, const mvog::Map& map, double occupancy_threshold,
                      const octomap::OcTree& tree) {
  Agreement agreement;
  agreement.sampled_rays = points.sampled_rays;
  const auto mvog_state = [&](const Eigen::Vector3d& p) {
    return map.occupancy(p).state(occupancy_threshold);
  };
  const auto octomap_state = [&](const Eigen::Vector3d& p) { return octomapState(tree, p); };
  countStates(points.endpoints, mvog_state, octomap_state, agreement.endpoints);
  countStates(points.along_rays, mvog_state, octomap_state, agreement.along_rays);
  return agreement;
}

EveryReadingAgreement compareWithEveryReading(const SamplePoints& points, double resolution,
                                              double occupancy_threshold, const mvog::Map& map,
                                              const mvog::Map& every_reading) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> offset(-kNearEndCells * resolution,
                                                kNearEndCells * resolution);
  std::vector<Eigen::Vector3d> near_ends;
  near_ends.reserve(points.endpoints.size() * kNearEndPoints);
  for (const Eigen::Vector3d& end : points.endpoints) {
    for (std::size_t k = 0; k < kNearEndPoints; ++k) {
      near_ends.push_back(end + Eigen::Vector3d(offset(rng), offset(rng), offset(rng)));
    }
  }
  const auto state = [&](const mvog::Map& of) {
    return [&of, occupancy_threshold](const Eigen::Vector3d& p) {
      return of.occupancy(p).state(occupancy_threshold);
    };
  };
  EveryReadingAgreement agreement;
  countStates(points.endpoints, state(map), state(every_reading), agreement.endpoints);
  countStates(points.along_rays, state(map), state(every_reading), agreement.along_rays);
  countStates(near_ends, state(map), state(every_reading), agreement.near_ends);
  return agreement;
}

}  // namespace mvog_bench
