#pragma once

#include <memory>

#include "mvog/config.h"
#include "mvog/map.h"

namespace mvog {

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
  /// What happened to the readings of the scan last prepared.
  const InsertionResult& result() const;
  /// Whether the scan last prepared can be applied to a map of `map_config` (same resolution,
  /// max_coordinate and rules).
  bool preparedFor(const MapConfig& map_config) const;

 private:
  friend class Map;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mvog
