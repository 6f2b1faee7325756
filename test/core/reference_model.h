// A plain reference of the scan update of Fig. 2, written from the paper's text and the README's
// decisions table without any of the map's speed-ups (scan-local scratch tiles, inline slots,
// the covered-free-space shortcut, tiles written in place): every reading's volumes per cell
// (eqs. 3-6), collected for the whole scan, joined per cell, clipped around the scan's hits, then
// merged into the cell's lists by ListMerger (whose rules test_volume.cpp checks one by one).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <tuple>
#include <utility>
#include <vector>

#include "mvog/constraints.h"
#include "mvog/map.h"
#include "mvog/raster.h"

namespace mvog {
namespace test {

class ReferenceModel {
 public:
  using Cells = std::map<std::pair<std::int32_t, std::int32_t>, CellVolumes>;

  explicit ReferenceModel(const MapConfig& config) : config_(config) {}

  /// Inserts a scan whose readings are all finite and within max_coordinate.
  void insertScan(const Scan& scan, const InsertionConfig& insertion = {}) {
    const double s = 1.0 / config_.resolution;
    const Eigen::Vector3d start = scan.origin * s;
    std::map<std::pair<std::int32_t, std::int32_t>,
             std::pair<std::vector<Volume>, std::vector<Volume>>>
        seen;  // per cell: the scan's free volumes, its hits' volumes
    // FreeSpaceRays::kOnePerEndVoxel (masses per scan, free space modelled): each hit adds its
    // own volume; the readings ending in one voxel (cell, floor of the height, whether an
    // obstacle) are walked each while fewer than 4, else only the one ending nearest the voxel's
    // centre (ties: the lowest end in x, then y, then z).
    const bool one_ray_per_voxel = config_.rules.mass_counting == MassCounting::kPerScan &&
                                   insertion.free_space_rays != FreeSpaceRays::kEveryReading &&
                                   insertion.model_negative_space;
    // FreeSpaceRays::kOnePathPerEndColumn: the rays of the voxels of 4 or more readings, by end
    // column and kind, sorted by height and cut where two neighbours' heights part by more than
    // 2 cells, each run walked along the path of its ray ending nearest the column's axis: a
    // cell before the column gets the hull of the lowest and highest rays' eq. 6 volumes at the
    // path's entry and exit parameters, the column each ray's last crossing.
    const bool one_path_per_column =
        one_ray_per_voxel && insertion.free_space_rays == FreeSpaceRays::kOnePathPerEndColumn;
    std::map<std::tuple<std::int32_t, std::int32_t, bool>, std::vector<Eigen::Vector3d>>
        column_ends;
    using Voxel = std::tuple<std::int32_t, std::int32_t, std::int32_t, bool>;
    std::map<Voxel, std::vector<Eigen::Vector3d>> voxel_ends;
    // A reading's last cell, entered at z_enter: its free crossing (no return), or its hit's
    // volume (if with_hit) and the free space up to it.
    auto last_crossing = [](std::vector<Volume>& free, std::vector<Volume>& hits, double z_enter,
                            double end_z, bool obstacle, bool with_hit) {
      if (!obstacle) {
        free.push_back(makeVolume(static_cast<float>(z_enter), static_cast<float>(end_z)));
        return;
      }
      const auto z = static_cast<float>(end_z);
      const Volume hit = makeVolume(z - 0.5f, z + 0.5f);
      if (with_hit) hits.push_back(hit);
      if (std::fabs(z_enter - end_z) > 1.0) {
        free.push_back(
            makeVolume(static_cast<float>(z_enter), z_enter < end_z ? hit.bottom : hit.top));
      }
    };
    auto walk = [&](const Eigen::Vector3d& end, bool obstacle, bool with_hit) {
      walkRay(
          start.x(), start.y(), start.z(), end.x(), end.y(), end.z(),
          [&](const CellIndex& c, double z_enter, double z_exit, bool is_last) {
            auto& [free, hits] = seen[{c.x, c.y}];
            if (!is_last) {
              free.push_back(makeVolume(static_cast<float>(z_enter), static_cast<float>(z_exit)));
              return;
            }
            last_crossing(free, hits, z_enter, end.z(), obstacle, with_hit);
          });
    };
    auto reading = [&](const Eigen::Vector3f& point, bool is_obstacle) {
      const Eigen::Vector3d ray = point.cast<double>() - scan.origin;
      const double length = ray.norm();
      if (length == 0.0) return;
      const bool obstacle = is_obstacle && length <= insertion.max_range;
      // A ray without a return frees at most out_of_range_free_length.
      const double free_length =
          is_obstacle ? insertion.max_range
                      : std::min(insertion.max_range, config_.rules.out_of_range_free_length);
      const Eigen::Vector3d end =
          (length > free_length ? Eigen::Vector3d(scan.origin + ray * (free_length / length))
                                : point.cast<double>()) *
          s;
      if (!one_ray_per_voxel) {
        walk(end, obstacle, true);
        return;
      }
      if (obstacle) {
        const Volume hit =
            makeVolume(static_cast<float>(end.z()) - 0.5f, static_cast<float>(end.z()) + 0.5f);
        seen[{static_cast<std::int32_t>(std::floor(end.x())),
              static_cast<std::int32_t>(std::floor(end.y()))}]
            .second.push_back(hit);
      }
      const Eigen::Vector3d floor = end.array().floor();
      voxel_ends[{static_cast<std::int32_t>(floor.x()), static_cast<std::int32_t>(floor.y()),
                  static_cast<std::int32_t>(floor.z()), obstacle}]
          .push_back(end);
    };
    for (const Eigen::Vector3f& hit : scan.hits) reading(hit, true);
    for (const Eigen::Vector3f& end : scan.out_of_range) reading(end, false);
    for (const auto& [voxel, ends] : voxel_ends) {
      const bool obstacle = std::get<3>(voxel);
      if (ends.size() < 4) {
        for (const Eigen::Vector3d& end : ends) walk(end, obstacle, false);
        continue;
      }
      const Eigen::Vector3d centre =
          Eigen::Vector3d(std::get<0>(voxel), std::get<1>(voxel), std::get<2>(voxel)) +
          Eigen::Vector3d::Constant(0.5);
      const auto nearer = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
        const double da = (a - centre).squaredNorm();
        const double db = (b - centre).squaredNorm();
        return da != db
                   ? da < db
                   : std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
      };
      const Eigen::Vector3d& nearest = *std::min_element(ends.begin(), ends.end(), nearer);
      if (one_path_per_column) {
        column_ends[{std::get<0>(voxel), std::get<1>(voxel), obstacle}].push_back(nearest);
        continue;
      }
      walk(nearest, obstacle, false);
    }
    auto walk_run = [&](const std::vector<Eigen::Vector3d>& run, bool obstacle) {
      if (run.size() == 1) {
        walk(run[0], obstacle, false);
        return;
      }
      const Eigen::Vector2d axis(std::floor(run[0].x()) + 0.5, std::floor(run[0].y()) + 0.5);
      const auto nearer_axis = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
        const double da = (a.head<2>() - axis).squaredNorm();
        const double db = (b.head<2>() - axis).squaredNorm();
        return da != db
                   ? da < db
                   : std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
      };
      const Eigen::Vector3d path = *std::min_element(run.begin(), run.end(), nearer_axis);
      auto height = [&](double t, double end_z) { return start.z() + t * (end_z - start.z()); };
      walkRay(
          start.x(), start.y(), 0.0, path.x(), path.y(), 1.0,
          [&](const CellIndex& c, double t_enter, double t_exit, bool is_last) {
            auto& [free, hits] = seen[{c.x, c.y}];
            if (!is_last) {
              const Volume low = makeVolume(static_cast<float>(height(t_enter, run.front().z())),
                                            static_cast<float>(height(t_exit, run.front().z())));
              const Volume high = makeVolume(static_cast<float>(height(t_enter, run.back().z())),
                                             static_cast<float>(height(t_exit, run.back().z())));
              free.push_back(volumeOfMinimumHeight(std::min(low.bottom, high.bottom),
                                                   std::max(low.top, high.top)));
              return;
            }
            for (const Eigen::Vector3d& end : run) {
              last_crossing(free, hits, height(t_enter, end.z()), end.z(), obstacle, false);
            }
          });
    };
    for (auto& [column, ends] : column_ends) {
      std::sort(ends.begin(), ends.end(),
                [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return a.z() < b.z(); });
      std::vector<Eigen::Vector3d> run;
      for (const Eigen::Vector3d& end : ends) {
        if (!run.empty() && end.z() - run.back().z() > 2.0) {
          walk_run(run, std::get<2>(column));
          run.clear();
        }
        run.push_back(end);
      }
      walk_run(run, std::get<2>(column));
    }

    const ModelRules& rules = config_.rules;
    const bool per_scan = rules.mass_counting == MassCounting::kPerScan;
    const float join_gap = per_scan ? kMaxMergeGap : 0.0f;
    for (auto& [key, lists] : seen) {
      const std::vector<Volume> free = joined(lists.first, join_gap, per_scan);
      const std::vector<Volume> hits = joined(lists.second, join_gap, per_scan);
      std::vector<Volume> added_free;
      for (const Volume& f : free) {
        if (!rules.clip_free_space_at_hits) {
          added_free.push_back(f);
          continue;
        }
        // What of f no hit of the scan covers, in parts at least 1 high.
        std::vector<std::pair<float, float>> parts{{f.bottom, f.top}};
        for (const Volume& h : hits) {
          std::vector<std::pair<float, float>> rest;
          for (const auto& [b, t] : parts) {
            if (h.top <= b || h.bottom >= t) {
              rest.emplace_back(b, t);
              continue;
            }
            if (h.bottom > b) rest.emplace_back(b, h.bottom);
            if (h.top < t) rest.emplace_back(h.top, t);
          }
          parts = rest;
        }
        for (const auto& [b, t] : parts) {
          if (t - b < kMinVolumeHeight) continue;
          const double mass =
              per_scan ? static_cast<double>(t) - b
              : (b == f.bottom && t == f.top)
                  ? f.mass
                  : f.mass * (static_cast<double>(t) - b) / (static_cast<double>(f.top) - f.bottom);
          added_free.push_back({b, t, static_cast<float>(mass)});
        }
      }
      CellVolumes& cell = cells_[key];
      std::vector<Volume> positive;
      std::vector<Volume> negative;
      ListMerger merger;
      merger.merge(cell.positive, hits, {}, {}, 1.0f, positive);
      merger.merge(cell.negative, added_free, positive,
                   {rules.split_free_space_at_obstacles, rules.clip_free_space_at_hits}, 1.0f,
                   negative);
      if (per_scan && std::isfinite(insertion.evidence_limit)) {  // evidence_limit
        std::vector<double> factors;
        boundEvidence(positive.data(), positive.size(), negative.data(), negative.size(),
                      insertion.evidence_limit, factors);
      }
      cell.positive = positive;
      cell.negative = negative;
      if (cell.positive.empty() && cell.negative.empty()) cells_.erase(key);
    }
  }

  const Cells& cells() const { return cells_; }

 private:
  /// The union of `volumes` where they are at most `join_gap` apart, each part with the summed
  /// masses (or, per scan, its height: density 1).
  static std::vector<Volume> joined(std::vector<Volume> volumes, float join_gap, bool per_scan) {
    std::sort(volumes.begin(), volumes.end(),
              [](const Volume& a, const Volume& b) { return a.bottom < b.bottom; });
    std::vector<Volume> out;
    std::vector<double> masses;
    for (const Volume& v : volumes) {
      if (!out.empty() && v.bottom - out.back().top <= join_gap) {
        out.back().top = std::max(out.back().top, v.top);
        masses.back() += v.mass;
      } else {
        out.push_back(v);
        masses.push_back(v.mass);
      }
    }
    for (std::size_t k = 0; k < out.size(); ++k) {
      out[k].mass = static_cast<float>(per_scan ? out[k].height() : masses[k]);
    }
    return out;
  }

  MapConfig config_;
  Cells cells_;
};

/// The map holds exactly the reference's cells and lists: the same bounds bit for bit, masses
/// within a relative 1e-5 (the map sums some masses in another order).
inline ::testing::AssertionResult sameAsReference(const Map& map, const ReferenceModel& reference) {
  std::size_t cells = 0;
  for (const auto& [key, expected] : reference.cells()) {
    ++cells;
    const CellVolumes held = map.cellVolumes({key.first, key.second});
    for (bool positive : {true, false}) {
      const std::vector<Volume>& a = positive ? held.positive : held.negative;
      const std::vector<Volume>& b = positive ? expected.positive : expected.negative;
      bool same = a.size() == b.size();
      for (std::size_t k = 0; same && k < a.size(); ++k) {
        same = a[k].bottom == b[k].bottom && a[k].top == b[k].top &&
               std::fabs(a[k].mass - b[k].mass) <= 1e-5f * std::max(1.0f, b[k].mass);
      }
      if (!same) {
        std::ostringstream text;
        text << "cell (" << key.first << ", " << key.second << ") "
             << (positive ? "positive" : "negative") << ": map";
        for (const Volume& v : a)
          text << " [" << v.bottom << ", " << v.top << " | " << v.mass << "]";
        text << ", reference";
        for (const Volume& v : b)
          text << " [" << v.bottom << ", " << v.top << " | " << v.mass << "]";
        return ::testing::AssertionFailure() << text.str();
      }
    }
  }
  std::size_t map_cells = 0;
  map.forEachVolume([&, last = CellIndex{0, 0}, first = true](const CellIndex& c, VolumeSign,
                                                              const Volume&) mutable {
    if (first || c != last) ++map_cells;
    first = false;
    last = c;
  });
  if (map_cells != cells) {
    return ::testing::AssertionFailure()
           << "the map has " << map_cells << " cells with volumes, the reference " << cells;
  }
  return ::testing::AssertionSuccess();
}

/// A map beside the reference model, with the same configuration and fed the same scans.
struct MapBesideReference {
  explicit MapBesideReference(const MapConfig& config) : map(config), reference(config) {}
  /// Inserts `scan` into both; whether they then hold the same.
  ::testing::AssertionResult insert(const Scan& scan, const InsertionConfig& insertion = {}) {
    map.insertScan(scan, insertion);
    reference.insertScan(scan, insertion);
    return sameAsReference(map, reference);
  }

  Map map;
  ReferenceModel reference;
};

}  // namespace test
}  // namespace mvog
