// Incremental map updates (map_io.h): the tiles that changed since a revision, as stored, so
// that a mirror becomes equal to its source bit for bit, decay included.
#include <algorithm>
#include <cmath>
#include <string>
#include <unordered_set>
#include <utility>

#include "byte_format.h"
#include "map_storage.h"
#include "mvog/map_io.h"

namespace mvog {
namespace detail {

/// An update's header, checked.
struct UpdateHeader {
  MapUpdateInfo info;
  MapConfig config;
  double mass_unit = 1.0;
  std::int64_t unit_exponent = 0;
  std::uint64_t num_cells = 0;
  std::uint64_t num_volumes = 0;
};

/// An update's tiles, checked and built, ready to be installed.
struct UpdateBody {
  std::vector<std::uint64_t> removed;
  std::vector<std::pair<std::uint64_t, TileBlock>> tiles;
};

}  // namespace detail

namespace {

constexpr char kUpdateMagic[8] = {'M', 'V', 'O', 'G', 'U', 'P', 'D', '\0'};
constexpr std::uint32_t kFullFlag = 1u;
constexpr std::size_t kRemovedTileBytes = 8;
constexpr std::size_t kTileRecordBytes = 16;

[[noreturn]] void invalidUpdate(const std::string& what) {
  throw MapFileError("invalid map update: " + what);
}

using detail::UpdateBody;
using detail::UpdateHeader;

UpdateHeader readHeader(const std::uint8_t* data, std::size_t size) {
  if (data == nullptr || size < kMapUpdateHeaderBytes + detail::kChecksumBytes) {
    invalidUpdate("truncated: " + std::to_string(size) +
                  " bytes is less than a header and a checksum");
  }
  if (std::memcmp(data, kUpdateMagic, sizeof(kUpdateMagic)) != 0) {
    invalidUpdate("not an MVOG map update (bad magic)");
  }
  detail::Reader reader(data, sizeof(kUpdateMagic));
  const std::uint32_t version = reader.u32();
  if (version != kMapUpdateFormatVersion) {
    invalidUpdate("format version " + std::to_string(version) + " is not supported (expected " +
                  std::to_string(kMapUpdateFormatVersion) + ")");
  }
  if (reader.u32() != kMapUpdateHeaderBytes) invalidUpdate("unexpected header size");
  UpdateHeader header;
  header.config.resolution = reader.f64();
  header.config.max_coordinate = reader.f64();
  const std::uint32_t rules = reader.u32();
  if (rules & ~detail::kAllRuleBits) invalidUpdate("unknown bits in the model's rules");
  header.config.rules = detail::rulesOf(rules);
  header.config.rules.out_of_range_free_length = reader.f64();
  const std::uint32_t flags = reader.u32();
  if (flags & ~kFullFlag) invalidUpdate("unknown flags");
  MapUpdateInfo& info = header.info;
  info.full = (flags & kFullFlag) != 0;
  info.source = reader.u64();
  info.from_revision = reader.u64();
  info.to_revision = reader.u64();
  header.mass_unit = reader.f64();
  header.unit_exponent = reader.i64();
  const std::uint64_t num_removed = reader.u64();
  const std::uint64_t num_tiles = reader.u64();
  header.num_cells = reader.u64();
  header.num_volumes = reader.u64();
  if (reader.u64() != 0) invalidUpdate("reserved header bytes are not zero");
  // Check the counts against the real size before trusting them for anything.
  const std::size_t body = size - kMapUpdateHeaderBytes - detail::kChecksumBytes;
  if (num_removed > body / kRemovedTileBytes || num_tiles > body / kTileRecordBytes ||
      header.num_cells > body / detail::kCellRecordBytes ||
      header.num_volumes > body / detail::kVolumeRecordBytes ||
      num_removed * kRemovedTileBytes + num_tiles * kTileRecordBytes +
              header.num_cells * detail::kCellRecordBytes +
              header.num_volumes * detail::kVolumeRecordBytes !=
          body) {
    invalidUpdate("the header's counts do not match the size of " + std::to_string(size) +
                  " bytes (truncated or corrupted)");
  }
  if (!detail::checksumMatches(data, size)) invalidUpdate("checksum mismatch (corrupted)");
  try {
    header.config.validate();
  } catch (const ConfigError& e) {
    invalidUpdate(std::string("bad header: ") + e.what());
  }
  if (info.from_revision > info.to_revision) {
    invalidUpdate("the from revision is after the to revision");
  }
  if (info.full && (info.from_revision != 0 || num_removed != 0)) {
    invalidUpdate("a full update with a from revision or removed tiles");
  }
  if (!(header.mass_unit > 0.5 && header.mass_unit <= 1.0)) {
    invalidUpdate("mass unit not in (0.5, 1]");
  }
  if (header.unit_exponent < detail::kMinUnitExponent || header.unit_exponent > 0) {
    invalidUpdate("unit exponent not in [-2^24, 0]");
  }
  info.resolution = header.config.resolution;
  info.tiles_removed = static_cast<std::size_t>(num_removed);
  info.tiles_changed = static_cast<std::size_t>(num_tiles);
  return header;
}

UpdateBody readBody(const std::uint8_t* data, const UpdateHeader& header) {
  UpdateBody body;
  detail::Reader reader(data, kMapUpdateHeaderBytes);
  for (std::size_t k = 0; k < header.info.tiles_removed; ++k) {
    const std::int32_t x = reader.i32();
    body.removed.push_back(detail::tileKey(x, reader.i32()));
  }
  std::vector<std::uint64_t> removed = body.removed;
  std::sort(removed.begin(), removed.end());
  if (std::adjacent_find(removed.begin(), removed.end()) != removed.end()) {
    invalidUpdate("a tile is listed removed twice");
  }
  const double max_cell = header.config.max_coordinate / header.config.resolution + 1.0;
  const bool split = header.config.rules.split_free_space_at_obstacles;
  const FreeSpaceRules free_space_rules = detail::freeSpaceRulesOf(header.config.rules);
  ListMerger merger;
  std::uint64_t cells_left = header.num_cells;
  std::uint64_t volumes_left = header.num_volumes;
  detail::TileBlock::Builder builder;
  CellIndex cell;
  CellVolumes volumes;
  for (std::size_t t = 0; t < header.info.tiles_changed; ++t) {
    const std::int32_t tile_x = reader.i32();
    const std::uint64_t key = detail::tileKey(tile_x, reader.i32());
    const std::int64_t exponent = reader.i32();
    const std::uint32_t num_cells = reader.u32();
    const std::string where = detail::tileName(key);
    if (!body.tiles.empty() && !detail::rowMajorBefore(body.tiles.back().first, key)) {
      invalidUpdate(where + " is out of order or listed twice");
    }
    if (std::binary_search(removed.begin(), removed.end(), key)) {
      invalidUpdate(where + " is listed both changed and removed");
    }
    if (exponent < header.unit_exponent || exponent > detail::kMaxExponentLag) {
      invalidUpdate(where + ": exponent not in [unit exponent, 2^24]");
    }
    if (num_cells == 0 || num_cells > detail::kCellsPerTile || num_cells > cells_left) {
      invalidUpdate(where + ": " + std::to_string(num_cells) + " cells");
    }
    cells_left -= num_cells;
    int previous_local = -1;
    for (std::uint32_t c = 0; c < num_cells; ++c) {
      const std::string problem = detail::readCell(reader, volumes_left, cell, volumes);
      if (!problem.empty()) invalidUpdate(problem);
      // The cell's name is made only for a message: this loop reads every cell of an update.
      auto fail_at_cell = [&](const std::string& what) {
        invalidUpdate(detail::cellName(cell).append(what));
      };
      if (detail::tileKeyOf(cell) != key) fail_at_cell(" is not in " + where);
      const auto local = static_cast<int>(detail::localIndex(cell));
      if (local <= previous_local) fail_at_cell(" is out of order or listed twice");
      previous_local = local;
      if (std::fabs(static_cast<double>(cell.x)) > max_cell ||
          std::fabs(static_cast<double>(cell.y)) > max_cell) {
        fail_at_cell(" lies beyond max_coordinate");
      }
      const std::string invalid =
          checkColumn(volumes.positive.data(), volumes.positive.size(), volumes.negative.data(),
                      volumes.negative.size(), split);
      if (!invalid.empty()) fail_at_cell(": " + invalid);
      volumes_left -= volumes.positive.size() + volumes.negative.size();
      merger.cutAsTheMergeDoes(volumes.negative, volumes.positive, free_space_rules);
      builder.add(static_cast<unsigned>(local), volumes.positive, volumes.negative);
    }
    body.tiles.emplace_back(key, builder.finish(static_cast<std::int32_t>(exponent), 0));
  }
  if (cells_left != 0 || volumes_left != 0) {
    invalidUpdate("fewer cells or volumes than the header counts");
  }
  return body;
}

}  // namespace

namespace detail {

/// The side of updates that works on a map's storage (a friend of Map).
struct MapUpdateCodec {
  static std::vector<std::uint8_t> encode(const Map& map, std::uint64_t since);
  /// `header` and `body` as a new map that continues `map`'s revisions and identity.
  static Map full(const Map& map, const UpdateHeader& header, UpdateBody&& body);
  static void incremental(Map& map, const UpdateHeader& header, UpdateBody&& body);
  static void checkFollows(const Map& map, const UpdateHeader& header);
};

std::vector<std::uint8_t> MapUpdateCodec::encode(const Map& map, std::uint64_t since) {
  const Map::Storage& storage = *map.storage_;
  const bool full = since == 0 || since > map.revision_ || !storage.removals.covers(since) ||
                    since < storage.exponents_rebased_revision;
  std::vector<std::uint64_t> changed;
  std::uint64_t num_cells = 0;
  std::uint64_t num_volumes = 0;
  for (std::uint64_t key : map.sortedTileKeys()) {
    const TileBlock& tile = storage.tiles.at(key);
    if (!full && tile.modifiedRevision() <= since) continue;
    changed.push_back(key);
    num_cells += tile.numCells();
    num_volumes += tile.numVolumes();
  }
  std::vector<std::uint64_t> removed;
  if (!full) {
    const std::optional<std::vector<TileIndex>> removed_tiles = map.tilesRemovedSince(since);
    for (const TileIndex& tile : *removed_tiles) removed.push_back(tileKey(tile.x, tile.y));
  }

  std::vector<std::uint8_t> out;
  out.reserve(kMapUpdateHeaderBytes + kRemovedTileBytes * removed.size() +
              kTileRecordBytes * changed.size() + kCellRecordBytes * num_cells +
              kVolumeRecordBytes * num_volumes + kChecksumBytes);
  Writer writer(out);
  writer.bytes(kUpdateMagic, sizeof(kUpdateMagic));
  writer.u32(kMapUpdateFormatVersion);
  writer.u32(static_cast<std::uint32_t>(kMapUpdateHeaderBytes));
  writer.f64(map.config_.resolution);
  writer.f64(map.config_.max_coordinate);
  writer.u32(rulesBits(map.config_.rules));
  writer.f64(map.config_.rules.out_of_range_free_length);
  writer.u32(full ? kFullFlag : 0u);
  writer.u64(storage.id);
  writer.u64(full ? 0 : since);
  writer.u64(map.revision_);
  writer.f64(map.mass_unit_);
  writer.i64(map.unit_exponent_);
  writer.u64(removed.size());
  writer.u64(changed.size());
  writer.u64(num_cells);
  writer.u64(num_volumes);
  writer.u64(0);
  for (std::uint64_t key : removed) {
    writer.i32(tileKeyX(key));
    writer.i32(tileKeyY(key));
  }
  for (std::uint64_t key : changed) {
    const TileBlock& tile = storage.tiles.at(key);
    writer.i32(tileKeyX(key));
    writer.i32(tileKeyY(key));
    writer.i32(tile.exponent());
    writer.u32(tile.numCells());
    const CellIndex origin = tileOrigin(key);
    for (unsigned local = 0; local < kCellsPerTile; ++local) {
      if (!tile.holds(local)) continue;
      const ColumnRef column = tile.column(local);
      writeCell(writer, cellInTile(origin, local), column.positive, column.num_positive,
                column.negative, column.num_negative);
    }
  }
  writer.checksum();
  return out;
}

void MapUpdateCodec::checkFollows(const Map& map, const UpdateHeader& header) {
  if (!(header.config.resolution == map.config_.resolution &&
        header.config.max_coordinate == map.config_.max_coordinate &&
        header.config.rules == map.config_.rules)) {
    invalidUpdate("its source's configuration changed (resolution, max_coordinate or rules)");
  }
  // Decay only lowers the unit; clear() and rebasing raise it, and make a full update.
  if (header.unit_exponent > map.unit_exponent_ ||
      (header.unit_exponent == map.unit_exponent_ && header.mass_unit > map.mass_unit_)) {
    invalidUpdate("the mass unit grew without a full update");
  }
}

Map MapUpdateCodec::full(const Map& map, const UpdateHeader& header, UpdateBody&& body) {
  Map fresh(header.config);
  fresh.revision_ = map.revision_ + 1;
  fresh.storage_->id = map.storage_->id;
  fresh.storage_->removals.restartAt(fresh.revision_);  // every tile changed: nothing to list
  fresh.mass_unit_ = header.mass_unit;
  fresh.unit_exponent_ = header.unit_exponent;
  for (auto& [key, tile] : body.tiles) {
    tile.setModifiedRevision(fresh.revision_);
    fresh.storage_->tiles.emplace(key, std::move(tile));
  }
  fresh.recomputeBounds();
  return fresh;
}

void MapUpdateCodec::incremental(Map& map, const UpdateHeader& header, UpdateBody&& body) {
  Map::Storage& storage = *map.storage_;
  const bool changes_nothing =
      body.tiles.empty() && header.mass_unit == map.mass_unit_ &&
      header.unit_exponent == map.unit_exponent_ &&
      std::none_of(body.removed.begin(), body.removed.end(),
                   [&](std::uint64_t key) { return storage.tiles.count(key) != 0; });
  if (changes_nothing) return;
  ++map.revision_;
  for (std::uint64_t key : body.removed) {
    const auto it = storage.tiles.find(key);
    if (it != storage.tiles.end()) storage.removeTile(it, map.revision_);
  }
  for (auto& [key, tile] : body.tiles) {
    tile.setModifiedRevision(map.revision_);
    storage.tiles[key] = std::move(tile);
  }
  map.mass_unit_ = header.mass_unit;
  map.unit_exponent_ = header.unit_exponent;
  map.recomputeBounds();
  storage.shrinkIndex();
}

}  // namespace detail

std::vector<std::uint8_t> serializeMapUpdate(const Map& map, std::uint64_t since_revision) {
  return detail::MapUpdateCodec::encode(map, since_revision);
}

MapUpdateInfo readMapUpdateInfo(const std::uint8_t* data, std::size_t size) {
  return readHeader(data, size).info;
}

MapUpdateResult MapMirror::apply(const std::uint8_t* data, std::size_t size) {
  const UpdateHeader header = readHeader(data, size);
  MapUpdateResult result;
  result.update = header.info;
  const bool same_source = source_revision_ != 0 && header.info.source == source_;
  if (header.info.full) {
    if (same_source && header.info.to_revision < source_revision_) {
      result.status = MapUpdateStatus::kOutdated;
      return result;
    }
    UpdateBody body = readBody(data, header);
    map_ = detail::MapUpdateCodec::full(map_, header, std::move(body));
  } else {
    if (!same_source || header.info.from_revision > source_revision_) {
      result.status = MapUpdateStatus::kMissed;
      return result;
    }
    if (header.info.to_revision < source_revision_) {
      result.status = MapUpdateStatus::kOutdated;
      return result;
    }
    detail::MapUpdateCodec::checkFollows(map_, header);
    UpdateBody body = readBody(data, header);
    detail::MapUpdateCodec::incremental(map_, header, std::move(body));
  }
  source_ = header.info.source;
  source_revision_ = header.info.to_revision;
  result.status = MapUpdateStatus::kApplied;
  return result;
}

}  // namespace mvog
