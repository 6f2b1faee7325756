#pragma once

#include <chrono>
#include <memory>

#include "mvog/config.h"
#include "mvog/map.h"

namespace mvog {

struct DepthFrame;

/// The first half of a scan's insertion (Fig. 2): its readings rasterised (Sec. III-B.1) and the
/// new volumes of every column it reaches created (eqs. 3-6), joined per column where they
/// overlap. Map::apply then applies the constraints once to every list the scan modified.
///
/// Preparing reads nothing of a map but its configuration: a caller that shares the map with
/// other threads can prepare a scan outside the map's lock and hold the lock only to apply it.
/// An update keeps its buffers (and threads) from scan to scan: reuse one.
class ScanUpdate {
 public:
  ScanUpdate();
  ~ScanUpdate();
  ScanUpdate(ScanUpdate&&) noexcept;
  ScanUpdate& operator=(ScanUpdate&&) noexcept;
  ScanUpdate(const ScanUpdate&) = delete;
  ScanUpdate& operator=(const ScanUpdate&) = delete;

  /// Rasterises `scan` for a map configured by `map_config`, replacing what the update held.
  /// Every reading is counted once in result(). Throws ConfigError if a config is invalid.
  void prepare(const Scan& scan, const MapConfig& map_config, const InsertionConfig& insertion);
  /// Rasterises the depth image of `frame` straight from its pixels, as prepare() would a Scan
  /// of them (backProjectDepthImage): the same readings, the same map. With one ray per end
  /// voxel or one path per end column (FreeSpaceRays, per-scan masses) no Scan is made; the pixels
  /// without a measurement are counted in result().rejected_no_measurement. Throws ConfigError
  /// if a config, the image or the camera is invalid.
  void prepare(const DepthFrame& frame, const MapConfig& map_config,
               const InsertionConfig& insertion);
  /// What happened to the readings of the scan last prepared.
  const InsertionResult& result() const;
  /// Whether the scan last prepared can be applied to a map of `map_config` (same resolution,
  /// max_coordinate and rules).
  bool preparedFor(const MapConfig& map_config) const;

 private:
  friend class Map;
  /// Validates the configs and readies the update's buffers for a scan.
  void begin(const MapConfig& map_config, const InsertionConfig& insertion);
  /// The hits and rays of the scan's end voxels (grouped since `grouping_began`), from `origin`,
  /// into the scratches (FreeSpaceRays::kOnePerEndVoxel or kOnePathPerEndColumn); `cells` and
  /// `level` as detail::GroupedScan.
  void walkEndVoxels(const Eigen::Vector3d& origin, const CellRange& cells, bool level,
                     std::chrono::steady_clock::time_point grouping_began);
  /// Every reading's ray walked.
  void prepareEveryReading(const Scan& scan);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mvog
