#include "mvog/config.h"

#include <cmath>
#include <string>

#include "config_checks.h"

namespace mvog {

using detail::require;

void MapConfig::validate() const {
  require(std::isfinite(resolution) && resolution > 0.0, "resolution",
          "must be a finite number > 0");
  require(std::isfinite(max_coordinate) && max_coordinate > 0.0, "max_coordinate",
          "must be a finite number > 0");
  // Heights are floats in grid units: keep them below 2^22 so that they resolve a quarter cell.
  require(max_coordinate / resolution <= 4194304.0, "max_coordinate",
          "must be at most 4194304 cells (max_coordinate / resolution)");
  require(!std::isnan(rules.out_of_range_free_length) && rules.out_of_range_free_length > 0.0,
          "out_of_range_free_length", "must be > 0 (infinity for no limit)");
}

void InsertionConfig::validate() const {
  require(std::isfinite(min_range) && min_range >= 0.0, "min_range",
          "must be a finite number >= 0");
  require(!std::isnan(max_range) && max_range > 0.0, "max_range",
          "must be > 0 (infinity for no limit)");
  require(min_range < max_range, "min_range", "must be smaller than max_range");
  require(insertion_threads >= 1 && insertion_threads <= 256, "insertion_threads",
          "must be in [1, 256]");
  require(evidence_limit >= 1.0, "evidence_limit",
          "must be >= 1 (a scan's own density), infinity for no limit");
  require(hit_memory_scans >= 0 && hit_memory_scans <= kMaxHitMemoryScans, "hit_memory_scans",
          "must be in [0, " + std::to_string(kMaxHitMemoryScans) + "]");
  require(free_space_rays == FreeSpaceRays::kEveryReading ||
              free_space_rays == FreeSpaceRays::kOnePerEndVoxel ||
              free_space_rays == FreeSpaceRays::kOnePathPerEndColumn,
          "free_space_rays", "must be kEveryReading, kOnePerEndVoxel or kOnePathPerEndColumn");
  require(hit_memory_scope == HitMemoryScope::kLineScans ||
              hit_memory_scope == HitMemoryScope::kEveryScan,
          "hit_memory_scope", "must be kLineScans or kEveryScan");
}

}  // namespace mvog
