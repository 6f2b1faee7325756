#include "mvog/frontiers.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <unordered_map>

#include "column_runs.h"

namespace mvog {
namespace {

using detail::StateRun;

/// Voxels [bottom, top] (inclusive) of one column.
struct VoxelSpan {
  std::int32_t bottom;
  std::int32_t top;
};

/// The voxels holding some height of (low, high), low < high (grid units).
VoxelSpan voxelsOver(double low, double high) {
  return {static_cast<std::int32_t>(std::floor(low)),
          static_cast<std::int32_t>(std::ceil(high)) - 1};
}

std::uint64_t cellKey(const CellIndex& cell) {
  return std::uint64_t{static_cast<std::uint32_t>(cell.x)} << 32 |
         static_cast<std::uint32_t>(cell.y);
}

/// Union-find over frontier runs, by index.
class Pieces {
 public:
  explicit Pieces(std::size_t count) : parent_(count) {
    std::iota(parent_.begin(), parent_.end(), std::uint32_t{0});
  }
  std::uint32_t find(std::uint32_t k) {
    while (parent_[k] != k) k = parent_[k] = parent_[parent_[k]];
    return k;
  }
  void join(std::uint32_t a, std::uint32_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent_[std::max(a, b)] = std::min(a, b);  // the root is a piece's first run
  }

 private:
  std::vector<std::uint32_t> parent_;
};

/// Buffers of the tiles of one update.
struct TileScratch {
  detail::RunsOfCells columns;  // the tile's and those of a border of one cell
  std::vector<VoxelSpan> spans;
};

/// The frontier runs of `tile`'s cells, cell by cell, each cell's from the lowest.
void computeTile(const Map& map, const TileIndex& tile, const PlanningConfig& config,
                 TileScratch& scratch, std::vector<FrontierRun>& runs) {
  const CellRange cells = Map::tileCells(tile);
  detail::RunsOfCells& columns = scratch.columns;
  columns.compute(map, {{cells.min.x - 1, cells.min.y - 1}, {cells.max.x + 1, cells.max.y + 1}},
                  config.occupancy_threshold);
  const double band_low = config.frontier_min_z / map.resolution();
  const double band_high = config.frontier_max_z / map.resolution();
  std::vector<VoxelSpan>& spans = scratch.spans;
  for (std::int32_t y = cells.min.y; y <= cells.max.y; ++y) {
    for (std::int32_t x = cells.min.x; x <= cells.max.x; ++x) {
      const std::vector<StateRun>& column = columns.at({x, y});
      spans.clear();
      for (std::size_t k = 0; k < column.size(); ++k) {
        const StateRun& run = column[k];
        if (run.state != OccupancyState::kFree) continue;
        const double low = std::max<double>(run.bottom, band_low);
        const double high = std::min<double>(run.top, band_high);
        if (low > high) continue;
        for (const CellIndex& beside :
             {CellIndex{x - 1, y}, CellIndex{x + 1, y}, CellIndex{x, y - 1}, CellIndex{x, y + 1}}) {
          for (const StateRun& other : columns.at(beside)) {
            if (other.known()) continue;
            const double from = std::max<double>(low, other.bottom);
            const double to = std::min<double>(high, other.top);
            if (from < to) spans.push_back(voxelsOver(from, to));
          }
        }
        // The runs of a column alternate in state: what lies above a free run is occupied or
        // unknown.
        if (k + 1 < column.size() && !column[k + 1].known() && run.top >= band_low &&
            run.top <= band_high) {
          const std::int32_t below_top = static_cast<std::int32_t>(std::ceil(run.top)) - 1;
          spans.push_back({below_top, below_top});
        }
        if (k > 0 && !column[k - 1].known() && run.bottom >= band_low && run.bottom <= band_high) {
          const auto above_bottom = static_cast<std::int32_t>(std::floor(run.bottom));
          spans.push_back({above_bottom, above_bottom});
        }
      }
      std::sort(spans.begin(), spans.end(),
                [](const VoxelSpan& a, const VoxelSpan& b) { return a.bottom < b.bottom; });
      for (const VoxelSpan& span : spans) {  // joined where they overlap or touch
        if (!runs.empty() && runs.back().cell == CellIndex{x, y} &&
            span.bottom <= runs.back().top + 1) {
          runs.back().top = std::max(runs.back().top, span.top);
        } else {
          runs.push_back({{x, y}, span.bottom, span.top});
        }
      }
    }
  }
}

}  // namespace

Frontiers::Frontiers(const PlanningConfig& config) : config_(config) { config_.validate(); }

void Frontiers::clear() {
  runs_.clear();
  points_.clear();
  num_clusters_ = 0;
}

void Frontiers::update(const Map& map) {
  TileScratch scratch;
  tiles_recomputed_ =
      runs_.update(map, true, [&](const TileIndex& tile, std::vector<FrontierRun>& runs) {
        computeTile(map, tile, config_, scratch, runs);
      });
  if (tiles_recomputed_ > 0) cluster(map.resolution());
}

void Frontiers::cluster(double resolution) {
  const std::vector<FrontierRun> runs = runs_.all();
  // The runs of a cell are consecutive: index them by cell.
  std::unordered_map<std::uint64_t, std::pair<std::uint32_t, std::uint32_t>> by_cell;
  by_cell.reserve(runs.size());
  for (std::uint32_t k = 0; k < runs.size(); ++k) {
    auto [it, inserted] = by_cell.try_emplace(cellKey(runs[k].cell), k, k + 1);
    if (!inserted) it->second.second = k + 1;
  }
  Pieces pieces(runs.size());
  for (std::uint32_t k = 0; k < runs.size(); ++k) {
    const FrontierRun& run = runs[k];
    // Half of the 26-neighbourhood across columns (the other half finds this run); two runs of
    // one column never touch (they were joined).
    for (const CellIndex& other :
         {CellIndex{run.cell.x + 1, run.cell.y}, CellIndex{run.cell.x - 1, run.cell.y + 1},
          CellIndex{run.cell.x, run.cell.y + 1}, CellIndex{run.cell.x + 1, run.cell.y + 1}}) {
      const auto it = by_cell.find(cellKey(other));
      if (it == by_cell.end()) continue;
      for (std::uint32_t j = it->second.first; j < it->second.second; ++j) {
        if (runs[j].bottom <= run.top + 1 && run.bottom <= runs[j].top + 1) pieces.join(k, j);
      }
    }
  }
  std::vector<std::int64_t> voxels(runs.size(), 0);  // by root
  for (std::uint32_t k = 0; k < runs.size(); ++k) {
    voxels[pieces.find(k)] += std::int64_t{runs[k].top} - runs[k].bottom + 1;
  }
  constexpr std::uint32_t kDropped = ~std::uint32_t{0};
  std::vector<std::uint32_t> cluster_of_root(runs.size(), kDropped);
  num_clusters_ = 0;
  points_.clear();
  for (std::uint32_t k = 0; k < runs.size(); ++k) {
    const std::uint32_t root = pieces.find(k);
    if (voxels[root] < config_.frontier_min_cells) continue;
    if (root == k) cluster_of_root[k] = num_clusters_++;  // a root is its piece's first run
    const FrontierRun& run = runs[k];
    for (std::int32_t z = run.bottom; z <= run.top; ++z) {
      points_.push_back({static_cast<float>((run.cell.x + 0.5) * resolution),
                         static_cast<float>((run.cell.y + 0.5) * resolution),
                         static_cast<float>((z + 0.5) * resolution), cluster_of_root[root]});
    }
  }
}

}  // namespace mvog
