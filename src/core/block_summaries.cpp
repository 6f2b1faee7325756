#include "block_summaries.h"

#include <algorithm>

#include "tile_block.h"

namespace mvog {
namespace detail {

void BlockSummaries::clear() {
  tiles_.clear();
  last_ = nullptr;
  map_ = nullptr;
  revision_ = 0;
}

void BlockSummaries::follow(const Map& map) {
  if (&map != map_ || map.revision() < revision_ || tiles_.size() > kMaxTiles) {
    clear();
  } else if (map.revision() != revision_) {
    for (const TileIndex& tile : map.tilesModifiedSince(revision_)) {
      tiles_.erase(tileKey(tile.x, tile.y));
    }
    for (auto it = tiles_.begin(); it != tiles_.end();) {
      const bool removed = it->second.witness && map.column(*it->second.witness).empty();
      it = removed ? tiles_.erase(it) : std::next(it);
    }
  }
  last_ = nullptr;
  map_ = &map;
  revision_ = map.revision();
}

const BlockSummaries::Summary& BlockSummaries::summary(std::int32_t x, std::int32_t y) {
  constexpr std::int32_t kPerTileMask = (1 << kPerTileLog2) - 1;
  const std::uint64_t key = tileKey(x >> kPerTileLog2, y >> kPerTileLog2);
  if (last_ == nullptr || key != last_key_) {  // blocks are mostly asked tile by tile
    last_ = &tiles_[key];
    last_key_ = key;
  }
  const auto local =
      static_cast<unsigned>(((y & kPerTileMask) << kPerTileLog2) | (x & kPerTileMask));
  if (!last_->known[local]) {
    last_->blocks[local] = summarise(x, y);
    last_->known[local] = true;
    if (!last_->blocks[local].free.empty()) {
      last_->witness = CellIndex{x * kBlockSize, y * kBlockSize};
    }
  }
  return last_->blocks[local];
}

BlockSummaries::Summary BlockSummaries::summarise(std::int32_t block_x, std::int32_t block_y) {
  Summary summary;
  std::vector<Extent> kept;
  bool first = true;
  for (std::int32_t y = block_y * kBlockSize; y < (block_y + 1) * kBlockSize; ++y) {
    for (std::int32_t x = block_x * kBlockSize; x < (block_x + 1) * kBlockSize; ++x) {
      stateRuns(map_->column({x, y}), threshold_, scratch_);
      // The free stretches of the first column, cut down to those of the others.
      kept.clear();
      CellFree& cell =
          summary.cells[static_cast<unsigned>(((y & kBlockMask) << kBlockLog2) | (x & kBlockMask))];
      for (const StateRun& run : scratch_.runs) {
        if (run.state == OccupancyState::kFree && cell.count < 2) {
          cell.bottom[cell.count] = run.bottom;
          cell.top[cell.count++] = run.top;
        }
        if (run.state == OccupancyState::kOccupied) {
          if (!summary.occupied) summary.occupied = Extent{run.bottom, run.top};
          summary.occupied->min = std::min<double>(summary.occupied->min, run.bottom);
          summary.occupied->max = std::max<double>(summary.occupied->max, run.top);
        }
        if (run.state != OccupancyState::kFree) continue;
        if (first) kept.push_back({run.bottom, run.top});
        for (const Extent& c : summary.free) {
          const double low = std::max<double>(c.min, run.bottom);
          const double high = std::min<double>(c.max, run.top);
          if (low < high) kept.push_back({low, high});
        }
      }
      summary.free.swap(kept);
      first = false;
    }
  }
  return summary;
}

}  // namespace detail
}  // namespace mvog
