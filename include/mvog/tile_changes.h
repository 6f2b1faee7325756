#pragma once

#include <cstdint>
#include <map>
#include <utility>
#include <vector>

#include "mvog/map.h"

namespace mvog {

/// The tiles of a map that changed from one call to the next, for results kept tile by tile.
///
/// Map::tilesModifiedSince lists the tiles that hold volumes and changed; a tile the map no
/// longer holds (all its cells emptied by setCellVolumes, or the map cleared) is not listed
/// there. TileChanges lists those too: it keeps one cell holding volumes of every tile seen, and a
/// tile whose cell is now empty without being listed as modified is gone.
class TileChanges {
 public:
  /// The tiles whose cells changed since the previous call (on the first call, and after reset()
  /// or when `map` is older than the map of the previous call, every tile holding volumes and
  /// every tile seen before), by rows of tiles from the lowest. After the map is replaced by
  /// another one, call reset(): revisions of two maps say nothing about each other.
  std::vector<TileIndex> update(const Map& map);
  void reset();

 private:
  std::uint64_t revision_ = 0;
  /// By (y, x) of the tile: a cell of the tile that held volumes at the previous call.
  std::map<std::pair<std::int32_t, std::int32_t>, CellIndex> witnesses_;
};

/// The tiles given and their four neighbours, each once, by rows of tiles from the lowest: the
/// tiles whose results change with those given, for results that look at a cell's four
/// neighbours.
std::vector<TileIndex> withNeighbourTiles(const std::vector<TileIndex>& tiles);

/// Results kept tile by tile (frontiers, surfaces): an update recomputes only the tiles of the map
/// that changed since the previous one.
template <class Item>
class TileResults {
 public:
  /// Recomputes the tiles of `map` that changed since the previous update (TileChanges), and with
  /// `with_neighbours` their four neighbours too: compute(tile, items) fills `items` (given empty)
  /// with a tile's results. Returns the number of tiles recomputed.
  template <class Compute>
  std::size_t update(const Map& map, bool with_neighbours, Compute&& compute) {
    std::vector<TileIndex> tiles = changes_.update(map);
    if (with_neighbours) tiles = withNeighbourTiles(tiles);
    for (const TileIndex& tile : tiles) {
      std::vector<Item>& items = by_tile_[{tile.y, tile.x}];
      items.clear();
      compute(tile, items);
      if (items.empty()) by_tile_.erase({tile.y, tile.x});
    }
    return tiles.size();
  }
  /// Forgets every result: the next update computes every tile (for a map replaced by another).
  void clear() {
    changes_.reset();
    by_tile_.clear();
  }
  /// Every result, by rows of tiles from the lowest.
  std::vector<Item> all() const {
    std::vector<Item> result;
    for (const auto& entry : by_tile_) {
      result.insert(result.end(), entry.second.begin(), entry.second.end());
    }
    return result;
  }

 private:
  TileChanges changes_;
  /// By (y, x) of the tile: rows of tiles from the lowest.
  std::map<std::pair<std::int32_t, std::int32_t>, std::vector<Item>> by_tile_;
};

}  // namespace mvog
