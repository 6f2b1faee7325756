// A column's state along its height, from eq. (9) and a threshold (internal to the core).
#pragma once

#include <vector>

#include "mvog/column.h"
#include "mvog/grid2d.h"

namespace mvog {
namespace detail {

/// A maximal stretch of a column in one state. Heights in grid units. Known runs are closed,
/// [bottom, top] (volumes hold their faces); unknown runs are the open gaps between them, and
/// (-inf, lowest) and (highest, +inf).
struct StateRun {
  float bottom = 0.0f;
  float top = 0.0f;
  OccupancyState state = OccupancyState::kUnknown;
  float top_probability = 0.0f;  ///< p just below the run's top (NaN for unknown runs)

  bool known() const { return state != OccupancyState::kUnknown; }
  /// Whether some height of [low, high] lies in the run (closed or open as above).
  bool meets(double low, double high) const {
    return known() ? bottom <= high && top >= low : bottom < high && top > low;
  }
};

/// The runs of a column covering every height, bottom to top: occupied where p > threshold,
/// free where p <= threshold, unknown where no volume is. Two known runs of different states
/// touch (the height between them belongs to both: checks that ask whether a state is met are
/// conservative there). Into `runs` (cleared first).
void stateRuns(const std::vector<ColumnSegment>& profile, double threshold,
               std::vector<StateRun>& runs);

/// Buffers for the runs of one column after another.
struct ColumnScratch {
  std::vector<ColumnSegment> profile;
  std::vector<StateRun> runs;
};

/// The runs of a column as stored, into scratch.runs.
void stateRuns(const ColumnView& column, double threshold, ColumnScratch& scratch);

/// How much a state stops a robot: free, then unknown, then occupied.
inline int severity(OccupancyState state) {
  return state == OccupancyState::kFree ? 0 : state == OccupancyState::kUnknown ? 1 : 2;
}
inline OccupancyState worse(OccupancyState a, OccupancyState b) {
  return severity(a) >= severity(b) ? a : b;
}

/// The worst state of the runs over the heights [low, high].
OccupancyState stateOver(const std::vector<StateRun>& runs, double low, double high);

/// The worst state a column takes over the heights [low, high]. Where that is not kFree,
/// scratch.runs holds the column's runs. A range that one negative volume covers and no positive
/// volume meets is found free without them (most of the cells of a check in open space).
OccupancyState stateOver(const ColumnView& column, double low, double high, double threshold,
                         ColumnScratch& scratch);

/// The runs of every column of a rectangle of cells, each computed once, for results that look at
/// a cell's neighbours.
class RunsOfCells {
 public:
  /// Computes the runs of every column of `cells` (its buffers are kept from call to call).
  void compute(const Map& map, const CellRange& cells, double threshold);
  /// The runs of a cell of the rectangle.
  const std::vector<StateRun>& at(const CellIndex& cell) const {
    return runs_[static_cast<std::size_t>(cell.y - cells_.min.y) *
                     static_cast<std::size_t>(cells_.width()) +
                 static_cast<std::size_t>(cell.x - cells_.min.x)];
  }

 private:
  CellRange cells_ = kNoCells;
  std::vector<std::vector<StateRun>> runs_;
  std::vector<ColumnSegment> profile_;
};

}  // namespace detail
}  // namespace mvog
