#pragma once

#include <array>
#include <bitset>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <unordered_map>
#include <unordered_set>

#include <octomap/OcTree.h>

#include "input.h"
#include "mvog/map.h"

namespace mvog_bench {

/// How the backends map one input.
struct RunOptions {
  double resolution = 0.1;
  /// Hits further than this (m) are truncated to it and insert free space only, in every
  /// backend (OctoMap's insertPointCloud maxrange); infinity: no limit.
  double max_range = 0.0;
  int threads = 1;  ///< MVOG only; OctoMap's and Bonxai's insertions are single-threaded
  /// MVOG only: the model's rules (MapConfig::rules).
  mvog::ModelRules rules;
  /// MVOG only: occupied where p is above it.
  double occupancy_threshold = mvog::kDefaultOccupancyThreshold;
  /// MVOG only: insert the out-of-range readings too (with rules.out_of_range_free_length).
  bool out_of_range = false;
  /// MVOG only: which rays are walked for free space (InsertionConfig::free_space_rays).
  mvog::FreeSpaceRays free_space_rays = mvog::InsertionConfig{}.free_space_rays;
  /// OctoMap only: its log-odds clamped to [logodds(0.1192), logodds(0.971)] at each update (its
  /// default), or not clamped at all (OcTree::setClampingThresMin(0), setClampingThresMax(1)).
  bool octomap_clamping = true;
  /// MVOG only: InsertionConfig::evidence_limit.
  double evidence_limit = mvog::InsertionConfig{}.evidence_limit;
  /// MVOG only: InsertionConfig::hit_memory_scans.
  int hit_memory_scans = mvog::InsertionConfig{}.hit_memory_scans;
  /// MVOG only: InsertionConfig::hit_memory_scope.
  mvog::HitMemoryScope hit_memory_scope = mvog::InsertionConfig{}.hit_memory_scope;
};

/// Seconds from `start` to now (steady clock): what each backend's insertion took.
double secondsSince(std::chrono::steady_clock::time_point start);

struct MvogStats {
  int threads = 1;
  double insert_seconds = 0.0;
  mvog::InsertionResult insertion;
  mvog::MemoryUsage memory;
  std::size_t file_bytes = 0;  ///< mvog::serializeMap
  /// The map file's own FNV-1a checksum: equal checksums, equal maps (e.g. across --threads).
  std::uint64_t checksum = 0;
};

struct MvogRun {
  mvog::Map map;
  MvogStats stats;
};

struct OctomapStats {
  double insert_seconds = 0.0;
  std::size_t memory_bytes = 0;  ///< OcTree::memoryUsage() after prune()
  std::size_t tree_nodes = 0;
  std::size_t leaf_nodes = 0;
  std::size_t full_file_bytes = 0;    ///< OcTree::write() (.ot, full probabilities)
  std::size_t binary_file_bytes = 0;  ///< octomapBinaryFileBytes()
};

struct OctomapRun {
  std::unique_ptr<octomap::OcTree> tree;
  OctomapStats stats;
};

/// Inserts every scan with Map::insertScan; only the insertion is timed.
MvogRun runMvog(const InputData& input, const RunOptions& options);

/// Inserts every scan with OcTree::insertPointCloud(cloud, origin, max_range), one thread; only
/// the insertion is timed. The point clouds are built beforehand.
OctomapRun runOctomap(const InputData& input, const RunOptions& options);

/// Size of OcTree::writeBinary() (.bt, maximum likelihood). writeBinary converts the tree to its
/// maximum-likelihood estimate, so call this after every other use of the tree.
std::size_t octomapBinaryFileBytes(octomap::OcTree& tree);

/// Cells of the smallest 3D grid at `resolution` holding every ray (origins and ends).
std::size_t boundingBoxVoxels(const InputData& input, const RunOptions& options);

/// The bare walk, the floor of MVOG's insertion: the same rays through mvog::walkRay with
/// nothing per visited cell but a min, a max and an add into a dense array of the cells.
struct WalkStats {
  double insert_seconds = 0.0;
  std::size_t cell_visits = 0;
};
WalkStats runWalk(const InputData& input, const RunOptions& options);

/// The voxels of edge `voxel_edge` that some ray of `input` crosses (truncated to max_range),
/// by a 3D Amanatides-Woo walk from its origin to its end.
class RayCoverage {
 public:
  RayCoverage(const InputData& input, double max_range, double voxel_edge);
  /// Whether a crossed voxel lies within `reach` voxels of the one holding `point` along every
  /// axis; if not, `point` is more than reach * voxel_edge from every ray.
  bool near(const Eigen::Vector3d& point, int reach) const;

 private:
  /// Blocks of 16^3 voxels, a bit each: a lidar's rays of 100 m cross tens of millions.
  static constexpr int kBlockShift = 4;
  using Block = std::bitset<std::size_t{1} << (3 * kBlockShift)>;
  static std::size_t bitInBlock(const Eigen::Vector3i& voxel);
  bool crossed(const Eigen::Vector3i& voxel) const;

  double voxel_edge_;
  std::unordered_map<std::uint64_t, Block> blocks_;
};

/// The key of a voxel in a hash set (16 bits an axis: keys repeat every 65,536 voxels).
std::uint64_t voxelKey(const Eigen::Vector3i& voxel);

/// Where the maps are asked: at most `max_rays` rays sampled evenly over the input, and points
/// far from every ray.
struct SamplePoints {
  std::size_t sampled_rays = 0;
  std::vector<Eigen::Vector3d> endpoints;   ///< each sampled ray's end (truncated to max_range)
  std::vector<Eigen::Vector3d> along_rays;  ///< at 10, 30, 50, 70 and 90 % of each sampled ray
  /// Random points of the data's bounding box grown by kFarMargin, more than kFarDistance from
  /// every ray (none of their 1 m voxels and their neighbours is crossed by a ray): nothing
  /// was seen there.
  std::vector<Eigen::Vector3d> far_from_data;
};
SamplePoints samplePoints(const InputData& input, const RunOptions& options, std::size_t max_rays);

/// How many of some points a map calls unknown, free and occupied (index: mvog::OccupancyState).
struct StateCounts {
  std::array<std::size_t, 3> counts{};
  void add(mvog::OccupancyState state) { ++counts[static_cast<std::size_t>(state)]; }
  std::size_t points() const { return counts[0] + counts[1] + counts[2]; }
  /// Percentage of the points in `state` (NaN without points).
  double percent(mvog::OccupancyState state) const;
};

/// What a map says at the sample points (MVOG: occupancy().state(threshold); OctoMap: search(),
/// null = unknown, else isNodeOccupied()).
struct Quality {
  StateCounts endpoints;      ///< an obstacle was certainly there: occupied is right
  StateCounts along_rays;     ///< the ray passed: free is right
  StateCounts far_from_data;  ///< nothing was seen: unknown is right
};
/// The states a map whose state at p is `state_of(p)` gives at `points`.
template <class StateOf>
StateCounts statesAt(const std::vector<Eigen::Vector3d>& points, const StateOf& state_of) {
  StateCounts counts;
  for (const Eigen::Vector3d& p : points) counts.add(state_of(p));
  return counts;
}
/// The quality of a map whose state at p is `state_of(p)`.
template <class StateOf>
Quality qualityOf(const SamplePoints& points, StateOf&& state_of) {
  return {statesAt(points.endpoints, state_of), statesAt(points.along_rays, state_of),
          statesAt(points.far_from_data, state_of)};
}
Quality mvogQuality(const mvog::Map& map, double occupancy_threshold, const SamplePoints& points);
/// OctoMap's state at `point`: search(), null = unknown, else isNodeOccupied().
mvog::OccupancyState octomapState(const octomap::OcTree& tree, const Eigen::Vector3d& point);
Quality octomapQuality(const octomap::OcTree& tree, const SamplePoints& points);

/// Occupied / free / unknown of both maps at the same points: counts[mvog][octomap].
struct StateAgreement {
  std::array<std::array<std::size_t, 3>, 3> counts{};

  std::size_t points() const;
  std::size_t agreeing() const;
};

struct Agreement {
  std::size_t sampled_rays = 0;
  StateAgreement endpoints;
  StateAgreement along_rays;
};

Agreement compareMaps(const SamplePoints& points, const mvog::Map& map, double occupancy_threshold,
                      const octomap::OcTree& tree);

/// MVOG's map against a map of the same rays with every reading's ray walked
/// (mvog::FreeSpaceRays): counts[map][every-reading map], at the sample points and within
/// kNearEndCells cells of the sampled ends (kNearEndPoints random points around each), where a
/// surface meets the free space in front of it.
constexpr double kNearEndCells = 2.0;
constexpr std::size_t kNearEndPoints = 4;
struct EveryReadingAgreement {
  StateAgreement endpoints;
  StateAgreement along_rays;
  StateAgreement near_ends;
};
EveryReadingAgreement compareWithEveryReading(const SamplePoints& points, double resolution,
                                              double occupancy_threshold, const mvog::Map& map,
                                              const mvog::Map& every_reading);

}  // namespace mvog_bench
