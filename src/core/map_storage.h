// The map's tiles (internal to the core).
#pragma once

#include <cstdint>
#include <unordered_map>

#include "mvog/map.h"
#include "tile_block.h"

namespace mvog {

struct Map::Storage {
  /// By detail::tileKey; no tile is empty.
  std::unordered_map<std::uint64_t, detail::TileBlock> tiles;
};

}  // namespace mvog
