#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>

#include <octomap/OcTree.h>

#include "input.h"
#include "mvog/map.h"

namespace mvog_bench {

/// How both backends map one input.
struct RunOptions {
  double resolution = 0.1;
  /// Hits further than this (m) are truncated to it and insert free space only, in both
  /// backends (OctoMap's insertPointCloud maxrange); infinity: no limit.
  double max_range = 0.0;
  int threads = 1;  ///< MVOG only; OctoMap's insertion is single-threaded
  /// MVOG only: InsertionConfig::clear_conflicting_free_space (Sec. V.B), the counterpart of
  /// OctoMap's insertPointCloud, where a scan's occupied voxels win over its free ones.
  bool clear_conflicting_free_space = false;
};

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

/// Occupied / free / unknown of both maps at the same points: counts[mvog][octomap], indexed
/// by mvog::OccupancyState (unknown, free, occupied).
struct StateAgreement {
  std::array<std::array<std::size_t, 3>, 3> counts{};

  std::size_t points() const;
  std::size_t agreeing() const;
};

struct Agreement {
  std::size_t sampled_rays = 0;
  StateAgreement endpoints;   ///< each sampled ray's end (truncated to max_range)
  StateAgreement along_rays;  ///< points at 10, 30, 50, 70 and 90 % of each sampled ray
};

/// Samples at most `max_rays` rays evenly over the input and compares the maps along them
/// (MVOG: occupancy().state(0.5); OctoMap: search(), null = unknown, else isNodeOccupied()).
Agreement compareMaps(const InputData& input, const RunOptions& options, const mvog::Map& map,
                      const octomap::OcTree& tree, std::size_t max_rays);

}  // namespace mvog_bench
