#include "mvog/planning_config.h"

#include <cmath>
#include <string>

#include "config_checks.h"

namespace mvog {
namespace {

using detail::require;

/// A band [min, max] of heights: not NaN, min <= max, infinite bounds allowed.
void requireBand(double min, double max, const char* min_field) {
  require(!std::isnan(min) && !std::isnan(max) && min <= max, min_field,
          "must not be NaN nor above the band's max_z");
}

}  // namespace

void PlanningConfig::validate() const {
  require(occupancy_threshold >= 0.0 && occupancy_threshold < 1.0, "occupancy_threshold",
          "must be in [0, 1)");
  require(max_query_cells >= 1, "max_query_cells", "must be >= 1");
  requireBand(frontier_min_z, frontier_max_z, "frontier_min_z");
  require(frontier_min_cells >= 1, "frontier_min_cells", "must be >= 1");
  require(std::isfinite(robot_height) && robot_height > 0.0, "robot_height",
          "must be a finite number > 0");
  require(std::isfinite(max_step) && max_step >= 0.0, "max_step", "must be a finite number >= 0");
  requireBand(traversable_min_z, traversable_max_z, "traversable_min_z");
}

}  // namespace mvog
