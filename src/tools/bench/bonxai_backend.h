#pragma once
// Bonxai (github.com/facontidavide/Bonxai, MPL-2.0), a peer for side-by-side benchmarks only:
// CMakeLists.txt compiles it into mvog_bench from MVOG_PEERS_DIR when its sources are there
// (MVOG_BENCH_HAVE_BONXAI); it is never part of the product, its tests or CI, and never copied
// into this repository. This header does not include Bonxai's.

#include <cstddef>
#include <memory>

#include "backends.h"
#include "input.h"

namespace Bonxai {
class ProbabilisticMap;
}

namespace mvog_bench {

#ifdef MVOG_BENCH_HAVE_BONXAI
constexpr bool kBonxaiBuilt = true;
#else
constexpr bool kBonxaiBuilt = false;
#endif

/// Why there is no Bonxai backend when kBonxaiBuilt is false: where CMake looked for it.
constexpr const char* kBonxaiMissing =
    "mvog_bench was built without Bonxai: CMake found no Bonxai sources at " MVOG_BENCH_BONXAI_DIR
    " (MVOG_PEERS_DIR; configure with -DMVOG_PEERS_DIR=DIR, DIR holding bonxai/, to build its "
    "backend)";

struct BonxaiStats {
  double insert_seconds = 0.0;
  /// VoxelGrid::memUsage(), Bonxai's own count: the leaf blocks' pool in whole chunks (512 blocks
  /// of 8^3 cells of 4 bytes, used or not), the inner grids and every mask, the root hash map's
  /// entries and one byte per bucket; not what the hash map and the shared pointers allocate
  /// beside, nor the allocator's bookkeeping.
  std::size_t memory_bytes = 0;
  std::size_t active_cells = 0;  ///< VoxelGrid::activeCellsCount(): the voxels with a value
};

struct BonxaiRun {
  /// Shared: Bonxai's type stays incomplete outside bonxai_backend.cpp.
  std::shared_ptr<const Bonxai::ProbabilisticMap> map;
  BonxaiStats stats;
};

/// Inserts every scan with ProbabilisticMap::insertPointCloud(hits, origin, max_range), one
/// thread, with OctoMap's rays (runOctomap: the same hits, the origin in single precision, hits
/// beyond max_range truncated to free space); only the insertion is timed. Defined only when
/// kBonxaiBuilt.
BonxaiRun runBonxai(const InputData& input, const RunOptions& options);

/// The state of the voxel holding `point`: isOccupied, isFree, else unknown (no cell, or
/// log-odds exactly at Bonxai's threshold, 0.5). Defined only when kBonxaiBuilt.
mvog::OccupancyState bonxaiState(const Bonxai::ProbabilisticMap& map, const Eigen::Vector3d& point);

/// bonxaiState at each point. Defined only when kBonxaiBuilt.
Quality bonxaiQuality(const Bonxai::ProbabilisticMap& map, const SamplePoints& points);

}  // namespace mvog_bench
