// One ray per end voxel (FreeSpaceRays::kOnePerEndVoxel): a scan's readings checked, counted and
// grouped by the voxel they end in, from its points or straight from a depth image's pixels; and
// those rays by the column they end in (FreeSpaceRays::kOnePathPerEndColumn).
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "depth_readings.h"
#include "mvog/depth_image.h"
#include "scan_scratch.h"

namespace mvog {
namespace detail {

void EndVoxelIndex::begin() {
  size_ = 0;
  if (++stamp_ == std::uint32_t{1} << 31) {  // the tag holds 31 bits of stamp: start again
    for (Slot& slot : slots_) slot.tag = 0;
    stamp_ = 1;
  }
}

void EndVoxelRays::begin() {
  voxels_.clear();
  index_.begin();
  last_corner_.setConstant(std::numeric_limits<double>::quiet_NaN());
}

namespace {

std::size_t hashOf(std::int32_t x, std::int32_t y, std::int32_t z) {
  std::uint64_t h = static_cast<std::uint32_t>(x) * 0x9E3779B97F4A7C15ull;
  h ^= static_cast<std::uint32_t>(y) * 0xC2B2AE3D27D4EB4Full;
  h ^= static_cast<std::uint32_t>(z) * 0x165667B19E3779F9ull;
  return static_cast<std::size_t>(h ^ (h >> 32));
}

}  // namespace

void EndVoxelIndex::place(const Slot& slot) {
  const std::size_t mask = slots_.size() - 1;
  std::size_t k = hashOf(slot.x, slot.y, slot.z) & mask;
  while (slots_[k].tag >> 1 == stamp_) k = (k + 1) & mask;
  slots_[k] = slot;
}

void EndVoxelIndex::grow() {
  std::vector<Slot> old(std::max<std::size_t>(1024, 2 * slots_.size()), Slot{0, 0, 0, 0, 0});
  old.swap(slots_);
  for (const Slot& slot : old) {
    if (slot.tag >> 1 == stamp_) place(slot);
  }
}

std::pair<std::uint32_t, bool> EndVoxelIndex::findOrAdd(const EndVoxel& voxel) {
  const std::uint32_t tag = stamp_ << 1 | static_cast<std::uint32_t>(voxel.obstacle);
  if (2 * (std::size_t{size_} + 1) > slots_.size()) grow();
  const std::size_t mask = slots_.size() - 1;
  std::size_t k = hashOf(voxel.x, voxel.y, voxel.z) & mask;
  for (;; k = (k + 1) & mask) {
    const Slot& slot = slots_[k];
    if (slot.tag >> 1 != stamp_) break;
    if (slot.tag == tag && slot.x == voxel.x && slot.y == voxel.y && slot.z == voxel.z) {
      return {slot.index, false};
    }
  }
  // A scan holds fewer than 2^32 readings.
  slots_[k] = {voxel.x, voxel.y, voxel.z, tag, size_};
  return {size_++, true};
}

void EndVoxelRays::offerElsewhere(const EndVoxel& voxel, const Eigen::Vector3d& end) {
  const Eigen::Vector3d corner = cornerOf(voxel);
  const Eigen::Vector3d centre = corner.array() + 0.5;
  const double distance = (end - centre).squaredNorm();
  const auto [index, added] = index_.findOrAdd(voxel);
  if (added) {
    voxels_.push_back({{end},
                       end,
                       distance,
                       {voxel.x, voxel.y},
                       static_cast<float>(end.z()),
                       static_cast<float>(end.z()),
                       1,
                       voxel.obstacle});
  } else {
    join(voxels_[index], voxel.obstacle, end, distance);
  }
  // The voxel is the last offered once it holds the reading: offer() may then join it.
  last_obstacle_ = voxel.obstacle;
  last_index_ = index;
  last_corner_ = corner;
  last_centre_ = centre;
}

void EndVoxelRays::merge(const EndVoxelRays& other) {
  for (const VoxelReadings& readings : other.voxels_) {
    // Every reading of a voxel ends in it: `nearest` names it.
    const auto [index, added] = index_.findOrAdd(endVoxelOf(readings.nearest, readings.obstacle));
    if (added) {
      voxels_.push_back(readings);
      continue;
    }
    VoxelReadings& into = voxels_[index];
    // The ends are kept while a voxel holds fewer than kReadingsForOneRay readings: then both
    // parts hold all theirs.
    for (std::uint32_t k = 0; k < readings.count && into.count + k < into.ends.size(); ++k) {
      into.ends[into.count + k] = readings.ends[k];
    }
    into.count += readings.count;
    into.lowest_hit = std::min(into.lowest_hit, readings.lowest_hit);
    into.highest_hit = std::max(into.highest_hit, readings.highest_hit);
    keepNearer(into, readings.nearest, readings.nearest_distance);
  }
}

void EndColumnRuns::formRuns(std::size_t voxels) {
  // A counting sort by column: column_rays_ becomes where each column's ends start, then end.
  std::uint32_t offset = 0;
  for (std::uint32_t& count : column_rays_) offset += std::exchange(count, offset);
  sorted_.resize(ends_.size());
  for (const RayEnd& ray : ends_) sorted_[column_rays_[ray.column]++] = ray;
  by_column_.resize(ends_.size());
  runs_.clear();
  run_of_first_voxel_.assign(voxels, kNoRun);
  std::uint32_t first = 0;
  for (const std::uint32_t end : column_rays_) {
    std::sort(sorted_.begin() + first, sorted_.begin() + end,
              [](const RayEnd& a, const RayEnd& b) { return a.end.z() < b.end.z(); });
    const CellIndex cell = cellAt(sorted_[first].end.x(), sorted_[first].end.y());
    const Eigen::Vector2d axis(cell.x + 0.5, cell.y + 0.5);
    Run run{first, 0, 0};
    std::uint32_t first_voxel = sorted_[first].voxel;
    double path_distance = 0.0;
    auto close_run = [&] {
      run_of_first_voxel_[first_voxel] = static_cast<std::uint32_t>(runs_.size());
      runs_.push_back(run);
    };
    for (std::uint32_t k = first; k < end; ++k) {
      const Eigen::Vector3d& ray_end = by_column_[k] = sorted_[k].end;
      if (k > first && ray_end.z() - by_column_[k - 1].z() > kColumnRunHeightGap) {
        close_run();
        run = {k, 0, 0};
        first_voxel = sorted_[k].voxel;
      }
      first_voxel = std::min(first_voxel, sorted_[k].voxel);
      // The run follows the path of its end nearest the column's axis.
      const double distance = (ray_end.head<2>() - axis).squaredNorm();
      const Eigen::Vector3d& path = by_column_[run.first + run.path];
      if (run.count == 0 || distance < path_distance ||
          (distance == path_distance &&
           std::lexicographical_compare(ray_end.data(), ray_end.data() + 3, path.data(),
                                        path.data() + 3))) {
        run.path = run.count;
        path_distance = distance;
      }
      ++run.count;
    }
    close_run();
    first = end;
  }
}

namespace {

/// The `part`-th of `parts` runs of a scan's readings from its points (Scan): calls hit(p) for
/// each of its obstacle readings, then out_of_range(p) for each of its out-of-range readings.
struct ScanReadings {
  const Scan& scan;
  std::size_t part;
  std::size_t parts;
  template <class Hit, class OutOfRange>
  void forEach(Hit&& hit, OutOfRange&& out_of_range) const {
    const std::size_t hits = scan.hits.size();
    for (std::size_t k = hits * part / parts; k < hits * (part + 1) / parts; ++k) {
      hit(scan.hits[k]);
    }
    const std::size_t out_of_range_readings = scan.out_of_range.size();
    for (std::size_t k = out_of_range_readings * part / parts;
         k < out_of_range_readings * (part + 1) / parts; ++k) {
      out_of_range(scan.out_of_range[k]);
    }
  }
};

/// The `part`-th of `parts` runs of rows of a depth image (DepthFrame, validated), read straight
/// from its pixels, the pixels without a measurement counted in `skipped`. They are passed on a
/// batch at a time, from a buffer: GCC 12's SLP vectoriser at -O3 drops a point's rounding to
/// float where it is rounded and widened back at once (its map then differs from its Scan's:
/// test InsertDepthImage.MakesTheMapOfTheImagesReadingsBitForBitWhateverTheThreadsAndOptions).
struct DepthFrameReadings {
  const DepthFrame& frame;
  std::size_t part;
  std::size_t parts;
  std::size_t& skipped;

  template <class Hit, class OutOfRange>
  void forEach(Hit&& hit, OutOfRange&& out_of_range) const {
    constexpr std::size_t kBatch = 256;  // 3 KB of points, in the first-level cache
    std::array<Eigen::Vector3f, kBatch> points;
    std::array<bool, kBatch> hits;
    std::size_t kept = 0;
    auto pass_on = [&] {
      for (std::size_t k = 0; k < kept; ++k) {
        if (hits[k]) {
          hit(points[k]);
        } else {
          out_of_range(points[k]);
        }
      }
      kept = 0;
    };
    auto keep = [&](const Eigen::Vector3f& p, bool is_hit) {
      points[kept] = p;
      hits[kept] = is_hit;
      if (++kept == kBatch) pass_on();
    };
    const std::size_t rows = frame.image.height;
    forEachDepthReading(
        frame, rows * part / parts, rows * (part + 1) / parts,
        [&](const Eigen::Vector3f& p) { keep(p, true); },
        [&](const Eigen::Vector3f& p) { keep(p, false); }, skipped);
    pass_on();
  }
};

/// groupByEndVoxel of the readings `readings` gives (ScanReadings or DepthFrameReadings).
template <class Readings>
GroupedScan groupReadings(const Readings& readings, const Eigen::Vector3d& origin,
                          const MapConfig& map_config, const InsertionConfig& insertion,
                          EndVoxelRays& voxels, InsertionResult& result) {
  const double s = 1.0 / map_config.resolution;
  const bool origin_accepted = map_config.withinBounds(origin);
  GroupedScan grouped;
  auto offer = [&](const Eigen::Vector3f& end, ReadingKind kind) {
    Eigen::Vector3d ray_end;
    bool obstacle = false;
    if (!acceptReading(origin, origin_accepted, end.cast<double>(), kind, map_config, insertion,
                       ray_end, obstacle, result)) {
      return;
    }
    grouped.level = grouped.level && ray_end.z() == origin.z();
    const Eigen::Vector3d end_cells = ray_end * s;
    voxels.offer(end_cells, obstacle);
  };
  readings.forEach([&](const Eigen::Vector3f& p) { offer(p, ReadingKind::kObstacle); },
                   [&](const Eigen::Vector3f& p) { offer(p, ReadingKind::kOutOfRange); });
  if (origin_accepted) grouped.cells.extend(cellAt(origin.x() * s, origin.y() * s));
  for (const VoxelReadings& voxel : voxels.voxels()) grouped.cells.extend(voxel.cell);
  return grouped;
}

/// groupByEndVoxel of the readings `readings_of(part, parts)` gives, each of `parts` runs on
/// a thread of `pool`, into voxels[part], then merged into voxels[0].
template <class ReadingsOf>
GroupedScan groupInParts(const ReadingsOf& readings_of, const Eigen::Vector3d& origin,
                         const MapConfig& map_config, const InsertionConfig& insertion,
                         ThreadPool* pool, std::vector<EndVoxelRays>& voxels,
                         InsertionResult& result) {
  const std::size_t parts = pool != nullptr ? pool->threads() : 1;
  if (voxels.size() < parts) voxels.resize(parts);
  std::vector<GroupedScan> grouped(parts);
  std::vector<InsertionResult> results(parts);
  auto group = [&](std::size_t, std::size_t part) {
    voxels[part].begin();
    grouped[part] = groupReadings(readings_of(part, parts), origin, map_config, insertion,
                                  voxels[part], results[part]);
  };
  if (pool != nullptr) {
    pool->run(parts, group);
  } else {
    group(0, 0);
  }
  for (std::size_t part = 1; part < parts; ++part) {
    voxels[0].merge(voxels[part]);
    grouped[0].cells.extend(grouped[part].cells);
    grouped[0].level = grouped[0].level && grouped[part].level;
  }
  for (const InsertionResult& r : results) result += r;
  return grouped[0];
}

}  // namespace

GroupedScan groupByEndVoxel(const Scan& scan, const MapConfig& map_config,
                            const InsertionConfig& insertion, ThreadPool* pool,
                            std::vector<EndVoxelRays>& voxels, InsertionResult& result) {
  return groupInParts(
      [&](std::size_t part, std::size_t parts) {
        return ScanReadings{scan, part, parts};
      },
      scan.origin, map_config, insertion, pool, voxels, result);
}

GroupedScan groupByEndVoxel(const DepthFrame& frame, const MapConfig& map_config,
                            const InsertionConfig& insertion, ThreadPool* pool,
                            std::vector<EndVoxelRays>& voxels, InsertionResult& result) {
  const std::size_t parts = pool != nullptr ? pool->threads() : 1;
  std::vector<std::size_t> skipped(parts, 0);
  const GroupedScan grouped = groupInParts(
      [&](std::size_t part, std::size_t count) {
        return DepthFrameReadings{frame, part, count, skipped[part]};
      },
      frame.map_from_camera.translation(), map_config, insertion, pool, voxels, result);
  for (std::size_t count : skipped) result.rejected_no_measurement += count;
  return grouped;
}

}  // namespace detail
}  // namespace mvog
