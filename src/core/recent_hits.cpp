#include "recent_hits.h"

#include <algorithm>

namespace mvog {
namespace detail {

bool RecentHits::holdsTile(std::uint64_t tile_key, int scans) const {
  const auto tile = last_scan_of_tile_.find(tile_key);
  return tile != last_scan_of_tile_.end() && within(tile->second, scans);
}

void RecentHits::append(std::uint64_t cell_key, int scans, std::vector<ScanInterval>& out) const {
  const auto column = by_column_.find(cell_key);
  if (column == by_column_.end()) return;
  for (const Hit& hit : column->second) {
    if (within(hit.scan, scans)) out.push_back({hit.bottom, hit.top, 0.0});
  }
}

void RecentHits::forgetOld(std::vector<Hit>& column, int scans) const {
  column.erase(std::remove_if(column.begin(), column.end(),
                              [&](const Hit& hit) { return !within(hit.scan, scans); }),
               column.end());
}

void RecentHits::endScan(const std::vector<ScanScratch>& scratches, int scans) {
  ++scans_ended_;
  if (scans == 0) {
    by_column_.clear();
    last_scan_of_tile_.clear();
    return;
  }
  for (const ScanScratch& scratch : scratches) {
    for (const auto& [key, tile] : scratch.tiles()) {
      if (!tile->hits.empty()) last_scan_of_tile_[key] = scans_ended_;
      const CellIndex origin = tileOrigin(key);
      for (const TileHit& hit : tile->hits) {
        std::vector<Hit>& column = by_column_[cellKey(cellInTile(origin, hit.local))];
        forgetOld(column, scans);
        column.push_back({scans_ended_, hit.bottom, hit.top});
      }
    }
  }
  // Now and then every column: those no scan hits again would keep their old hits.
  if (scans_ended_ % static_cast<std::uint64_t>(scans) == 0) {
    for (auto column = by_column_.begin(); column != by_column_.end();) {
      forgetOld(column->second, scans);
      column = column->second.empty() ? by_column_.erase(column) : std::next(column);
    }
    for (auto tile = last_scan_of_tile_.begin(); tile != last_scan_of_tile_.end();) {
      tile = within(tile->second, scans) ? std::next(tile) : last_scan_of_tile_.erase(tile);
    }
  }
}

}  // namespace detail
}  // namespace mvog
