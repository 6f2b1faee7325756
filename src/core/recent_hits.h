#pragma once

#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "scan_scratch.h"

namespace mvog {
namespace detail {

/// The hits of a map's latest scans, by column (InsertionConfig::hit_memory_scans): Sec. V.B's
/// scan groups, a scan's free space clipped around its predecessors' hits as around its own.
class RecentHits {
 public:
  /// Whether tile `tile_key` (tileKey) holds a hit of the last `scans` scans.
  bool holdsTile(std::uint64_t tile_key, int scans) const;
  /// Appends the hits of column `cell_key` (cellKey) in the last `scans` scans to `out` (grid
  /// units).
  void append(std::uint64_t cell_key, int scans, std::vector<ScanInterval>& out) const;
  /// Ends a scan: the hits of `scratches` are kept while `scans` (at least 1) more scans are
  /// inserted.
  void endScan(const std::vector<ScanScratch>& scratches, int scans);
  /// The bytes held (Map::memoryUsage).
  std::size_t bytes() const;

 private:
  struct Hit {
    std::uint64_t scan;
    float bottom;
    float top;
  };
  /// Whether scan `scan` is one of the last `scans` scans.
  bool within(std::uint64_t scan, int scans) const {
    return scan + static_cast<std::uint64_t>(scans) > scans_ended_;
  }

  /// Each column's hits, oldest first.
  std::unordered_map<std::uint64_t, std::vector<Hit>> by_column_;
  /// The last scan with a hit in each tile (Map::apply's shortcut passes the others).
  std::unordered_map<std::uint64_t, std::uint64_t> last_scan_of_tile_;
  std::uint64_t scans_ended_ = 0;
  std::uint64_t last_purge_ = 0;  ///< scans_ended_ when every column was last purged
};

}  // namespace detail
}  // namespace mvog
