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

void RecentHits::endScan(const std::vector<ScanScratch>& scratches, int scans) {
  ++scans_ended_;
  // A column's hits are oldest first: those out of the window lead.
  auto forget_old = [&](std::vector<Hit>& column) {
    const auto kept = std::find_if(column.begin(), column.end(),
                                   [&](const Hit& hit) { return within(hit.scan, scans); });
    column.erase(column.begin(), kept);
  };
  for (const ScanScratch& scratch : scratches) {
    for (const auto& [key, tile] : scratch.tiles()) {
      if (!tile->hits.empty()) last_scan_of_tile_[key] = scans_ended_;
      const CellIndex origin = tileOrigin(key);
      for (const TileHit& hit : tile->hits) {
        std::vector<Hit>& column = by_column_[cellKey(cellInTile(origin, hit.local))];
        forget_old(column);
        column.push_back({scans_ended_, hit.bottom, hit.top});
      }
    }
  }
  // Every `scans` scans every column: those no scan hits again would keep their old hits.
  if (scans_ended_ - last_purge_ < static_cast<std::uint64_t>(scans)) return;
  last_purge_ = scans_ended_;
  for (auto column = by_column_.begin(); column != by_column_.end();) {
    forget_old(column->second);
    column = column->second.empty() ? by_column_.erase(column) : std::next(column);
  }
  for (auto tile = last_scan_of_tile_.begin(); tile != last_scan_of_tile_.end();) {
    tile = within(tile->second, scans) ? std::next(tile) : last_scan_of_tile_.erase(tile);
  }
}

std::size_t RecentHits::bytes() const {
  // A node of either index holds its next pointer, the key and the value.
  std::size_t bytes =
      sizeof(RecentHits) +
      (by_column_.bucket_count() + last_scan_of_tile_.bucket_count()) * sizeof(void*) +
      by_column_.size() * (2 * sizeof(void*) + sizeof(std::vector<Hit>)) +
      last_scan_of_tile_.size() * (sizeof(void*) + 2 * sizeof(std::uint64_t));
  for (const auto& column : by_column_) bytes += column.second.capacity() * sizeof(Hit);
  return bytes;
}

}  // namespace detail
}  // namespace mvog
