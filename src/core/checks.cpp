// Segment and box checks (mvog/checks.h): each column's runs of one state intersected with the
// heights the query spans over that column.
#include "mvog/checks.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <optional>
#include <string>

#include "block_summaries.h"
#include "capsule.h"
#include "column_runs.h"
#include "mvog/raster.h"

namespace mvog {
namespace {

using Blocks = detail::BlockSummaries;
using detail::AlignedBox;
using detail::Extent;
using detail::StateRun;
using detail::worse;

constexpr double kInf = std::numeric_limits<double>::infinity();

std::array<const Eigen::Vector3d*, 2> pointsOf(const Segment& segment) {
  return {&segment.start, &segment.end};
}
std::array<const Eigen::Vector3d*, 2> pointsOf(const Box& box) { return {&box.min, &box.max}; }

/// Validates `config` and each query, and adds up the cells the queries visit (prepare(query)
/// returns a query's). Refuses, before any work, a query with a point that is not finite or lies
/// beyond the map's max_coordinate (beyond it nothing can be known, and cell indices would
/// overflow), and more cells in all than max_query_cells.
template <class Query, class Prepare>
void requireQueries(const Map& map, const PlanningConfig& config, const std::vector<Query>& queries,
                    const char* what, Prepare&& prepare) {
  config.validate();
  std::int64_t cells = 0;
  for (std::size_t k = 0; k < queries.size(); ++k) {
    for (const Eigen::Vector3d* point : pointsOf(queries[k])) {
      if (!map.config().withinBounds(*point)) {
        throw ConfigError(std::string(what) + " " + std::to_string(k) +
                          ": a point is not finite or lies beyond the map's max_coordinate");
      }
    }
    cells += prepare(queries[k]);
    if (cells > config.max_query_cells) {
      throw ConfigError("max_query_cells: the queries cover " + std::to_string(cells) +
                        " cells, more than " + std::to_string(config.max_query_cells));
    }
  }
}

/// floor(grid_coordinate), |grid_coordinate| < 2^31, without a library call (the build targets
/// no particular x86 level, where std::floor is one: it counted for a tenth of a check).
std::int32_t floorCell(double grid_coordinate) {
  const auto truncated = static_cast<std::int32_t>(grid_coordinate);
  return truncated - (grid_coordinate < truncated ? 1 : 0);
}

/// Cells [first, last] of row y, over which a segment passes within its radius along y for t in
/// `t`.
struct Row {
  std::int32_t y;
  std::int32_t first;
  std::int32_t last;
  Extent t;
};

/// What the checks of one call share.
struct CheckContext {
  const Map& map;
  const double threshold;
  detail::BlockSummaries& blocks;
  detail::ColumnScratch scratch;
  std::vector<Row> rows;
};

/// One segment in grid units, checked cell by cell.
class SegmentWalk {
 public:
  SegmentWalk(CheckContext& context, const Segment& segment, double radius)
      : context_(context),
        start_(segment.start / context.map.resolution()),
        delta_((segment.end - segment.start) / context.map.resolution()),
        inverse_delta_(delta_.cwiseInverse()),
        radius_(radius / context.map.resolution()),
        length_((segment.end - segment.start).norm()) {}

  /// The cells the check visits at most.
  std::int64_t cells() const {
    if (radius_ == 0.0) {
      const CellIndex a = cellAt(start_.x(), start_.y());
      const CellIndex b = cellAt(start_.x() + delta_.x(), start_.y() + delta_.y());
      return std::abs(std::int64_t{b.x} - a.x) + std::abs(std::int64_t{b.y} - a.y) + 1;
    }
    std::int64_t count = 0;
    forEachRow([&](const Row& row) { count += std::int64_t{row.last} - row.first + 1; });
    return count;
  }

  SegmentCheck check() {
    if (radius_ == 0.0) {
      walkRay(start_.x(), start_.y(), start_.z(), start_.x() + delta_.x(), start_.y() + delta_.y(),
              start_.z() + delta_.z(),
              [&](const CellIndex& cell, double z_enter, double z_exit, bool) {
                visitCrossedCell(cell, z_enter, z_exit);
              });
    } else {
      visitSweptBlocks();
    }
    SegmentCheck result;
    result.state = state_;
    if (state_ != OccupancyState::kFree) result.blocked_at = blocked_t_ * length_;
    return result;
  }

 private:
  /// Calls visit(Row) for each row of cells over which some point within the radius may lie, in
  /// the order the segment meets them: the cells over which the segment passes within the radius
  /// along x and along y (a superset of the capsule's footprint, refined per cell).
  template <class Visit>
  void forEachRow(Visit&& visit) const {
    const double y0 = std::min(start_.y(), start_.y() + delta_.y()) - radius_;
    const double y1 = std::max(start_.y(), start_.y() + delta_.y()) + radius_;
    const std::int32_t low = floorCell(y0);
    const std::int32_t high = floorCell(y1);
    const bool forward = delta_.y() >= 0.0;
    for (std::int32_t k = 0; k <= high - low; ++k) {
      const std::int32_t y = forward ? low + k : high - k;
      const std::optional<Extent> t = slab(1, y - radius_, y + 1 + radius_);
      if (!t) continue;
      const double x_a = start_.x() + t->min * delta_.x();
      const double x_b = start_.x() + t->max * delta_.x();
      visit(Row{y, floorCell(std::min(x_a, x_b) - radius_), floorCell(std::max(x_a, x_b) + radius_),
                *t});
    }
  }

  /// The range of t in [0, 1] over which the segment lies within [low, high] along `axis`.
  std::optional<Extent> slab(int axis, double low, double high) const {
    if (delta_[axis] == 0.0) {
      if (start_[axis] < low || start_[axis] > high) return std::nullopt;
      return Extent{0.0, 1.0};
    }
    double t_low = (low - start_[axis]) * inverse_delta_[axis];
    double t_high = (high - start_[axis]) * inverse_delta_[axis];
    if (t_low > t_high) std::swap(t_low, t_high);
    t_low = std::max(t_low, 0.0);
    t_high = std::min(t_high, 1.0);
    if (t_low > t_high) return std::nullopt;
    return Extent{t_low, t_high};
  }

  /// The range of t over which the segment passes within the radius of the rectangle of cells
  /// [x0, x1) x [y0, y1), along x and along y; nothing if it never does.
  std::optional<Extent> nearRectangle(double x0, double x1, double y0, double y1) const {
    const std::optional<Extent> along_x = slab(0, x0 - radius_, x1 + radius_);
    const std::optional<Extent> along_y = slab(1, y0 - radius_, y1 + radius_);
    if (!along_x || !along_y) return std::nullopt;
    const Extent t{std::max(along_x->min, along_y->min), std::min(along_x->max, along_y->max)};
    if (t.min > t.max) return std::nullopt;
    return t;
  }

  /// The heights the sphere spans for t in `t` (a superset of those it spans over any cell it
  /// passes over then).
  Extent sweptHeights(const Extent& t) const {
    const double z_a = start_.z() + t.min * delta_.z();
    const double z_b = start_.z() + t.max * delta_.z();
    return {std::min(z_a, z_b) - radius_, std::max(z_a, z_b) + radius_};
  }

  /// Radius 0: the segment crosses the column from height z_enter to z_exit (walkRay's order is
  /// the segment's, so the first blocked cell holds the first blocked point).
  void visitCrossedCell(const CellIndex& cell, double z_enter, double z_exit) {
    if (state_ == OccupancyState::kOccupied) return;  // nothing left to learn
    const double low = std::min(z_enter, z_exit);
    const double high = std::max(z_enter, z_exit);
    const std::int32_t block_x = cell.x >> Blocks::kBlockLog2;
    const std::int32_t block_y = cell.y >> Blocks::kBlockLog2;
    if (context_.blocks.cellFreeOver(cell, low, high)) return;
    // Once unknown space was met, the first blocked point is known: only an occupied one matters.
    if (state_ == OccupancyState::kUnknown &&
        !context_.blocks.mayBeOccupiedOver(block_x, block_y, low, high)) {
      return;
    }
    const OccupancyState state = detail::stateOver(context_.map.column(cell), low, high,
                                                   context_.threshold, context_.scratch);
    if (state == OccupancyState::kFree) return;
    if (state_ == OccupancyState::kFree) blocked_t_ = firstBlockedInCell(cell, z_enter, z_exit);
    state_ = worse(state_, state);
  }

  /// Where the segment first meets a run that is not free in `cell`, whose runs are in the
  /// context's scratch.
  double firstBlockedInCell(const CellIndex& cell, double z_enter, double z_exit) const {
    const bool upwards = z_exit >= z_enter;
    const double low = std::min(z_enter, z_exit);
    const double high = std::max(z_enter, z_exit);
    double z_first = upwards ? kInf : -kInf;
    for (const StateRun& run : context_.scratch.runs) {
      if (run.state == OccupancyState::kFree || !run.meets(low, high)) continue;
      z_first = upwards ? std::min<double>(z_first, std::max<double>(z_enter, run.bottom))
                        : std::max<double>(z_first, std::min<double>(z_enter, run.top));
    }
    // The t at which the segment enters the cell: the later of its entries along x and y.
    double t_enter = 0.0;
    for (int axis = 0; axis < 2; ++axis) {
      if (delta_[axis] == 0.0) continue;
      const double wall = (axis == 0 ? cell.x : cell.y) + (delta_[axis] > 0.0 ? 0.0 : 1.0);
      t_enter = std::max(t_enter, (wall - start_[axis]) / delta_[axis]);
    }
    if (z_first == z_enter) return t_enter;
    return std::clamp((z_first - start_.z()) / delta_.z(), t_enter, 1.0);
  }

  /// Radius > 0: the footprint's rows, block by block of FreeBlocks, in the order the segment
  /// meets them; a block free over the heights the sphere spans near it is passed whole.
  void visitSweptBlocks() {
    const detail::Capsule capsule(start_, start_ + delta_, radius_);
    std::vector<Row>& rows = context_.rows;
    rows.clear();
    forEachRow([&](const Row& row) { rows.push_back(row); });
    const bool forward = delta_.x() >= 0.0;
    for (std::size_t begin = 0; begin < rows.size();) {
      const std::int32_t block_y = rows[begin].y >> Blocks::kBlockLog2;
      std::size_t end = begin;
      std::int32_t first = rows[begin].first;
      std::int32_t last = rows[begin].last;
      for (; end < rows.size() && rows[end].y >> Blocks::kBlockLog2 == block_y; ++end) {
        first = std::min(first, rows[end].first);
        last = std::max(last, rows[end].last);
      }
      const std::int32_t low = first >> Blocks::kBlockLog2;
      const std::int32_t high = last >> Blocks::kBlockLog2;
      for (std::int32_t k = 0; k <= high - low; ++k) {
        const std::int32_t block_x = forward ? low + k : high - k;
        const std::int32_t x0 = block_x * Blocks::kBlockSize;
        const std::int32_t y0 = block_y * Blocks::kBlockSize;
        const std::optional<Extent> t =
            nearRectangle(x0, x0 + Blocks::kBlockSize, y0, y0 + Blocks::kBlockSize);
        if (!t) continue;
        const bool could_block_earlier = t->min < blocked_t_;
        if (state_ == OccupancyState::kOccupied && !could_block_earlier) continue;
        const Extent heights = sweptHeights(*t);
        if (context_.blocks.freeOver(block_x, block_y, heights.min, heights.max)) continue;
        if (!could_block_earlier &&
            !context_.blocks.mayBeOccupiedOver(block_x, block_y, heights.min, heights.max)) {
          continue;  // only an occupied point could tell more
        }
        for (std::size_t r = begin; r < end; ++r) {
          const std::int32_t from = std::max(rows[r].first, x0);
          const std::int32_t to = std::min(rows[r].last, x0 + Blocks::kBlockSize - 1);
          for (std::int32_t j = 0; j <= to - from; ++j) {
            visitSweptCell(capsule, {forward ? from + j : to - j, rows[r].y});
          }
        }
      }
      begin = end;
    }
  }

  /// Radius > 0: a cell the segment may pass over within the radius.
  void visitSweptCell(const detail::Capsule& capsule, const CellIndex& cell) {
    const std::optional<Extent> t = nearRectangle(cell.x, cell.x + 1, cell.y, cell.y + 1);
    if (!t) return;
    // What the cell may still tell: an earlier blocked point, or an occupied one.
    const bool could_block_earlier = t->min < blocked_t_;
    if (state_ == OccupancyState::kOccupied && !could_block_earlier) return;
    // First with the heights the sphere spans while near the cell (a superset), then, unless that
    // tells nothing, with the heights the capsule spans over the cell itself.
    const Extent near = sweptHeights(*t);
    if (context_.blocks.cellFreeOver(cell, near.min, near.max)) return;
    const OccupancyState near_state = detail::stateOver(
        context_.map.column(cell), near.min, near.max, context_.threshold, context_.scratch);
    if (near_state == OccupancyState::kFree) return;
    if (!could_block_earlier && near_state != OccupancyState::kOccupied) return;
    // Each stretch that is not free within those heights, exactly: where the sphere first meets
    // the box it fills over the cell, if ever (for unknown space, the box's faces included).
    for (const StateRun& run : context_.scratch.runs) {  // filled: near_state is not free
      if (run.state == OccupancyState::kFree || !run.meets(near.min, near.max)) continue;
      if (!could_block_earlier && run.state != OccupancyState::kOccupied) continue;
      const AlignedBox box{{double(cell.x), double(cell.y), run.bottom},
                           {cell.x + 1.0, cell.y + 1.0, run.top}};
      const std::optional<double> contact = capsule.firstContact(box);
      if (!contact) continue;
      state_ = worse(state_, run.state);
      blocked_t_ = std::min(blocked_t_, *contact);
    }
  }

  CheckContext& context_;
  const Eigen::Vector3d start_;  // grid units
  const Eigen::Vector3d delta_;  // end - start, grid units
  const Eigen::Vector3d inverse_delta_;
  const double radius_;  // grid units
  const double length_;  // m
  OccupancyState state_ = OccupancyState::kFree;
  double blocked_t_ = kInf;  // t of the first point met that is not free
};

}  // namespace

SegmentChecker::SegmentChecker(const PlanningConfig& config)
    : config_(config),
      blocks_(std::make_unique<detail::BlockSummaries>(config.occupancy_threshold)) {
  config_.validate();
}

SegmentChecker::~SegmentChecker() = default;
SegmentChecker::SegmentChecker(SegmentChecker&&) noexcept = default;
SegmentChecker& SegmentChecker::operator=(SegmentChecker&&) noexcept = default;

void SegmentChecker::clear() { blocks_->clear(); }

std::vector<SegmentCheck> SegmentChecker::check(const Map& map,
                                                const std::vector<Segment>& segments,
                                                double radius) {
  // At most max_coordinate, as the segments' points: the swept rows' cell indices then stay
  // within 2 * 4194304 (MapConfig::validate), far from int32's limit, and no request covers more
  // than that many rows to count.
  if (!(std::isfinite(radius) && radius >= 0.0 && radius <= map.config().max_coordinate)) {
    throw ConfigError("radius: must be a finite number >= 0 and at most the map's max_coordinate");
  }
  blocks_->follow(map);
  CheckContext context{map, config_.occupancy_threshold, *blocks_, {}, {}};
  std::vector<SegmentWalk> walks;
  walks.reserve(segments.size());
  requireQueries(map, config_, segments, "segment", [&](const Segment& segment) {
    walks.emplace_back(context, segment, radius);
    return walks.back().cells();
  });
  std::vector<SegmentCheck> results;
  results.reserve(segments.size());
  for (SegmentWalk& walk : walks) results.push_back(walk.check());
  return results;
}

std::vector<SegmentCheck> checkSegments(const Map& map, const std::vector<Segment>& segments,
                                        double radius, const PlanningConfig& config) {
  return SegmentChecker(config).check(map, segments, radius);
}

std::vector<BoxCheck> checkBoxes(const Map& map, const std::vector<Box>& boxes,
                                 const PlanningConfig& config) {
  std::vector<CellRange> footprints;
  footprints.reserve(boxes.size());
  requireQueries(map, config, boxes, "box", [&](const Box& box) {
    if ((box.min.array() > box.max.array()).any()) {
      throw ConfigError("box " + std::to_string(footprints.size()) +
                        ": min lies above max along an axis");
    }
    footprints.push_back(map.cellsInRectangle(box.min.x(), box.min.y(), box.max.x(), box.max.y()));
    return footprints.back().width() * footprints.back().height();
  });
  detail::ColumnScratch scratch;
  std::vector<BoxCheck> results;
  results.reserve(boxes.size());
  for (std::size_t k = 0; k < boxes.size(); ++k) {
    const Eigen::Vector3d min = boxes[k].min / map.resolution();
    const Eigen::Vector3d max = boxes[k].max / map.resolution();
    const double box_volume = (max - min).prod();
    OccupancyState state = OccupancyState::kFree;
    double known_volume = 0.0;
    float max_probability = -1.0f;
    const CellRange& footprint = footprints[k];
    for (std::int32_t y = footprint.min.y; y <= footprint.max.y; ++y) {
      for (std::int32_t x = footprint.min.x; x <= footprint.max.x; ++x) {
        // The box's corners belong to it: a cell it only touches counts for the state.
        const double area = (std::min(max.x(), x + 1.0) - std::max(min.x(), double(x))) *
                            (std::min(max.y(), y + 1.0) - std::max(min.y(), double(y)));
        detail::stateRuns(map.column({x, y}), config.occupancy_threshold, scratch);
        state = worse(state, detail::stateOver(scratch.runs, min.z(), max.z()));
        for (const ColumnSegment& segment : scratch.profile) {
          if (segment.bottom > max.z() || segment.top < min.z()) continue;
          max_probability = std::max(max_probability, segment.probability);
          known_volume += area * (std::min<double>(max.z(), segment.top) -
                                  std::max<double>(min.z(), segment.bottom));
        }
      }
    }
    BoxCheck result;
    result.state = state;
    result.known_fraction =
        box_volume > 0.0 ? known_volume / box_volume : std::numeric_limits<double>::quiet_NaN();
    if (max_probability >= 0.0f) result.max_probability = max_probability;
    results.push_back(result);
  }
  return results;
}

}  // namespace mvog
