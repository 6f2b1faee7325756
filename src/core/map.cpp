#include "mvog/map.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <new>
#include <thread>
#include <utility>

#include "mvog/raster.h"

namespace mvog {
namespace {

std::uint64_t packKey(std::int32_t x, std::int32_t y) {
  return (std::uint64_t{static_cast<std::uint32_t>(x)} << 32) | static_cast<std::uint32_t>(y);
}

/// Grows `range` to hold `other` too (an empty `other` changes nothing).
void include(CellRange& range, const CellRange& other) {
  if (other.empty()) return;
  if (range.empty()) {
    range = other;
    return;
  }
  range.min = {std::min(range.min.x, other.min.x), std::min(range.min.y, other.min.y)};
  range.max = {std::max(range.max.x, other.max.x), std::max(range.max.y, other.max.y)};
}

/// Splits x > 0 into f * 2^e with f in (0.5, 1] (exactly, subnormal x included).
double splitPowerOfTwo(double x, int& e) {
  double f = std::frexp(x, &e);
  if (f == 0.5) {
    f = 1.0;
    --e;
  }
  return f;
}

/// When the map's unit exponent falls below this, the exponents are rebased (see Map::decay);
/// a cell's exponent is kept within kMaxExponentLag of the map's, which changes nothing that a
/// double can show: 2^-kMaxExponentLag is zero in double.
constexpr std::int64_t kMinUnitExponent = -(std::int64_t{1} << 24);
constexpr std::int64_t kMaxExponentLag = std::int64_t{1} << 24;

}  // namespace

// ---- Cell: one heap block [header | positive volumes | negative volumes] behind one pointer.
// An unobserved cell costs 8 bytes; the paper's two lists share the block (Sec. III-A). The
// header holds the cell's mass exponent: real mass = stored mass * Map::mass_unit_ *
// 2^(Map::unit_exponent_ - exponent) (see Map::decay).

class Map::Cell {
 public:
  Cell() = default;
  ~Cell() { std::free(block_); }
  Cell(const Cell&) = delete;
  Cell& operator=(const Cell&) = delete;

  std::uint32_t count(VolumeSign sign) const {
    if (block_ == nullptr) return 0;
    return sign == VolumeSign::kPositive ? block_->num_positive : block_->num_negative;
  }
  const Volume* list(VolumeSign sign) const {
    if (block_ == nullptr) return nullptr;
    return sign == VolumeSign::kPositive ? volumes() : volumes() + block_->num_positive;
  }
  bool empty() const { return block_ == nullptr; }
  std::size_t bytes() const { return block_ == nullptr ? 0 : blockBytes(block_->capacity); }
  std::int32_t exponent() const { return block_ == nullptr ? 0 : block_->exponent; }

  /// Replaces both lists, masses in the unit of `unit_exponent`; returns the change of bytes held.
  std::ptrdiff_t assign(const CellVolumes& volumes_in, std::int64_t unit_exponent) {
    const std::size_t old_bytes = bytes();
    const std::size_t total = volumes_in.positive.size() + volumes_in.negative.size();
    std::free(block_);
    block_ = nullptr;
    if (total > 0) {
      reserve(static_cast<std::uint32_t>(total));
      block_->exponent = static_cast<std::int32_t>(unit_exponent);
      block_->num_positive = static_cast<std::uint32_t>(volumes_in.positive.size());
      block_->num_negative = static_cast<std::uint32_t>(volumes_in.negative.size());
      std::copy(volumes_in.positive.begin(), volumes_in.positive.end(), volumes());
      std::copy(volumes_in.negative.begin(), volumes_in.negative.end(),
                volumes() + block_->num_positive);
    }
    return static_cast<std::ptrdiff_t>(bytes()) - static_cast<std::ptrdiff_t>(old_bytes);
  }

  /// The map's unit exponent moves up by -unit_exponent (to 0): keep the cell's real masses.
  void rebaseExponent(std::int64_t unit_exponent) {
    if (block_ == nullptr) return;
    block_->exponent = static_cast<std::int32_t>(
        std::min(std::int64_t{block_->exponent} - unit_exponent, kMaxExponentLag));
  }

 private:
  struct Header {
    std::uint32_t num_positive;
    std::uint32_t num_negative;
    std::uint32_t capacity;
    std::int32_t exponent;
  };
  static_assert(alignof(Header) >= alignof(Volume) && sizeof(Header) % alignof(Volume) == 0,
                "volumes follow the header directly");

  static std::size_t blockBytes(std::uint32_t capacity) {
    return sizeof(Header) + std::size_t{capacity} * sizeof(Volume);
  }
  Volume* volumes() const { return reinterpret_cast<Volume*>(block_ + 1); }

  /// Makes room for `needed` volumes; returns the change of bytes held.
  std::ptrdiff_t reserve(std::uint32_t needed) {
    const std::uint32_t capacity = block_ == nullptr ? 0 : block_->capacity;
    if (needed <= capacity) return 0;
    // Most columns hold a handful of volumes: grow one at a time, then by half, so that spare
    // capacity stays small.
    const std::uint32_t grown =
        std::max(needed, capacity < 4 ? capacity + 1 : capacity + capacity / 2);
    const std::size_t old_bytes = bytes();
    void* block = std::realloc(block_, blockBytes(grown));
    if (block == nullptr) throw std::bad_alloc();
    if (block_ == nullptr) {
      static_cast<Header*>(block)->num_positive = 0;
      static_cast<Header*>(block)->num_negative = 0;
    }
    block_ = static_cast<Header*>(block);
    block_->capacity = grown;
    return static_cast<std::ptrdiff_t>(blockBytes(grown)) - static_cast<std::ptrdiff_t>(old_bytes);
  }

  Header* block_ = nullptr;
};

struct Map::Tile {
  std::array<Cell, kTileSize * kTileSize> cells;
  std::uint64_t modified_revision = 0;

  Cell& at(const CellIndex& c) { return cells[localIndex(c)]; }
  const Cell& at(const CellIndex& c) const { return cells[localIndex(c)]; }
  static std::size_t localIndex(const CellIndex& c) {
    constexpr std::int32_t kMask = kTileSize - 1;
    return static_cast<std::size_t>((c.y & kMask) * kTileSize + (c.x & kMask));
  }
};

// ---- InsertionResult / PointOccupancy --------------------------------------------------------

std::vector<Scan> splitScan(const Scan& scan, std::size_t max_readings) {
  if (max_readings == 0) throw ConfigError("max_readings: must be >= 1");
  std::vector<Scan> pieces;
  auto piece_with_room = [&]() -> Scan& {
    if (pieces.empty() ||
        pieces.back().hits.size() + pieces.back().out_of_range.size() == max_readings) {
      pieces.emplace_back().origin = scan.origin;
    }
    return pieces.back();
  };
  for (std::size_t next = 0; next < scan.hits.size();) {
    Scan& piece = piece_with_room();
    const std::size_t count = std::min(max_readings - piece.hits.size(), scan.hits.size() - next);
    piece.hits.assign(scan.hits.begin() + next, scan.hits.begin() + next + count);
    next += count;
  }
  for (std::size_t next = 0; next < scan.out_of_range.size();) {
    Scan& piece = piece_with_room();
    const std::size_t room = max_readings - piece.hits.size() - piece.out_of_range.size();
    const std::size_t count = std::min(room, scan.out_of_range.size() - next);
    piece.out_of_range.insert(piece.out_of_range.end(), scan.out_of_range.begin() + next,
                              scan.out_of_range.begin() + next + count);
    next += count;
  }
  return pieces;
}

InsertionResult& InsertionResult::operator+=(const InsertionResult& other) {
  obstacle_readings += other.obstacle_readings;
  out_of_range_readings += other.out_of_range_readings;
  truncated_to_max_range += other.truncated_to_max_range;
  rejected_non_finite += other.rejected_non_finite;
  rejected_out_of_bounds += other.rejected_out_of_bounds;
  rejected_too_close += other.rejected_too_close;
  ignored_out_of_range += other.ignored_out_of_range;
  return *this;
}

OccupancyState PointOccupancy::state(double occupancy_threshold) const {
  if (!probability) return OccupancyState::kUnknown;
  return *probability > occupancy_threshold ? OccupancyState::kOccupied : OccupancyState::kFree;
}

// ---- Map -----------------------------------------------------------------------------------

Map::Map(const MapConfig& config) : config_(config) {
  config_.validate();
  scale_inverse_ = 1.0 / config_.resolution;
}

Map::~Map() = default;
Map::Map(Map&&) noexcept = default;
Map& Map::operator=(Map&&) noexcept = default;

CellRange Map::tileCells(const TileIndex& tile) {
  const CellIndex min{tile.x * kTileSize, tile.y * kTileSize};
  return {min, {min.x + kTileSize - 1, min.y + kTileSize - 1}};
}

const Map::Tile* Map::findTile(const TileIndex& index) const {
  const auto it = tiles_.find(packKey(index.x, index.y));
  return it == tiles_.end() ? nullptr : it->second.get();
}

const Map::Cell* Map::findCell(const CellIndex& cell) const {
  const Tile* t = findTile(tileOf(cell));
  return t == nullptr ? nullptr : &t->at(cell);
}

CellIndex Map::cellAtPoint(double x, double y) const {
  return cellAt(x * scale_inverse_, y * scale_inverse_);
}

CellRange Map::cellsInRectangle(double min_x, double min_y, double max_x, double max_y) const {
  return {cellAtPoint(min_x, min_y), cellAtPoint(max_x, max_y)};
}

void Map::growBounds(const CellRange& cells) { include(bounds_, cells); }

void Map::recomputeBounds() {
  bounds_ = CellRange{{0, 0}, {-1, -1}};
  for (const auto& entry : tiles_) {
    const CellRange tile_cells = tileCells(
        {static_cast<std::int32_t>(entry.first >> 32), static_cast<std::int32_t>(entry.first)});
    for (std::int32_t y = tile_cells.min.y; y <= tile_cells.max.y; ++y) {
      for (std::int32_t x = tile_cells.min.x; x <= tile_cells.max.x; ++x) {
        if (!entry.second->at({x, y}).empty()) include(bounds_, {{x, y}, {x, y}});
      }
    }
  }
}


/// Finds or creates the tiles that a writer touches, remembering the last one: consecutive cells
/// of a ray mostly share a tile. `created` (if given) receives new tiles instead of the map, so
/// that several writers can run at once on disjoint tiles (see insertScan). The rectangle of the
/// cells given volumes is kept for the map's bounds, which hold cells with volumes only.
class Map::TileWriter {
 public:
  TileWriter(Map& map, std::unordered_map<std::uint64_t, std::unique_ptr<Tile>>* created)
      : map_(map), created_(created) {}

  Cell& cell(const CellIndex& index) {
    const TileIndex tile_index = tileOf(index);
    const std::uint64_t key = packKey(tile_index.x, tile_index.y);
    if (last_tile_ == nullptr || key != last_key_) {
      last_key_ = key;
      last_tile_ = lookup(key);
      last_tile_->modified_revision = map_.revision_;
    }
    return last_tile_->at(index);
  }
  std::ptrdiff_t bytesAdded() const { return bytes_added_; }
  const CellRange& touched() const { return touched_; }

 private:
  Tile* lookup(std::uint64_t key) {
    if (created_ == nullptr) {
      std::unique_ptr<Tile>& slot = map_.tiles_[key];
      if (!slot) slot = std::make_unique<Tile>();
      return slot.get();
    }
    const auto existing = map_.tiles_.find(key);
    if (existing != map_.tiles_.end()) return existing->second.get();
    std::unique_ptr<Tile>& slot = (*created_)[key];
    if (!slot) slot = std::make_unique<Tile>();
    return slot.get();
  }

  Map& map_;
  std::unordered_map<std::uint64_t, std::unique_ptr<Tile>>* created_;
  std::uint64_t last_key_ = 0;
  Tile* last_tile_ = nullptr;
  std::ptrdiff_t bytes_added_ = 0;
  CellRange touched_{
      {std::numeric_limits<std::int32_t>::max(), std::numeric_limits<std::int32_t>::max()},
      {std::numeric_limits<std::int32_t>::min(), std::numeric_limits<std::int32_t>::min()}};
};

// ---- Queries -------------------------------------------------------------------------------

namespace {

/// Eq. (9) from the stored masses of the volumes containing a height: the stored unit cancels,
/// so decay (which changes only the unit) leaves it exactly unchanged (Sec. III-E).
std::optional<float> probabilityOf(const Volume* positive, const Volume* negative) {
  const float rho_plus = positive != nullptr ? positive->density() : 0.0f;
  const float rho_minus = negative != nullptr ? negative->density() : 0.0f;
  if (!(rho_plus + rho_minus > 0.0f)) return std::nullopt;
  return rho_plus / (rho_plus + rho_minus);
}

}  // namespace

PointOccupancy Map::occupancy(const Eigen::Vector3d& point) const {
  PointOccupancy result;
  if (!point.allFinite()) return result;
  if (point.cwiseAbs().maxCoeff() > config_.max_coordinate) return result;
  const Cell* cell = findCell(cellAtPoint(point.x(), point.y()));
  if (cell == nullptr || cell->empty()) return result;
  const auto z = static_cast<float>(point.z() * scale_inverse_);
  const Volume* positive =
      findVolume(cell->list(VolumeSign::kPositive), cell->count(VolumeSign::kPositive), z);
  const Volume* negative =
      findVolume(cell->list(VolumeSign::kNegative), cell->count(VolumeSign::kNegative), z);
  if (positive != nullptr) result.positive_density = realMass(*cell, positive->density());
  if (negative != nullptr) result.negative_density = realMass(*cell, negative->density());
  result.probability = probabilityOf(positive, negative);
  return result;
}

double Map::realMass(const Cell& cell, float stored_mass) const {
  return std::ldexp(stored_mass * mass_unit_, static_cast<int>(unit_exponent_ - cell.exponent()));
}

CellVolumes Map::cellVolumes(const CellIndex& index) const {
  CellVolumes result;
  const Cell* cell = findCell(index);
  if (cell == nullptr) return result;
  for (VolumeSign sign : {VolumeSign::kPositive, VolumeSign::kNegative}) {
    std::vector<Volume>& out = sign == VolumeSign::kPositive ? result.positive : result.negative;
    const Volume* list = cell->list(sign);
    for (std::uint32_t k = 0; k < cell->count(sign); ++k) {
      out.push_back(
          {list[k].bottom, list[k].top, static_cast<float>(realMass(*cell, list[k].mass))});
    }
  }
  return result;
}

template <class T, class CellValue>
Grid2D<T> Map::fillGrid(const CellRange& cells, T unobserved, CellValue&& value_of) const {
  if (cells.empty()) throw ConfigError("cells: the range is empty");
  if (cells.width() * cells.height() > (std::int64_t{1} << 28)) {
    throw ConfigError("cells: the range exceeds 2^28 cells");
  }
  Grid2D<T> grid;
  grid.resolution = config_.resolution;
  grid.cells = cells;
  grid.values.assign(grid.width() * grid.height(), unobserved);
  // Walk tile by tile: one lookup per tile, and unobserved tiles are skipped whole.
  const TileIndex first = tileOf(cells.min);
  const TileIndex last = tileOf(cells.max);
  for (std::int32_t ty = first.y; ty <= last.y; ++ty) {
    for (std::int32_t tx = first.x; tx <= last.x; ++tx) {
      const Tile* tile = findTile({tx, ty});
      if (tile == nullptr) continue;
      const CellRange in_tile = tileCells({tx, ty});
      const std::int32_t x0 = std::max(in_tile.min.x, cells.min.x);
      const std::int32_t x1 = std::min(in_tile.max.x, cells.max.x);
      const std::int32_t y0 = std::max(in_tile.min.y, cells.min.y);
      const std::int32_t y1 = std::min(in_tile.max.y, cells.max.y);
      for (std::int32_t y = y0; y <= y1; ++y) {
        for (std::int32_t x = x0; x <= x1; ++x) {
          const Cell& cell = tile->at({x, y});
          if (cell.empty()) continue;
          grid.values[static_cast<std::size_t>(y - cells.min.y) * grid.width() +
                      static_cast<std::size_t>(x - cells.min.x)] = value_of(cell);
        }
      }
    }
  }
  return grid;
}

CrossSection Map::crossSection(double z, const CellRange& cells) const {
  const float unknown = std::numeric_limits<float>::quiet_NaN();
  if (!std::isfinite(z)) throw ConfigError("z: must be finite");
  const auto height = static_cast<float>(z * scale_inverse_);
  return fillGrid<float>(cells, unknown, [&](const Cell& cell) {
    const std::optional<float> p = probabilityOf(
        findVolume(cell.list(VolumeSign::kPositive), cell.count(VolumeSign::kPositive), height),
        findVolume(cell.list(VolumeSign::kNegative), cell.count(VolumeSign::kNegative), height));
    return p ? *p : unknown;
  });
}

namespace {

/// Occupancy of a column over the band [low, high] (grid units), see Map::projection.
OccupancyState bandState(const Volume* positive, std::uint32_t num_positive, const Volume* negative,
                         std::uint32_t num_negative, float low, float high,
                         double occupancy_threshold) {
  auto in_band = [&](const Volume& v) { return v.top >= low && v.bottom <= high && v.mass > 0; };
  bool known = std::any_of(negative, negative + num_negative, in_band);
  for (const Volume* p = positive; p != positive + num_positive; ++p) {
    if (!in_band(*p)) continue;
    known = true;
    // The highest p over this volume's part of the band: where no negative volume covers it,
    // rho- = 0 and p = 1; negatives are more than 1 apart, so one covers it all or some part
    // of it is uncovered.
    const float part_low = std::max(p->bottom, low);
    const float part_high = std::min(p->top, high);
    const Volume* cover = std::find_if(negative, negative + num_negative, [&](const Volume& n) {
      return n.bottom <= part_low && part_high <= n.top;
    });
    const float rho_minus = cover != negative + num_negative ? cover->density() : 0.0f;
    const float rho_plus = p->density();
    if (rho_plus / (rho_plus + rho_minus) > occupancy_threshold) return OccupancyState::kOccupied;
  }
  return known ? OccupancyState::kFree : OccupancyState::kUnknown;
}

}  // namespace

Projection Map::projection(double z_min, double z_max, double occupancy_threshold,
                           const CellRange& cells) const {
  if (std::isnan(z_min) || std::isnan(z_max) || z_min > z_max) {
    throw ConfigError("z_min: must not be NaN nor above z_max");
  }
  if (!(occupancy_threshold >= 0.0 && occupancy_threshold < 1.0)) {
    throw ConfigError("occupancy_threshold: must be in [0, 1)");
  }
  const auto low = static_cast<float>(z_min * scale_inverse_);
  const auto high = static_cast<float>(z_max * scale_inverse_);
  return fillGrid<OccupancyState>(cells, OccupancyState::kUnknown, [&](const Cell& cell) {
    return bandState(cell.list(VolumeSign::kPositive), cell.count(VolumeSign::kPositive),
                     cell.list(VolumeSign::kNegative), cell.count(VolumeSign::kNegative), low, high,
                     occupancy_threshold);
  });
}

std::vector<std::uint64_t> Map::sortedTileKeys() const {
  std::vector<std::uint64_t> keys;
  keys.reserve(tiles_.size());
  for (const auto& entry : tiles_) keys.push_back(entry.first);
  std::sort(keys.begin(), keys.end(), [](std::uint64_t a, std::uint64_t b) {
    // By (y, x) as signed numbers: rows of tiles from the lowest.
    const auto ax = static_cast<std::int32_t>(a >> 32), ay = static_cast<std::int32_t>(a);
    const auto bx = static_cast<std::int32_t>(b >> 32), by = static_cast<std::int32_t>(b);
    return ay != by ? ay < by : ax < bx;
  });
  return keys;
}

void Map::forEachVolumeIn(
    const CellRange& cells,
    const std::function<void(const CellIndex&, VolumeSign, const Volume&)>& visit) const {
  for (std::uint64_t key : sortedTileKeys()) {
    const TileIndex tile_index{static_cast<std::int32_t>(key >> 32),
                               static_cast<std::int32_t>(key)};
    const CellRange tile_cells = tileCells(tile_index);
    if (tile_cells.max.x < cells.min.x || tile_cells.min.x > cells.max.x ||
        tile_cells.max.y < cells.min.y || tile_cells.min.y > cells.max.y) {
      continue;
    }
    const Tile& tile = *tiles_.at(key);
    for (std::int32_t y = tile_cells.min.y; y <= tile_cells.max.y; ++y) {
      for (std::int32_t x = tile_cells.min.x; x <= tile_cells.max.x; ++x) {
        const CellIndex index{x, y};
        const Cell& cell = tile.at(index);
        if (cell.empty() || !cells.contains(index)) continue;
        for (VolumeSign sign : {VolumeSign::kPositive, VolumeSign::kNegative}) {
          const Volume* list = cell.list(sign);
          for (std::uint32_t k = 0; k < cell.count(sign); ++k) {
            const auto mass = static_cast<float>(realMass(cell, list[k].mass));
            visit(index, sign, Volume{list[k].bottom, list[k].top, mass});
          }
        }
      }
    }
  }
}

void Map::forEachVolume(
    const std::function<void(const CellIndex&, VolumeSign, const Volume&)>& visit) const {
  forEachVolumeIn(bounds_, visit);
}

// ---- Decay, bookkeeping ------------------------------------------------------------------------

void Map::decay(double k_d) {
  if (!(k_d > 0.0 && k_d <= 1.0)) throw ConfigError("k_d: must be in (0, 1]");
  if (k_d == 1.0) return;
  ++revision_;  // every mass changes; no probability does, so no tile is marked
  // mass_unit_ * 2^unit_exponent_ *= k_d, with mass_unit_ kept in (0.5, 1]: no cell is touched,
  // and the unit exponent never rises (k_d <= 1).
  int k_exponent = 0;
  const double k_fraction = splitPowerOfTwo(k_d, k_exponent);
  int unit_exponent = 0;
  mass_unit_ = splitPowerOfTwo(mass_unit_ * k_fraction, unit_exponent);
  unit_exponent_ += k_exponent + unit_exponent;
  // After some 2^24 binary orders of decay, move the exponents back near zero so that they stay
  // within 32 bits. No real mass changes that a double can show, and no stored mass changes.
  if (unit_exponent_ < kMinUnitExponent) {
    for (auto& entry : tiles_) {
      for (Cell& cell : entry.second->cells) cell.rebaseExponent(unit_exponent_);
    }
    unit_exponent_ = 0;
  }
}

MemoryUsage Map::memoryUsage() const {
  MemoryUsage usage;
  usage.tiles = tiles_.size();
  for (const auto& entry : tiles_) {
    for (const Cell& cell : entry.second->cells) {
      if (cell.empty()) continue;
      ++usage.cells_with_volumes;
      usage.positive_volumes += cell.count(VolumeSign::kPositive);
      usage.negative_volumes += cell.count(VolumeSign::kNegative);
    }
  }
  const std::size_t tile_index_bytes =
      tiles_.bucket_count() * sizeof(void*) +
      tiles_.size() * (sizeof(void*) + sizeof(decltype(tiles_)::value_type));
  usage.bytes_held =
      sizeof(Map) + tile_index_bytes + tiles_.size() * sizeof(Tile) + bytes_in_cells_;
  usage.minimal_grid_cells = static_cast<std::size_t>(bounds_.width() * bounds_.height());
  usage.table_one_bytes = usage.minimal_grid_cells * 8 +
                          (usage.positive_volumes + usage.negative_volumes) * sizeof(Volume);
  return usage;
}

void Map::clear() {
  tiles_.clear();
  bounds_ = CellRange{{0, 0}, {-1, -1}};
  bytes_in_cells_ = 0;
  mass_unit_ = 1.0;
  unit_exponent_ = 0;
  ++revision_;
}

std::vector<TileIndex> Map::tilesModifiedSince(std::uint64_t revision) const {
  std::vector<TileIndex> modified;
  for (std::uint64_t key : sortedTileKeys()) {
    if (tiles_.at(key)->modified_revision > revision) {
      modified.push_back({static_cast<std::int32_t>(key >> 32), static_cast<std::int32_t>(key)});
    }
  }
  return modified;
}

void Map::setCellVolumes(const CellIndex& index, const CellVolumes& volumes) {
  // Readings within max_coordinate fall in cells |i|, |j| <= max_coordinate * s + 1.
  const double max_cell = config_.max_coordinate * scale_inverse_ + 1.0;
  if (std::fabs(static_cast<double>(index.x)) > max_cell ||
      std::fabs(static_cast<double>(index.y)) > max_cell) {
    throw ConfigError("cell: (" + std::to_string(index.x) + ", " + std::to_string(index.y) +
                      ") lies beyond max_coordinate");
  }
  CellVolumes stored = volumes;
  const std::string problem =
      checkColumn(stored.positive.data(), stored.positive.size(), stored.negative.data(),
                  stored.negative.size(), config_.rules.split_free_space_at_obstacles);
  if (!problem.empty()) throw ConfigError(problem);
  for (VolumeSign sign : {VolumeSign::kPositive, VolumeSign::kNegative}) {
    std::vector<Volume>& list = sign == VolumeSign::kPositive ? stored.positive : stored.negative;
    const char* name = sign == VolumeSign::kPositive ? "positive volumes: " : "negative volumes: ";
    for (Volume& v : list) {
      v.mass = static_cast<float>(v.mass / mass_unit_);
      if (!std::isfinite(v.mass)) {
        throw ConfigError(std::string(name) + "a mass is too large for the map's decayed unit");
      }
    }
  }
  const bool now_empty = stored.positive.empty() && stored.negative.empty();
  const Cell* existing = findCell(index);
  if (now_empty && (existing == nullptr || existing->empty())) return;  // nothing changes
  ++revision_;
  TileWriter writer(*this, nullptr);
  bytes_in_cells_ += writer.cell(index).assign(stored, unit_exponent_);
  if (now_empty) {
    recomputeBounds();
  } else {
    growBounds({index, index});
  }
}

}  // namespace mvog
