#pragma once

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
  /// Appends the hits of column `cell_key` in the last `scans` scans to `out` (grid units).
  void append(std::uint64_t cell_key, int scans, std::vector<ScanInterval>& out) const;
  /// Ends a scan: the hits of `scratches` are kept while `scans` more scans are inserted (none
  /// for 0: every hit kept is forgotten).
  void endScan(const std::vector<ScanScratch>& scratches, int scans);

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
  /// Forgets the hits of `column` older than the last `scans` scans.
  void forgetOld(std::vector<Hit>& column, int scans) const;

  std::unordered_map<std::uint64_t, std::vector<Hit>> by_column_;
  /// The last scan with a hit in each tile (Map::apply's fast path passes the others).
  std::unordered_map<std::uint64_t, std::uint64_t> last_scan_of_tile_;
  std::uint64_t scans_ended_ = 0;
};

}  // namespace detail
}  // namespace mvog
