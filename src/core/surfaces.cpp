#include "mvog/surfaces.h"

#include <algorithm>
#include <cmath>

#include "column_runs.h"

namespace mvog {
namespace {

using detail::StateRun;

/// A surface in grid units.
struct Top {
  float z;
  float clearance;
  bool capped;
  float probability;
};

/// Calls visit(Top) for each top of occupied space of a column, from the lowest.
template <class Visit>
void forEachTop(const std::vector<StateRun>& runs, Visit&& visit) {
  // Runs alternate in state and the highest is unknown: an occupied run has a run above it, and
  // a free run above it has one more.
  for (std::size_t k = 0; k + 1 < runs.size(); ++k) {
    if (runs[k].state != OccupancyState::kOccupied) continue;
    const StateRun& above = runs[k + 1];
    const bool free_above = above.state == OccupancyState::kFree;
    visit(Top{runs[k].top, free_above ? above.top - above.bottom : 0.0f,
              free_above && runs[k + 2].state == OccupancyState::kOccupied,
              runs[k].top_probability});
  }
}

}  // namespace

Surfaces::Surfaces(const PlanningConfig& config) : config_(config) { config_.validate(); }

void Surfaces::clear() {
  by_tile_.clear();
  surfaces_.clear();
}

void Surfaces::update(const Map& map) {
  const auto resolution = static_cast<float>(map.resolution());
  detail::RunsOfCells columns;
  tiles_recomputed_ =
      by_tile_.update(map, false, [&](const TileIndex& tile, std::vector<Surface>& surfaces) {
        const CellRange cells = Map::tileCells(tile);
        columns.compute(map, cells, config_.occupancy_threshold);
        for (std::int32_t y = cells.min.y; y <= cells.max.y; ++y) {
          for (std::int32_t x = cells.min.x; x <= cells.max.x; ++x) {
            forEachTop(columns.at({x, y}), [&](const Top& top) {
              surfaces.push_back({static_cast<float>((x + 0.5) * map.resolution()),
                                  static_cast<float>((y + 0.5) * map.resolution()),
                                  top.z * resolution, top.clearance * resolution, top.capped,
                                  top.probability});
            });
          }
        }
      });
  if (tiles_recomputed_ > 0) surfaces_ = by_tile_.all();
}

TraversableMap traversableMap(const Map& map, const CellRange& cells,
                              const PlanningConfig& config) {
  config.validate();
  if (cells.empty()) throw ConfigError("cells: the range is empty");
  if (cells.width() * cells.height() > (std::int64_t{1} << 28)) {
    throw ConfigError("cells: the range exceeds 2^28 cells");
  }
  const double s = 1.0 / map.resolution();
  const double band_low = config.traversable_min_z * s;
  const double band_high = config.traversable_max_z * s;
  const double robot_height = config.robot_height * s;
  const double max_step = config.max_step * s;

  // The tops within the band and the band's state, for the cells and a border of one cell.
  const CellRange around{{cells.min.x - 1, cells.min.y - 1}, {cells.max.x + 1, cells.max.y + 1}};
  const auto around_width = static_cast<std::size_t>(around.width());
  detail::RunsOfCells columns;
  columns.compute(map, around, config.occupancy_threshold);
  std::vector<std::vector<Top>> tops(around_width * static_cast<std::size_t>(around.height()));
  std::vector<OccupancyState> band_states(tops.size());
  auto index = [&](std::int32_t x, std::int32_t y) {
    return static_cast<std::size_t>(y - around.min.y) * around_width +
           static_cast<std::size_t>(x - around.min.x);
  };
  for (std::int32_t y = around.min.y; y <= around.max.y; ++y) {
    for (std::int32_t x = around.min.x; x <= around.max.x; ++x) {
      const std::vector<StateRun>& runs = columns.at({x, y});
      band_states[index(x, y)] = detail::stateOver(runs, band_low, band_high);
      forEachTop(runs, [&](const Top& top) {
        if (top.z >= band_low && top.z <= band_high) tops[index(x, y)].push_back(top);
      });
    }
  }

  TraversableMap grid;
  grid.resolution = map.resolution();
  grid.cells = cells;
  grid.values.reserve(static_cast<std::size_t>(cells.width() * cells.height()));
  for (std::int32_t y = cells.min.y; y <= cells.max.y; ++y) {
    for (std::int32_t x = cells.min.x; x <= cells.max.x; ++x) {
      // Every neighbour holding a top in the band holds one within a step of `top`.
      auto steps_fit = [&](const Top& top) {
        for (const std::size_t n :
             {index(x - 1, y), index(x + 1, y), index(x, y - 1), index(x, y + 1)}) {
          if (!tops[n].empty() && std::none_of(tops[n].begin(), tops[n].end(), [&](const Top& t) {
                return std::abs(double{t.z} - top.z) <= max_step;
              })) {
            return false;
          }
        }
        return true;
      };
      const std::vector<Top>& here = tops[index(x, y)];
      bool traversable = false;
      bool blocked = false;
      for (const Top& top : here) {
        if (top.clearance >= robot_height) {
          if (steps_fit(top)) traversable = true;
          blocked = true;  // unless another top fits
        } else if (top.capped) {
          blocked = true;
        }
      }
      // Without a top in the band: occupied somewhere in it (the worst state over it, even where
      // some of it is unknown), or free throughout.
      if (here.empty() && band_states[index(x, y)] != OccupancyState::kUnknown) blocked = true;
      grid.values.push_back(traversable ? Traversability::kTraversable
                            : blocked   ? Traversability::kBlocked
                                        : Traversability::kUnknown);
    }
  }
  return grid;
}

}  // namespace mvog
