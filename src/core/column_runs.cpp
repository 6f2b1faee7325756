#include "column_runs.h"

#include <algorithm>
#include <limits>

namespace mvog {
namespace detail {

void stateRuns(const std::vector<ColumnSegment>& profile, double threshold,
               std::vector<StateRun>& runs) {
  constexpr float kInf = std::numeric_limits<float>::infinity();
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  runs.clear();
  float known_to = -kInf;  // top of the known part so far
  for (const ColumnSegment& segment : profile) {
    if (segment.bottom > known_to) {
      runs.push_back({known_to, segment.bottom, OccupancyState::kUnknown, kNaN});
    }
    const OccupancyState state =
        segment.probability > threshold ? OccupancyState::kOccupied : OccupancyState::kFree;
    if (runs.back().state == state && runs.back().top == segment.bottom) {
      runs.back().top = segment.top;
      runs.back().top_probability = segment.probability;
    } else {
      runs.push_back({segment.bottom, segment.top, state, segment.probability});
    }
    known_to = segment.top;
  }
  runs.push_back({known_to, kInf, OccupancyState::kUnknown, kNaN});
}

void stateRuns(const ColumnView& column, double threshold, ColumnScratch& scratch) {
  columnProfile(column, scratch.profile);
  stateRuns(scratch.profile, threshold, scratch.runs);
}

OccupancyState stateOver(const std::vector<StateRun>& runs, double low, double high) {
  OccupancyState state = OccupancyState::kFree;
  for (const StateRun& run : runs) {
    if (run.bottom > high) break;
    if (run.meets(low, high)) state = worse(state, run.state);
  }
  return state;
}

OccupancyState stateOver(const ColumnView& column, double low, double high, double threshold,
                         ColumnScratch& scratch) {
  const Volume* negative_end = column.negative + column.num_negative;
  const Volume* covering = std::partition_point(column.negative, negative_end,
                                                [low](const Volume& v) { return v.top < low; });
  const Volume* positive_end = column.positive + column.num_positive;
  const Volume* meeting = std::partition_point(column.positive, positive_end,
                                               [low](const Volume& v) { return v.top < low; });
  if (covering != negative_end && covering->bottom <= low && covering->top >= high &&
      covering->mass > 0.0f && (meeting == positive_end || meeting->bottom > high)) {
    return OccupancyState::kFree;
  }
  stateRuns(column, threshold, scratch);
  return stateOver(scratch.runs, low, high);
}

void RunsOfCells::compute(const Map& map, const CellRange& cells, double threshold) {
  cells_ = cells;
  runs_.resize(static_cast<std::size_t>(cells.width() * cells.height()));
  std::size_t k = 0;
  for (std::int32_t y = cells.min.y; y <= cells.max.y; ++y) {
    for (std::int32_t x = cells.min.x; x <= cells.max.x; ++x) {
      columnProfile(map.column({x, y}), profile_);
      stateRuns(profile_, threshold, runs_[k++]);
    }
  }
}

}  // namespace detail
}  // namespace mvog
