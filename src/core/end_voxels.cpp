// One ray per end voxel (FreeSpaceRays::kOnePerEndVoxel): a scan's readings checked, counted and
// grouped by the voxel they end in, from its points or straight from a depth image's pixels.
#include <algorithm>
#include <cmath>
#include <vector>

#include "depth_readings.h"
#include "mvog/depth_image.h"
#include "scan_scratch.h"

namespace mvog {
namespace detail {

void EndVoxelRays::begin() {
  voxels_.clear();
  if (++stamp_ == std::uint32_t{1} << 31) {  // the tag holds 31 bits of stamp: start again
    for (Slot& slot : slots_) slot.tag = 0;
    stamp_ = 1;
  }
}

namespace {

std::size_t hashOf(std::int32_t x, std::int32_t y, std::int32_t z) {
  std::uint64_t h = static_cast<std::uint32_t>(x) * 0x9E3779B97F4A7C15ull;
  h ^= static_cast<std::uint32_t>(y) * 0xC2B2AE3D27D4EB4Full;
  h ^= static_cast<std::uint32_t>(z) * 0x165667B19E3779F9ull;
  return static_cast<std::size_t>(h ^ (h >> 32));
}

}  // namespace

void EndVoxelRays::place(const Slot& slot) {
  const std::size_t mask = slots_.size() - 1;
  std::size_t k = hashOf(slot.x, slot.y, slot.z) & mask;
  while (slots_[k].tag >> 1 == stamp_) k = (k + 1) & mask;
  slots_[k] = slot;
}

void EndVoxelRays::grow() {
  std::vector<Slot> old(std::max<std::size_t>(1024, 2 * slots_.size()), Slot{0, 0, 0, 0, 0});
  old.swap(slots_);
  for (const Slot& slot : old) {
    if (slot.tag >> 1 == stamp_) place(slot);
  }
}

void EndVoxelRays::offerElsewhere(const EndVoxel& voxel, const Eigen::Vector3d& end) {
  last_ = voxel;
  const std::uint32_t tag = stamp_ << 1 | static_cast<std::uint32_t>(voxel.obstacle);
  if (2 * (voxels_.size() + 1) > slots_.size()) grow();
  const std::size_t mask = slots_.size() - 1;
  std::size_t k = hashOf(voxel.x, voxel.y, voxel.z) & mask;
  for (;; k = (k + 1) & mask) {
    const Slot& slot = slots_[k];
    if (slot.tag >> 1 != stamp_) break;
    if (slot.tag == tag && slot.x == voxel.x && slot.y == voxel.y && slot.z == voxel.z) {
      last_index_ = slot.index;
      join(voxels_[last_index_], voxel, end);
      return;
    }
  }
  // A scan holds fewer than 2^32 readings.
  last_index_ = static_cast<std::uint32_t>(voxels_.size());
  slots_[k] = {voxel.x, voxel.y, voxel.z, tag, last_index_};
  voxels_.push_back({{end},
                     end,
                     centreDistance(voxel, end),
                     {voxel.x, voxel.y},
                     static_cast<float>(end.z()),
                     static_cast<float>(end.z()),
                     1,
                     voxel.obstacle});
}

namespace {

/// A scan's readings from its points (Scan): calls hit(p) for each obstacle reading, then
/// out_of_range(p) for each out-of-range reading.
struct ScanReadings {
  const Scan& scan;
  template <class Hit, class OutOfRange>
  void forEach(Hit&& hit, OutOfRange&& out_of_range) const {
    for (const Eigen::Vector3f& p : scan.hits) hit(p);
    for (const Eigen::Vector3f& p : scan.out_of_range) out_of_range(p);
  }
};

/// A scan's readings straight from a depth image's pixels (DepthFrame, validated), the pixels
/// without a measurement counted in `skipped`. They are passed on a batch at a time, from a
/// buffer: GCC 12's SLP vectoriser at -O3 drops a point's rounding to float where it is rounded
/// and widened back at once (its map then differs from its Scan's: test
/// InsertDepthImage.MakesTheMapOfTheImagesReadingsBitForBitWhateverTheThreadsAndOptions).
struct DepthFrameReadings {
  const DepthFrame& frame;
  std::size_t& skipped;
  /// Readings of the frame not yet passed on, and whether each is a hit.
  std::vector<Eigen::Vector3f>& points;
  std::vector<bool>& hits;

  template <class Hit, class OutOfRange>
  void forEach(Hit&& hit, OutOfRange&& out_of_range) const {
    constexpr std::size_t kBatch = 256;  // 3 KB of points, in the first-level cache
    points.clear();
    hits.clear();
    auto pass_on = [&] {
      for (std::size_t k = 0; k < points.size(); ++k) {
        if (hits[k]) {
          hit(points[k]);
        } else {
          out_of_range(points[k]);
        }
      }
      points.clear();
      hits.clear();
    };
    auto keep = [&](const Eigen::Vector3f& p, bool is_hit) {
      points.push_back(p);
      hits.push_back(is_hit);
      if (points.size() == kBatch) pass_on();
    };
    forEachDepthReading(
        frame, [&](const Eigen::Vector3f& p) { keep(p, true); },
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

}  // namespace

GroupedScan groupByEndVoxel(const Scan& scan, const MapConfig& map_config,
                            const InsertionConfig& insertion, EndVoxelRays& voxels,
                            InsertionResult& result) {
  return groupReadings(ScanReadings{scan}, scan.origin, map_config, insertion, voxels, result);
}

GroupedScan groupByEndVoxel(const DepthFrame& frame, const MapConfig& map_config,
                            const InsertionConfig& insertion, EndVoxelRays& voxels,
                            InsertionResult& result) {
  std::size_t skipped = 0;
  std::vector<Eigen::Vector3f> points;
  std::vector<bool> hits;
  const GroupedScan grouped =
      groupReadings(DepthFrameReadings{frame, skipped, points, hits},
                    frame.map_from_camera.translation(), map_config, insertion, voxels, result);
  result.rejected_no_measurement += skipped;
  return grouped;
}

}  // namespace detail
}  // namespace mvog
