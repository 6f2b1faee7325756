#include "mvog/tile_changes.h"

#include <algorithm>

namespace mvog {
namespace {

using TileKey = std::pair<std::int32_t, std::int32_t>;  // (y, x): rows of tiles from the lowest

TileKey keyOf(const TileIndex& tile) { return {tile.y, tile.x}; }
TileIndex tileOfKey(const TileKey& key) { return {key.second, key.first}; }

std::vector<TileIndex> sortedUnique(std::vector<TileKey> keys) {
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  std::vector<TileIndex> tiles;
  tiles.reserve(keys.size());
  for (const TileKey& key : keys) tiles.push_back(tileOfKey(key));
  return tiles;
}

}  // namespace

std::vector<TileIndex> TileChanges::update(const Map& map) {
  if (map.revision() < revision_) reset();  // another map
  std::vector<TileKey> changed;
  if (revision_ == 0) {  // everything seen before counts as changed (possibly gone)
    for (const auto& entry : witnesses_) changed.push_back(entry.first);
  }
  std::vector<TileKey> modified;
  for (const TileIndex& tile : map.tilesModifiedSince(revision_)) modified.push_back(keyOf(tile));
  std::sort(modified.begin(), modified.end());
  // Tiles not modified whose cell holding volumes is empty now: removed from the map.
  for (auto it = witnesses_.begin(); it != witnesses_.end();) {
    if (!std::binary_search(modified.begin(), modified.end(), it->first) &&
        map.column(it->second).empty()) {
      changed.push_back(it->first);
      it = witnesses_.erase(it);
    } else {
      ++it;
    }
  }
  for (const TileKey& key : modified) {
    changed.push_back(key);
    const CellRange cells = Map::tileCells(tileOfKey(key));
    witnesses_.erase(key);
    for (std::int32_t y = cells.min.y; y <= cells.max.y && !witnesses_.count(key); ++y) {
      for (std::int32_t x = cells.min.x; x <= cells.max.x; ++x) {
        if (!map.column({x, y}).empty()) {
          witnesses_[key] = {x, y};
          break;
        }
      }
    }
  }
  revision_ = map.revision();
  return sortedUnique(std::move(changed));
}

void TileChanges::reset() { revision_ = 0; }

std::vector<TileIndex> withNeighbourTiles(const std::vector<TileIndex>& tiles) {
  std::vector<TileKey> keys;
  keys.reserve(5 * tiles.size());
  for (const TileIndex& tile : tiles) {
    for (const TileIndex& t : {tile, TileIndex{tile.x - 1, tile.y}, TileIndex{tile.x + 1, tile.y},
                               TileIndex{tile.x, tile.y - 1}, TileIndex{tile.x, tile.y + 1}}) {
      keys.push_back(keyOf(t));
    }
  }
  return sortedUnique(std::move(keys));
}

}  // namespace mvog
