#include "recent_hits.h"

#include <algorithm>

namespace mvog {
namespace detail {

const RecentHits::Tile* RecentHits::tile(std::uint64_t tile_key, int scans) const {
  const auto tile = tiles_.find(tile_key);
  return tile != tiles_.end() && !tile->second.hits.empty() &&
                 within(tile->second.hits.back().scan, scans)
             ? &tile->second
             : nullptr;
}

void RecentHits::append(const Tile& tile, unsigned local, int scans,
                        std::vector<ScanInterval>& out) const {
  for (const Hit& hit : tile.hits) {
    if (hit.local == local && within(hit.scan, scans)) out.push_back({hit.bottom, hit.top, 0.0});
  }
}

void RecentHits::endScan(const std::vector<ScanScratch>& scratches, int scans) {
  ++scans_ended_;
  // A tile's hits are oldest first: those out of the window lead. Its cells' bits are made anew
  // from those left.
  auto forget_old = [&](Tile& tile) {
    const auto kept = std::find_if(tile.hits.begin(), tile.hits.end(),
                                   [&](const Hit& hit) { return within(hit.scan, scans); });
    tile.hits.erase(tile.hits.begin(), kept);
    std::fill(std::begin(tile.cells), std::end(tile.cells), std::uint64_t{0});
    for (const Hit& hit : tile.hits)
      tile.cells[hit.local / 64] |= std::uint64_t{1} << (hit.local % 64);
  };
  for (const ScanScratch& scratch : scratches) {
    for (const auto& [key, scratch_tile] : scratch.tiles()) {
      if (scratch_tile->hits.empty()) continue;
      Tile& tile = tiles_[key];
      if (!tile.hits.empty() && !within(tile.hits.front().scan, scans)) forget_old(tile);
      for (const TileHit& hit : scratch_tile->hits) {
        tile.hits.push_back(
            {static_cast<std::uint32_t>(scans_ended_), hit.bottom, hit.top, hit.local});
        tile.cells[hit.local / 64] |= std::uint64_t{1} << (hit.local % 64);
      }
    }
  }
  // Every `scans` scans every tile: those no scan hits again would keep their old hits.
  if (scans_ended_ - last_purge_ < static_cast<std::uint64_t>(scans)) return;
  last_purge_ = scans_ended_;
  for (auto tile = tiles_.begin(); tile != tiles_.end();) {
    forget_old(tile->second);
    tile = tile->second.hits.empty() ? tiles_.erase(tile) : std::next(tile);
  }
}

std::size_t RecentHits::bytes() const {
  // A node of the index holds its next pointer, the key and the tile.
  std::size_t bytes = sizeof(RecentHits) + tiles_.bucket_count() * sizeof(void*) +
                      tiles_.size() * (sizeof(void*) + sizeof(std::uint64_t) + sizeof(Tile));
  for (const auto& tile : tiles_) bytes += tile.second.hits.capacity() * sizeof(Hit);
  return bytes;
}

}  // namespace detail
}  // namespace mvog
