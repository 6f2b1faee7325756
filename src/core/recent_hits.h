#pragma once

#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "scan_scratch.h"

namespace mvog {
namespace detail {

/// A tile's hits kept by RecentHits, oldest first, and a bit per cell (cellIndexInTile) set where
/// the cell may hold one (a cell whose hits aged out keeps its bit until the next purge).
struct RecentTileHits {
  struct Hit {
    /// The scan's number, modulo 2^32: a hit is purged within 2 windows of at most
    /// kMaxHitMemoryScans scans, long before the count wraps round to it.
    std::uint32_t scan;
    float bottom;
    float top;
    std::uint16_t local;  ///< the cell in its tile (cellIndexInTile)
  };
  std::vector<Hit> hits;
  std::uint64_t cells[kCellsPerTile / 64] = {};
  bool mayHold(unsigned local) const { return ((cells[local / 64] >> (local % 64)) & 1) != 0; }
};

/// The hits of a map's latest scans, by tile (InsertionConfig::hit_memory_scans): Sec. V.B's
/// scan groups, a scan's free space clipped around its predecessors' hits as around its own.
class RecentHits {
 public:
  using Tile = RecentTileHits;
  using Hit = RecentTileHits::Hit;

  /// The hits tile `tile_key` (tileKey) keeps of the last `scans` scans, or null where it keeps
  /// none.
  const Tile* tile(std::uint64_t tile_key, int scans) const;
  /// Appends the hits of cell `local` of `tile` in the last `scans` scans to `out` (grid units).
  void append(const Tile& tile, unsigned local, int scans, std::vector<ScanInterval>& out) const;
  /// Ends a scan: the hits of `scratches` are kept while `scans` (at least 1) more scans are
  /// inserted.
  void endScan(const std::vector<ScanScratch>& scratches, int scans);
  /// The bytes held (Map::memoryUsage).
  std::size_t bytes() const;

 private:
  /// Whether scan `scan` is one of the last `scans` scans.
  bool within(std::uint32_t scan, int scans) const {
    return static_cast<std::uint32_t>(scans_ended_) - scan < static_cast<std::uint32_t>(scans);
  }

  std::unordered_map<std::uint64_t, Tile> tiles_;
  std::uint64_t scans_ended_ = 0;
  std::uint64_t last_purge_ = 0;  ///< scans_ended_ when every tile was last purged
};

}  // namespace detail
}  // namespace mvog
