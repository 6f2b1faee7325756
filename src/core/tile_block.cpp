#include "tile_block.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <new>

namespace mvog {
namespace detail {

namespace {
std::string pairName(const char* what, std::int32_t x, std::int32_t y) {
  std::string name = what;
  name += " (";
  name += std::to_string(x);
  name += ", ";
  name += std::to_string(y);
  name += ')';
  return name;
}
}  // namespace

std::string cellName(const CellIndex& cell) { return pairName("cell", cell.x, cell.y); }
std::string tileName(std::uint64_t key) { return pairName("tile", tileKeyX(key), tileKeyY(key)); }

TileBlock::~TileBlock() { std::free(block_); }

TileBlock& TileBlock::operator=(TileBlock&& other) noexcept {
  if (this != &other) {
    std::free(block_);
    block_ = other.block_;
    other.block_ = nullptr;
  }
  return *this;
}

std::size_t TileBlock::volumesOffset(std::uint32_t num_cells, bool wide) {
  const std::size_t counts =
      wide ? 4 * (2 * std::size_t{num_cells} + 1) : 2 * (std::size_t{num_cells} + 1) + num_cells;
  const std::size_t end = sizeof(Header) + counts;
  return (end + alignof(Volume) - 1) / alignof(Volume) * alignof(Volume);
}

std::size_t TileBlock::bytes() const {
  if (block_ == nullptr) return 0;
  return block_->volumes_offset + std::size_t{block_->num_volumes} * sizeof(Volume);
}

TileBlock::Layout::Layout(const TileBlock& tile) {
  if (tile.empty()) return;
  const Header& header = *tile.block_;
  std::copy(std::begin(header.occupied), std::end(header.occupied), occupied_);
  std::copy(std::begin(header.words_before), std::end(header.words_before), words_before_ + 1);
  starts_ = tile.starts();
  positive_counts_ = tile.positiveCounts();
  volumes_ = tile.volumes();
  wide_ = header.wide != 0;
}

std::uint32_t TileBlock::numPositive() const {
  std::uint32_t total = 0;
  for (std::uint32_t r = 0; r < numCells(); ++r) total += positiveCount(r);
  return total;
}

void TileBlock::scaleMasses(double factor, std::int32_t exponent) {
  if (block_ == nullptr) return;
  Volume* all = const_cast<Volume*>(volumes());
  for (std::uint32_t k = 0; k < block_->num_volumes; ++k) {
    all[k].mass = static_cast<float>(all[k].mass * factor);
  }
  block_->exponent = exponent;
  block_->lightest_mass = kUnknownMass;
}

CellRange TileBlock::heldCells() const {
  CellRange held = kNoCells;
  if (block_ == nullptr) return held;
  for (int row = 0; row < kTileSize; ++row) {
    const auto bits = static_cast<std::uint16_t>(block_->occupied[row / 4] >> (16 * (row % 4)));
    if (bits == 0) continue;
    int first = 0;
    while (((bits >> first) & 1u) == 0) ++first;
    int last = kTileSize - 1;
    while (((bits >> last) & 1u) == 0) --last;
    held.extend(CellRange{{first, row}, {last, row}});
  }
  return held;
}

void TileBlock::rebaseExponent(std::int64_t offset, std::int64_t max_lag) {
  if (block_ == nullptr) return;
  block_->exponent =
      static_cast<std::int32_t>(std::min(std::int64_t{block_->exponent} - offset, max_lag));
}

void TileBlock::Builder::add(unsigned local, const ColumnRef& column, double mass_scale) {
  locals_.push_back(static_cast<std::uint16_t>(local));
  starts_.push_back(static_cast<std::uint32_t>(volumes_.size()));
  num_positive_.push_back(column.num_positive);
  for (const auto& [list, count] : {std::make_pair(column.positive, column.num_positive),
                                    std::make_pair(column.negative, column.num_negative)}) {
    for (std::uint32_t k = 0; k < count; ++k) {
      Volume v = list[k];
      if (mass_scale != 1.0) v.mass = static_cast<float>(v.mass * mass_scale);
      volumes_.push_back(v);
    }
  }
}

void TileBlock::Builder::addUnchanged(const TileBlock& tile, unsigned first, unsigned end) {
  if (tile.empty() || first >= end) return;
  const Header& header = *tile.block_;
  // The rank of the first cell at or after `first` (< end <= kCellsPerTile): the held cells
  // before it.
  unsigned r = tile.rank(first);
  const unsigned first_rank = r;
  const auto shift = static_cast<std::int64_t>(volumes_.size()) -
                     static_cast<std::int64_t>(r < header.num_cells ? tile.start(r) : 0);
  for (unsigned word = first >> 6; word < kCellsPerTile / 64 && 64 * word < end; ++word) {
    std::uint64_t bits = header.occupied[word];
    if (64 * word < first) bits &= ~std::uint64_t{0} << (first & 63);
    if (end < 64 * (word + 1)) bits &= (std::uint64_t{1} << (end & 63)) - 1;
    for (; bits != 0; bits &= bits - 1, ++r) {
      locals_.push_back(static_cast<std::uint16_t>(64 * word + lowestBit(bits)));
      starts_.push_back(static_cast<std::uint32_t>(tile.start(r) + shift));
      num_positive_.push_back(tile.positiveCount(r));
    }
  }
  if (r == first_rank) return;
  const Volume* from = tile.volumes() + tile.start(first_rank);
  volumes_.insert(volumes_.end(), from, tile.volumes() + tile.start(r));
}

void TileBlock::Builder::add(unsigned local, const std::vector<Volume>& positive,
                             const std::vector<Volume>& negative) {
  locals_.push_back(static_cast<std::uint16_t>(local));
  starts_.push_back(static_cast<std::uint32_t>(volumes_.size()));
  num_positive_.push_back(static_cast<std::uint32_t>(positive.size()));
  volumes_.insert(volumes_.end(), positive.begin(), positive.end());
  volumes_.insert(volumes_.end(), negative.begin(), negative.end());
}

TileBlock TileBlock::allocate(std::uint32_t num_cells, std::uint32_t num_volumes, bool wide,
                              std::int32_t exponent, std::uint64_t modified_revision) {
  const std::size_t offset = volumesOffset(num_cells, wide);
  void* memory = std::malloc(offset + std::size_t{num_volumes} * sizeof(Volume));
  if (memory == nullptr) throw std::bad_alloc();
  TileBlock tile;
  tile.block_ = static_cast<Header*>(memory);
  Header& header = *tile.block_;
  std::memset(header.occupied, 0, sizeof(header.occupied));
  header.modified_revision = modified_revision;
  header.exponent = exponent;
  header.num_volumes = num_volumes;
  header.num_cells = static_cast<std::uint16_t>(num_cells);
  header.volumes_offset = static_cast<std::uint16_t>(offset);
  header.wide = wide ? 1 : 0;
  header.lightest_mass = kUnknownMass;
  return tile;
}

void TileBlock::countWordsBefore() {
  unsigned before = 0;
  for (unsigned w = 0; w + 1 < kCellsPerTile / 64; ++w) {
    before += bitCount(block_->occupied[w]);
    block_->words_before[w] = static_cast<std::uint8_t>(before);  // at most 192
  }
}

TileBlock TileBlock::Builder::finish(std::int32_t exponent, std::uint64_t modified_revision) {
  TileBlock tile;
  const auto num_cells = static_cast<std::uint32_t>(locals_.size());
  if (num_cells > 0) {
    const auto num_volumes = static_cast<std::uint32_t>(volumes_.size());
    const bool wide = num_volumes > std::numeric_limits<std::uint16_t>::max() ||
                      *std::max_element(num_positive_.begin(), num_positive_.end()) >
                          std::numeric_limits<std::uint8_t>::max();
    tile = allocate(num_cells, num_volumes, wide, exponent, modified_revision);
    Header& header = *tile.block_;
    auto* base = reinterpret_cast<unsigned char*>(tile.block_ + 1);
    starts_.push_back(num_volumes);
    for (std::uint32_t r = 0; r < num_cells; ++r) {
      header.occupied[locals_[r] >> 6] |= std::uint64_t{1} << (locals_[r] & 63);
    }
    tile.countWordsBefore();
    for (std::uint32_t r = 0; r <= num_cells; ++r) {
      if (wide) {
        std::memcpy(base + 4 * std::size_t{r}, &starts_[r], 4);
      } else {
        const auto value = static_cast<std::uint16_t>(starts_[r]);
        std::memcpy(base + 2 * std::size_t{r}, &value, 2);
      }
    }
    for (std::uint32_t r = 0; r < num_cells; ++r) {
      if (wide) {
        std::memcpy(base + 4 * (std::size_t{num_cells} + 1 + r), &num_positive_[r], 4);
      } else {
        base[2 * (std::size_t{num_cells} + 1) + r] = static_cast<unsigned char>(num_positive_[r]);
      }
    }
    if (num_volumes > 0) {
      std::memcpy(const_cast<Volume*>(tile.volumes()), volumes_.data(),
                  std::size_t{num_volumes} * sizeof(Volume));
    }
  }
  clear();
  return tile;
}

void TileBlock::Builder::clear() {
  locals_.clear();
  starts_.clear();
  num_positive_.clear();
  volumes_.clear();
}

void TileBlock::Rewrite::clear() {
  cells_.clear();
  volumes_.clear();
  builder_.clear();
}

void TileBlock::Rewrite::set(unsigned local, const ColumnRef& lists) {
  assert(cells_.empty() || cells_.back().local < local);  // apply() copies the cells between
  cells_.push_back({local, volumes_.size(), lists.num_positive, lists.num_negative});
  // Volume by volume: a cell's lists are short (a range insert costs more for one volume).
  for (std::uint32_t k = 0; k < lists.num_positive; ++k) volumes_.push_back(lists.positive[k]);
  for (std::uint32_t k = 0; k < lists.num_negative; ++k) volumes_.push_back(lists.negative[k]);
}

TileBlock TileBlock::Rewrite::apply(const TileBlock& tile, std::int32_t exponent,
                                    std::uint64_t modified_revision) {
  TileBlock narrow = applyNarrow(tile, exponent, modified_revision);
  if (!narrow.empty()) return narrow;
  unsigned next_local = 0;
  for (const Cell& cell : cells_) {
    builder_.addUnchanged(tile, next_local, cell.local);
    if (cell.num_positive + cell.num_negative > 0) {
      const Volume* v = volumes_.data() + cell.start;
      builder_.add(cell.local, {v, cell.num_positive, v + cell.num_positive, cell.num_negative},
                   1.0);
    }
    next_local = cell.local + 1;
  }
  builder_.addUnchanged(tile, next_local, kCellsPerTile);
  return builder_.finish(exponent, modified_revision);
}

TileBlock TileBlock::Rewrite::applyNarrow(const TileBlock& tile, std::int32_t exponent,
                                          std::uint64_t modified_revision) const {
  if (!tile.empty() && tile.block_->wide != 0) return {};
  // The new tile's size and bitmap.
  std::uint32_t num_cells = tile.numCells();
  std::uint32_t num_volumes = tile.numVolumes();
  std::uint64_t occupied[kCellsPerTile / 64] = {};
  if (!tile.empty()) std::memcpy(occupied, tile.block_->occupied, sizeof(occupied));
  for (const Cell& cell : cells_) {
    const std::uint64_t bit = std::uint64_t{1} << (cell.local & 63);
    if (tile.holds(cell.local)) {
      const ColumnRef old = tile.column(cell.local);
      --num_cells;
      num_volumes -= old.num_positive + old.num_negative;
      occupied[cell.local >> 6] &= ~bit;
    }
    if (cell.num_positive + cell.num_negative == 0) continue;
    if (cell.num_positive > std::numeric_limits<std::uint8_t>::max()) return {};
    ++num_cells;
    num_volumes += cell.num_positive + cell.num_negative;
    occupied[cell.local >> 6] |= bit;
  }
  if (num_cells == 0 || num_volumes > std::numeric_limits<std::uint16_t>::max()) return {};

  TileBlock result = allocate(num_cells, num_volumes, false, exponent, modified_revision);
  std::memcpy(result.block_->occupied, occupied, sizeof(occupied));
  result.countWordsBefore();
  auto* starts = reinterpret_cast<unsigned char*>(result.block_ + 1);
  unsigned char* counts = starts + 2 * (std::size_t{num_cells} + 1);
  auto* volumes = const_cast<Volume*>(result.volumes());
  std::uint32_t rank = 0;     // the new tile's cells written
  std::uint32_t written = 0;  // and volumes
  auto write_start = [&](std::uint32_t at, std::uint32_t start) {
    const auto value = static_cast<std::uint16_t>(start);
    std::memcpy(starts + 2 * std::size_t{at}, &value, 2);
  };
  // The old cells of ranks [first_rank, end_rank), unchanged: their volumes are one run, their
  // starts all move by one offset and their positive counts stay (both narrow here).
  const unsigned char* old_starts = tile.empty() ? nullptr : tile.starts();
  const unsigned char* old_counts = tile.empty() ? nullptr : tile.positiveCounts();
  auto copy_unchanged = [&](unsigned first_rank, unsigned end_rank) {
    if (first_rank == end_rank) return;
    const std::uint32_t first = startAt(old_starts, false, first_rank);
    const std::uint32_t count = startAt(old_starts, false, end_rank) - first;
    std::memcpy(volumes + written, tile.volumes() + first, std::size_t{count} * sizeof(Volume));
    for (unsigned r = first_rank; r < end_rank; ++r) {
      write_start(rank + (r - first_rank), startAt(old_starts, false, r) - first + written);
    }
    std::memcpy(counts + rank, old_counts + first_rank, end_rank - first_rank);
    rank += end_rank - first_rank;
    written += count;
  };
  unsigned old_rank = 0;  // the next old cell not yet passed
  for (const Cell& cell : cells_) {
    if (!tile.empty()) {
      const unsigned below = tile.rank(cell.local);
      copy_unchanged(old_rank, below);
      old_rank = below + (tile.holds(cell.local) ? 1 : 0);
    }
    const std::uint32_t count = cell.num_positive + cell.num_negative;
    if (count == 0) continue;
    std::memcpy(volumes + written, volumes_.data() + cell.start,
                std::size_t{count} * sizeof(Volume));
    write_start(rank, written);
    counts[rank++] = static_cast<unsigned char>(cell.num_positive);
    written += count;
  }
  copy_unchanged(old_rank, tile.numCells());
  write_start(num_cells, written);
  return result;
}

}  // namespace detail
}  // namespace mvog
