// What blocks of cells hold, summed up (internal to the core): what lets the segment checks
// (mvog/checks.h) pass open and unknown space without looking at each column.
#pragma once

#include <array>
#include <bitset>
#include <cstdint>
#include <optional>
#include <unordered_map>
#include <vector>

#include "capsule.h"
#include "column_runs.h"
#include "mvog/map.h"

namespace mvog {
namespace detail {

/// Per block of 4 x 4 cells of a map, the heights over which every cell of the block is known
/// and free, and those over which some cell is occupied; found when first asked and kept until
/// the block's tile changes.
class BlockSummaries {
 public:
  static constexpr int kBlockLog2 = 2;
  static constexpr std::int32_t kBlockSize = 1 << kBlockLog2;

  explicit BlockSummaries(double threshold) : threshold_(threshold) {}

  /// Makes the blocks those of `map`: forgets the tiles that changed since the previous call, or
  /// everything for another map, an older one (revisions start again) or when more than
  /// kMaxTiles tiles are kept.
  void follow(const Map& map);
  void clear();

  /// Whether every height of [low, high] (grid units) lies strictly within the free space of
  /// every cell of block (x, y) of the map followed (strictly: the face where a free stretch
  /// meets another one belongs to both, see checkSegments).
  bool freeOver(std::int32_t x, std::int32_t y, double low, double high) {
    for (const Extent& free : summary(x, y).free) {
      if (free.min < low && high < free.max) return true;
    }
    return false;
  }
  /// The same for one cell: whether [low, high] lies strictly within one of the cell's two
  /// lowest free stretches (false tells nothing).
  bool cellFreeOver(const CellIndex& cell, double low, double high) {
    const CellFree& free = summary(cell.x >> kBlockLog2, cell.y >> kBlockLog2)
                               .cells[static_cast<unsigned>(((cell.y & kBlockMask) << kBlockLog2) |
                                                            (cell.x & kBlockMask))];
    for (int k = 0; k < free.count; ++k) {
      if (free.bottom[k] < low && high < free.top[k]) return true;
    }
    return false;
  }
  /// Whether some cell of block (x, y) may be occupied at some height of [low, high] (false: no
  /// cell is).
  bool mayBeOccupiedOver(std::int32_t x, std::int32_t y, double low, double high) {
    const std::optional<Extent>& occupied = summary(x, y).occupied;
    return occupied && occupied->min <= high && occupied->max >= low;
  }

 private:
  static constexpr std::int32_t kBlockMask = kBlockSize - 1;
  static constexpr int kPerTileLog2 = Map::kTileSizeLog2 - kBlockLog2;  // blocks along an edge
  static constexpr std::size_t kBlocksPerTile = std::size_t{1} << (2 * kPerTileLog2);
  /// Some 6 kB each: at most some 25 MB kept from call to call.
  static constexpr std::size_t kMaxTiles = std::size_t{1} << 12;

  /// A cell's two lowest free stretches.
  struct CellFree {
    float bottom[2];
    float top[2];
    int count = 0;
  };
  struct Summary {
    std::vector<Extent> free;        ///< heights where every cell is free, the faces excluded
    std::optional<Extent> occupied;  ///< from the lowest to the highest occupied height of a cell
    std::array<CellFree, std::size_t{kBlockSize} * kBlockSize> cells;  ///< row by row
  };
  /// The blocks of one tile.
  struct TileBlocks {
    std::bitset<kBlocksPerTile> known;
    std::array<Summary, kBlocksPerTile> blocks;
    /// A cell holding volumes, if some block is free at some height: a tile the map removed
    /// (tilesModifiedSince does not list it) is found by this cell being empty.
    std::optional<CellIndex> witness;
  };

  const Summary& summary(std::int32_t x, std::int32_t y);
  Summary summarise(std::int32_t block_x, std::int32_t block_y);

  const double threshold_;
  const Map* map_ = nullptr;
  std::uint64_t revision_ = 0;
  ColumnScratch scratch_;
  std::unordered_map<std::uint64_t, TileBlocks> tiles_;  // by tile
  std::uint64_t last_key_ = 0;
  TileBlocks* last_ = nullptr;  // the tile asked last (the map's nodes stay put)
};

}  // namespace detail
}  // namespace mvog
