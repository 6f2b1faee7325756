// Insertion (Sec. III-B, Fig. 2): a scan is rasterised whole, its new volumes are collected per
// column, then the constraints are applied once to every list it modified.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <unordered_map>

#include "mvog/constraints.h"
#include "mvog/map.h"
#include "mvog/raster.h"

namespace mvog {

bool Map::acceptReading(const Eigen::Vector3d& origin, const Eigen::Vector3d& end,
                        ReadingKind kind, const InsertionConfig& config, Eigen::Vector3d& ray_end,
                        bool& obstacle, InsertionResult& result) const {
  const bool is_obstacle = kind == ReadingKind::kObstacle;
  if (!origin.allFinite() || !end.allFinite()) {
    ++result.rejected_non_finite;
    return false;
  }
  if (origin.cwiseAbs().maxCoeff() > config_.max_coordinate ||
      end.cwiseAbs().maxCoeff() > config_.max_coordinate) {
    ++result.rejected_out_of_bounds;
    return false;
  }
  const Eigen::Vector3d ray = end - origin;
  const double length = ray.norm();
  // A zero-length out-of-range reading carries no free space; a zero-length hit is below any
  // min_range but the sensor itself (decision: both are dropped as too close).
  if (length == 0.0 || (is_obstacle && length < config.min_range)) {
    ++result.rejected_too_close;
    return false;
  }
  obstacle = is_obstacle && length <= config.max_range;
  if (!obstacle && !config.insert_out_of_range) {
    ++result.ignored_out_of_range;
    return false;
  }
  ray_end =
      length > config.max_range ? Eigen::Vector3d(origin + ray * (config.max_range / length)) : end;
  if (obstacle) {
    ++result.obstacle_readings;
  } else {
    ++result.out_of_range_readings;
    if (is_obstacle) ++result.truncated_to_max_range;
  }
  return true;
}

namespace {

std::uint64_t cellKey(const CellIndex& c) {
  return (std::uint64_t{static_cast<std::uint32_t>(c.x)} << 32) | static_cast<std::uint32_t>(c.y);
}
CellIndex cellOfKey(std::uint64_t key) {
  return {static_cast<std::int32_t>(key >> 32), static_cast<std::int32_t>(key)};
}

/// A scan's new volumes in one list of one column, overlapping ones joined (eq. 7): sorted,
/// disjoint, each with the summed mass of the volumes it joined.
struct ScanInterval {
  float bottom;
  float top;
  double mass;
};

void addInterval(std::vector<ScanInterval>& list, const Volume& v) {
  auto first = std::partition_point(list.begin(), list.end(),
                                    [&](const ScanInterval& i) { return i.top < v.bottom; });
  if (first == list.end() || first->bottom > v.top) {
    list.insert(first, {v.bottom, v.top, v.mass});
    return;
  }
  ScanInterval joined{std::min(v.bottom, first->bottom), v.top, v.mass};
  auto last = first;
  for (; last != list.end() && last->bottom <= v.top; ++last) {
    joined.top = std::max(joined.top, last->top);
    joined.mass += last->mass;
  }
  *first = joined;
  list.erase(first + 1, last);
}

struct ScanColumn {
  std::vector<ScanInterval> positive;
  std::vector<ScanInterval> negative;
};

/// Sec. III-B.2: the volumes one reading creates, handed to emit(cell, sign, volume). `start`
/// and `end` are in grid units.
template <class Emit>
void volumesOfReading(const Eigen::Vector3d& start, const Eigen::Vector3d& end, bool obstacle,
                      bool model_negative_space, Emit&& emit) {
  const float end_z = static_cast<float>(end.z());
  auto obstacle_volume = [&] { return makeVolume(end_z - 0.5f, end_z + 0.5f); };
  static const double margin = std::getenv("MVOG_MARGIN") ? std::atof(std::getenv("MVOG_MARGIN")) : 0.0;
  if (obstacle && model_negative_space && margin > 0.0) {
    const Eigen::Vector3d ray = end - start;
    const double length = ray.norm();
    if (length > margin) {
      const Eigen::Vector3d free_end = start + ray * ((length - margin) / length);
      walkRay(start.x(), start.y(), start.z(), free_end.x(), free_end.y(), free_end.z(),
              [&](const CellIndex& cell, double z_enter, double z_exit, bool) {
                emit(cell, VolumeSign::kNegative,
                     makeVolume(static_cast<float>(z_enter), static_cast<float>(z_exit)));
              });
    }
    emit(cellAt(end.x(), end.y()), VolumeSign::kPositive, obstacle_volume());
    return;
  }
  if (!model_negative_space) {
    // Only the obstacle's own volume, in the cell the walk would end in (see walkRay): no walk.
    if (obstacle) emit(cellAt(end.x(), end.y()), VolumeSign::kPositive, obstacle_volume());
    return;
  }
  walkRay(start.x(), start.y(), start.z(), end.x(), end.y(), end.z(),
          [&](const CellIndex& cell, double z_enter, double z_exit, bool is_last) {
            if (!is_last || !obstacle) {  // eqs. (3) and (4)
              emit(cell, VolumeSign::kNegative,
                   makeVolume(static_cast<float>(z_enter), static_cast<float>(z_exit)));
              return;
            }
            const Volume positive = obstacle_volume();  // eq. (5)
            emit(cell, VolumeSign::kPositive, positive);
            if (std::fabs(z_enter - end.z()) > 1.0) {  // Fig. 3, left: pad up to the obstacle
              emit(cell, VolumeSign::kNegative,
                   makeVolume(static_cast<float>(z_enter),
                              z_enter < end.z() ? positive.bottom : positive.top));
            }
          });
}

/// The new volumes of one column, as the model's rules make them from what the scan saw there.
void addedVolumes(const ScanColumn& column, const ModelRules& rules, float unit_mass,
                  CellVolumes& added) {
  added.positive.clear();
  added.negative.clear();
  const bool per_scan = rules.mass_counting == MassCounting::kPerScan;
  auto mass_of = [&](const ScanInterval& i, float bottom, float top) {
    const double height = static_cast<double>(top) - bottom;
    return static_cast<float>(
        (per_scan ? height : i.mass * height / (static_cast<double>(i.top) - i.bottom)) *
        unit_mass);
  };
  for (const ScanInterval& i : column.positive) {
    added.positive.push_back({i.bottom, i.top, mass_of(i, i.bottom, i.top)});
  }
  for (const ScanInterval& i : column.negative) {
    if (!rules.clip_free_space_at_hits) {
      added.negative.push_back({i.bottom, i.top, mass_of(i, i.bottom, i.top)});
      continue;
    }
    // Sec. V.B: the parts of the free interval outside the scan's own obstacle volumes; a part
    // lower than kMinVolumeHeight (a sliver beside a hit) is dropped.
    float below = i.bottom;
    auto keep = [&](float bottom, float top) {
      if (top - bottom >= kMinVolumeHeight) {
        added.negative.push_back({bottom, top, mass_of(i, bottom, top)});
      }
    };
    for (const ScanInterval& hit : column.positive) {
      if (hit.top <= below) continue;
      if (hit.bottom >= i.top) break;
      keep(below, std::min(hit.bottom, i.top));
      below = std::max(below, hit.top);
    }
    if (below < i.top) keep(below, i.top);
  }
}

}  // namespace

InsertionResult Map::insertReading(const Eigen::Vector3d& origin, const Eigen::Vector3d& end,
                                   ReadingKind kind, const InsertionConfig& config) {
  Scan scan;
  scan.origin = origin;
  const Eigen::Vector3f end_f = end.cast<float>();
  (kind == ReadingKind::kObstacle ? scan.hits : scan.out_of_range).push_back(end_f);
  return insertScan(scan, config);
}

InsertionResult Map::insertScan(const Scan& scan, const InsertionConfig& config) {
  config.validate();
  InsertionResult result;
  std::unordered_map<std::uint64_t, ScanColumn> columns;
  const Eigen::Vector3d start = scan.origin * scale_inverse_;
  auto accept = [&](const Eigen::Vector3f& end, ReadingKind kind) {
    Eigen::Vector3d ray_end;
    bool obstacle = false;
    if (!acceptReading(scan.origin, end.cast<double>(), kind, config, ray_end, obstacle, result)) {
      return;
    }
    volumesOfReading(start, ray_end * scale_inverse_, obstacle, config.model_negative_space,
                     [&](const CellIndex& cell, VolumeSign sign, const Volume& volume) {
                       ScanColumn& column = columns[cellKey(cell)];
                       addInterval(
                           sign == VolumeSign::kPositive ? column.positive : column.negative,
                           volume);
                     });
  };
  for (const Eigen::Vector3f& hit : scan.hits) accept(hit, ReadingKind::kObstacle);
  for (const Eigen::Vector3f& end : scan.out_of_range) accept(end, ReadingKind::kOutOfRange);
  if (columns.empty()) return result;

  ListMerger merger;
  CellVolumes added;
  CellVolumes merged;
  for (const auto& [key, column] : columns) {
    const CellIndex cell = cellOfKey(key);
    addedVolumes(column, config_.rules, 1.0f, added);
    const CellVolumes existing = cellVolumes(cell);
    merger.merge(existing.positive, added.positive, {}, {}, 1.0f, merged.positive);
    merger.merge(existing.negative, added.negative, merged.positive,
                 {config_.rules.split_free_space_at_obstacles, config_.rules.clip_free_space_at_hits},
                 1.0f, merged.negative);
    try { setCellVolumes(cell, merged); } catch (const ConfigError& e) {
      auto dump = [](const char* name, const std::vector<Volume>& l) {
        std::fprintf(stderr, "%s:", name);
        for (const Volume& v : l) std::fprintf(stderr, " [%.9g, %.9g | %.6g]", v.bottom, v.top, v.mass);
        std::fprintf(stderr, "\n");
      };
      dump("existing P", existing.positive); dump("existing N", existing.negative);
      dump("added P", added.positive); dump("added N", added.negative);
      dump("merged P", merged.positive); dump("merged N", merged.negative);
      throw;
    }
  }
  return result;
}

}  // namespace mvog
