// The storage of one tile of the map (internal to the core): the two volume lists of every cell
// of a 16 x 16 block of cells, in one heap block.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "mvog/cell_index.h"
#include "mvog/volume.h"

/// Compiles the function it marks twice, for the build's x86-64 level and for CPUs with the
/// popcnt instruction (nearly every x86-64 CPU since 2008), and lets the loader pick one (GCC's
/// and clang's function multiversioning). For the loops that find many columns by their rank in a
/// tile's bitmap (bitCount), where the instruction replaces a dozen. Not under ThreadSanitizer:
/// the loader runs the clones' resolver before the sanitizer's runtime is up, and its
/// instrumented code crashes there.
#if defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define MVOG_THREAD_SANITIZER 1
#endif
#endif
#if defined(__SANITIZE_THREAD__)
#define MVOG_THREAD_SANITIZER 1
#endif
#if defined(__x86_64__) && !defined(__POPCNT__) && !defined(MVOG_THREAD_SANITIZER) && \
    (defined(__GNUC__) || defined(__clang__))
#define MVOG_ALSO_FOR_POPCNT __attribute__((target_clones("popcnt", "default")))
#else
#define MVOG_ALSO_FOR_POPCNT
#endif

namespace mvog {
namespace detail {

constexpr int kTileSizeLog2 = 4;
constexpr int kTileSize = 1 << kTileSizeLog2;  ///< cells per tile edge
constexpr int kCellsPerTile = kTileSize * kTileSize;

/// The index of a cell within its tile: row-major, rows along +x.
inline unsigned localIndex(const CellIndex& c) {
  constexpr std::int32_t kMask = kTileSize - 1;
  return static_cast<unsigned>((c.y & kMask) * kTileSize + (c.x & kMask));
}

/// The cell of local index `local` in the tile whose first cell is `origin` (localIndex's
/// inverse).
inline CellIndex cellInTile(const CellIndex& origin, unsigned local) {
  return {origin.x + static_cast<std::int32_t>(local % kTileSize),
          origin.y + static_cast<std::int32_t>(local / kTileSize)};
}

/// The index of the lowest set bit of bits != 0 (bsf: on every x86-64, unlike popcnt).
inline unsigned lowestBit(std::uint64_t bits) {
  return static_cast<unsigned>(__builtin_ctzll(bits));
}

/// A tile (x, y) as one hash key, and back: the only place tile keys are packed and unpacked.
inline std::uint64_t tileKey(std::int32_t tile_x, std::int32_t tile_y) {
  return (std::uint64_t{static_cast<std::uint32_t>(tile_x)} << 32) |
         static_cast<std::uint32_t>(tile_y);
}
inline std::int32_t tileKeyX(std::uint64_t key) { return static_cast<std::int32_t>(key >> 32); }
inline std::int32_t tileKeyY(std::uint64_t key) { return static_cast<std::int32_t>(key); }
/// A cell (x, y) as one hash key, packed as a tile's.
inline std::uint64_t cellKey(const CellIndex& c) { return tileKey(c.x, c.y); }
inline std::uint64_t tileKeyOf(const CellIndex& c) {
  return tileKey(c.x >> kTileSizeLog2, c.y >> kTileSizeLog2);  // arithmetic shifts floor
}
/// The order of tiles in listings and files: by (y, x) as signed numbers, rows from the lowest.
inline bool rowMajorBefore(std::uint64_t a, std::uint64_t b) {
  const std::int32_t ay = tileKeyY(a), by = tileKeyY(b);
  return ay != by ? ay < by : tileKeyX(a) < tileKeyX(b);
}
inline CellIndex tileOrigin(std::uint64_t key) {
  return {tileKeyX(key) * kTileSize, tileKeyY(key) * kTileSize};
}
/// "cell (x, y)" and "tile (x, y)", as error messages name them.
std::string cellName(const CellIndex& cell);
std::string tileName(std::uint64_t key);

/// A cell's two lists, as stored (masses in the tile's unit).
struct ColumnRef {
  const Volume* positive = nullptr;
  std::uint32_t num_positive = 0;
  const Volume* negative = nullptr;
  std::uint32_t num_negative = 0;
  bool empty() const { return num_positive + num_negative == 0; }
};

/// One tile: [header | starts | positive counts | volumes] in a single allocation. Only the
/// cells holding a volume have an entry (found by the rank of their bit in the header's
/// bitmap), so an unobserved cell costs one bit: a 2D laser map fills its tiles in a thin band.
/// A cell's volumes are its positive list, then its negative list. Starts and positive counts
/// are 16 and 8 bits wide, or 32 bits in the rare tile whose volumes need it.
class TileBlock {
 public:
  TileBlock() = default;
  ~TileBlock();
  TileBlock(TileBlock&& other) noexcept : block_(other.block_) { other.block_ = nullptr; }
  TileBlock& operator=(TileBlock&& other) noexcept;
  TileBlock(const TileBlock&) = delete;
  TileBlock& operator=(const TileBlock&) = delete;

  bool empty() const { return block_ == nullptr; }
  /// The lists of cell `local` (empty for a cell without volumes).
  ColumnRef column(unsigned local) const;
  /// The lists of the cell of the given rank among those holding volumes (in local order).
  ColumnRef columnAtRank(unsigned rank) const;
  /// A tile's layout (its bitmap, entries and volumes), copied from its header once: for a loop
  /// that finds the lists of many of its cells (Map::apply's update of a tile), instead of reading
  /// them through the tile's block at each cell, and again past each call. Valid while the tile's
  /// block is and no cell's lists change length (their volumes may change in place).
  class Layout {
   public:
    explicit Layout(const TileBlock& tile);
    /// TileBlock::column.
    ColumnRef column(unsigned local) const;

   private:
    std::uint64_t occupied_[kCellsPerTile / 64] = {};  // all clear for an empty tile
    unsigned words_before_[kCellsPerTile / 64] = {};   // cells holding volumes before word k
    const unsigned char* starts_ = nullptr;
    const unsigned char* positive_counts_ = nullptr;
    const Volume* volumes_ = nullptr;
    bool wide_ = false;
  };

  bool holds(unsigned local) const {
    return block_ != nullptr && ((block_->occupied[local >> 6] >> (local & 63)) & 1u) != 0;
  }
  std::size_t bytes() const;
  std::uint32_t numCells() const { return block_ == nullptr ? 0 : block_->num_cells; }
  std::uint32_t numVolumes() const { return block_ == nullptr ? 0 : block_->num_volumes; }
  /// Positive volumes of the whole tile.
  std::uint32_t numPositive() const;

  /// The map's mass exponent when the tile was written (see Map::decay).
  std::int32_t exponent() const { return block_ == nullptr ? 0 : block_->exponent; }
  /// The map revision at which a volume of the tile last changed. Whoever changes volumes in place
  /// sets it afterwards, which also forgets cachedLightestMass.
  std::uint64_t modifiedRevision() const {
    return block_ == nullptr ? 0 : block_->modified_revision;
  }
  void setModifiedRevision(std::uint64_t revision) {
    if (block_ == nullptr) return;
    block_->modified_revision = revision;
    block_->lightest_mass = kUnknownMass;
  }
  /// Multiplies every mass by `factor` and takes `exponent` (after a decay step, Map::decay).
  void scaleMasses(double factor, std::int32_t exponent);
  /// What Map::forget last found to be the tile's lightest mass (stored unit), NaN if the tile
  /// changed since: a tile whose lightest mass is above the threshold is skipped without a look
  /// at its volumes.
  float cachedLightestMass() const {
    return block_ == nullptr ? kUnknownMass : block_->lightest_mass;
  }
  void cacheLightestMass(float mass) {
    if (block_ != nullptr) block_->lightest_mass = mass;
  }
  /// The cells holding volumes, in tile-local coordinates (0 to kTileSize - 1); empty if none.
  CellRange heldCells() const;
  /// Moves the exponent by -offset, clamped so it stays within 32 bits (Map::decay's rebase).
  void rebaseExponent(std::int64_t offset, std::int64_t max_lag);

  /// Builds tiles: add the cells that hold volumes in increasing local index, then finish().
  class Builder {
   public:
    /// Appends a cell; its masses are multiplied by `mass_scale` (a power of two, or 1).
    void add(unsigned local, const ColumnRef& column, double mass_scale);
    void add(unsigned local, const std::vector<Volume>& positive,
             const std::vector<Volume>& negative);
    /// Appends the cells of `tile` with local indices in [first, end), as they are: their
    /// volumes copied in one run.
    void addUnchanged(const TileBlock& tile, unsigned first, unsigned end);
    /// The tile of the cells added (empty if none), which the builder then forgets.
    TileBlock finish(std::int32_t exponent, std::uint64_t modified_revision);
    /// Forgets the cells added, keeping its buffers' capacity.
    void clear();

   private:
    std::vector<std::uint16_t> locals_;
    std::vector<std::uint32_t> starts_;
    std::vector<std::uint32_t> num_positive_;
    std::vector<Volume> volumes_;
  };

  /// New lists for some cells of a tile, gathered cell by cell, then the tile built anew with
  /// them and its other cells copied.
  class Rewrite {
   public:
    /// Forgets every cell set (and what an apply() that threw left in its builder).
    void clear();
    /// The new lists of cell `local` (both empty: the cell goes), in increasing local index.
    void set(unsigned local, const ColumnRef& lists);
    void set(unsigned local, const std::vector<Volume>& positive,
             const std::vector<Volume>& negative) {
      set(local, {positive.data(), static_cast<std::uint32_t>(positive.size()), negative.data(),
                  static_cast<std::uint32_t>(negative.size())});
    }
    bool empty() const { return cells_.empty(); }
    /// `tile` with the cells set replaced (empty if no cell is left).
    TileBlock apply(const TileBlock& tile, std::int32_t exponent, std::uint64_t modified_revision);

   private:
    /// Cell `local`'s new lists: volumes_[start, start + num_positive), then its negative ones.
    struct Cell {
      unsigned local;
      std::size_t start;
      std::uint32_t num_positive;
      std::uint32_t num_negative;
    };
    /// apply() for the tiles whose old and new entries are narrow (nearly all): one pass that
    /// writes the new tile, runs of unchanged cells copied whole. Empty, for the builder to do,
    /// if the old tile or the new one is wide, or if no cell is left.
    TileBlock applyNarrow(const TileBlock& tile, std::int32_t exponent,
                          std::uint64_t modified_revision) const;

    std::vector<Cell> cells_;
    std::vector<Volume> volumes_;
    Builder builder_;
  };

 private:
  struct Header {
    std::uint64_t occupied[kCellsPerTile / 64];  // bit k: cell k holds a volume
    std::uint64_t modified_revision;
    std::int32_t exponent;
    std::uint32_t num_volumes;
    std::uint16_t num_cells;
    std::uint16_t volumes_offset;  // bytes from the block's start to its volumes
    std::uint8_t wide;             // 32-bit starts and positive counts
    /// Cells holding volumes in the bitmap's words before words 1, 2 and 3: a rank is then one
    /// word's count.
    std::uint8_t words_before[kCellsPerTile / 64 - 1];
    float lightest_mass;  // see cachedLightestMass
  };
  static_assert(sizeof(Header) == 64, "the header fills one cache line");
  static constexpr float kUnknownMass = std::numeric_limits<float>::quiet_NaN();
  /// The number of cells holding volumes before cell `local` (its rank among them if it holds
  /// some).
  unsigned rank(unsigned local) const;
  std::uint32_t start(unsigned rank) const;
  std::uint32_t positiveCount(unsigned rank) const;
  const Volume* volumes() const;
  /// The entries: starts (num_cells + 1, 16 or 32 bits), then positive counts (8 or 32 bits).
  const unsigned char* starts() const;
  const unsigned char* positiveCounts() const;
  // The layout's reads, on values read from the header: by the members above at each call, by
  // Layout once.
  static unsigned rankIn(std::uint64_t word, unsigned words_before, unsigned local);
  static std::uint32_t startAt(const unsigned char* starts, bool wide, unsigned rank);
  static std::uint32_t positiveCountAt(const unsigned char* positive_counts, bool wide,
                                       unsigned rank);
  static ColumnRef columnIn(const Volume* volumes, const unsigned char* starts,
                            const unsigned char* positive_counts, bool wide, unsigned rank);
  static std::size_t volumesOffset(std::uint32_t num_cells, bool wide);
  /// A tile of `num_cells` cells and `num_volumes` volumes, its header written with an empty
  /// bitmap: the caller sets the bitmap, then calls countWordsBefore, and writes the entries and
  /// volumes.
  static TileBlock allocate(std::uint32_t num_cells, std::uint32_t num_volumes, bool wide,
                            std::int32_t exponent, std::uint64_t modified_revision);
  void countWordsBefore();

  Header* block_ = nullptr;
};

// The accessors of every query and insertion, inline.

/// Bits set in x, without a library call (the build targets no particular x86 level, where
/// __builtin_popcountll calls libgcc). GCC and clang recognise this form: compiled for a CPU with
/// popcnt, it is that one instruction (see MVOG_ALSO_FOR_POPCNT).
inline unsigned bitCount(std::uint64_t x) {
  x = x - ((x >> 1) & 0x5555555555555555ull);
  x = (x & 0x3333333333333333ull) + ((x >> 2) & 0x3333333333333333ull);
  x = (x + (x >> 4)) & 0x0f0f0f0f0f0f0f0full;
  return static_cast<unsigned>((x * 0x0101010101010101ull) >> 56);
}

inline unsigned TileBlock::rankIn(std::uint64_t word, unsigned words_before, unsigned local) {
  return words_before + bitCount(word & ((std::uint64_t{1} << (local & 63)) - 1));
}

inline std::uint32_t TileBlock::startAt(const unsigned char* starts, bool wide, unsigned rank) {
  if (wide) {
    std::uint32_t value;
    std::memcpy(&value, starts + 4 * std::size_t{rank}, 4);
    return value;
  }
  std::uint16_t value;
  std::memcpy(&value, starts + 2 * std::size_t{rank}, 2);
  return value;
}

inline std::uint32_t TileBlock::positiveCountAt(const unsigned char* positive_counts, bool wide,
                                                unsigned rank) {
  if (wide) {
    std::uint32_t value;
    std::memcpy(&value, positive_counts + 4 * std::size_t{rank}, 4);
    return value;
  }
  return positive_counts[rank];
}

inline ColumnRef TileBlock::columnIn(const Volume* volumes, const unsigned char* starts,
                                     const unsigned char* positive_counts, bool wide,
                                     unsigned rank) {
  const std::uint32_t first = startAt(starts, wide, rank);
  const std::uint32_t end = startAt(starts, wide, rank + 1);
  const std::uint32_t num_positive = positiveCountAt(positive_counts, wide, rank);
  const Volume* list = volumes + first;
  return {list, num_positive, list + num_positive, end - first - num_positive};
}

inline const unsigned char* TileBlock::starts() const {
  return reinterpret_cast<const unsigned char*>(block_ + 1);
}

inline const unsigned char* TileBlock::positiveCounts() const {
  return starts() + (block_->wide != 0 ? 4 : 2) * (std::size_t{block_->num_cells} + 1);
}

inline unsigned TileBlock::rank(unsigned local) const {
  const unsigned word = local >> 6;
  return rankIn(block_->occupied[word], word == 0 ? 0u : block_->words_before[word - 1], local);
}

inline std::uint32_t TileBlock::start(unsigned rank) const {
  return startAt(starts(), block_->wide != 0, rank);
}

inline std::uint32_t TileBlock::positiveCount(unsigned rank) const {
  return positiveCountAt(positiveCounts(), block_->wide != 0, rank);
}

inline const Volume* TileBlock::volumes() const {
  return reinterpret_cast<const Volume*>(reinterpret_cast<const unsigned char*>(block_) +
                                         block_->volumes_offset);
}

inline ColumnRef TileBlock::column(unsigned local) const {
  if (!holds(local)) return {};
  return columnAtRank(rank(local));
}

inline ColumnRef TileBlock::columnAtRank(unsigned r) const {
  return columnIn(volumes(), starts(), positiveCounts(), block_->wide != 0, r);
}

inline ColumnRef TileBlock::Layout::column(unsigned local) const {
  const unsigned word = local >> 6;
  if (((occupied_[word] >> (local & 63)) & 1u) == 0) return {};
  return columnIn(volumes_, starts_, positive_counts_, wide_,
                  rankIn(occupied_[word], words_before_[word], local));
}

}  // namespace detail
}  // namespace mvog
