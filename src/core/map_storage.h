// The map's tiles (internal to the core).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <unordered_map>
#include <utility>
#include <vector>

#include "mvog/constraints.h"
#include "mvog/map.h"
#include "recent_hits.h"
#include "tile_block.h"

namespace mvog {
namespace detail {

/// When the map's unit exponent falls below this, the exponents are rebased (see Map::decay);
/// a tile's exponent is kept within kMaxExponentLag of the map's, which changes nothing that a
/// double can show: 2^-kMaxExponentLag is zero in double.
constexpr std::int64_t kMinUnitExponent = -(std::int64_t{1} << 24);
constexpr std::int64_t kMaxExponentLag = std::int64_t{1} << 24;

/// The tiles removed from a map, each with the revision of its removal (Map::tilesRemovedSince,
/// incremental map updates). Bounded: beyond kMaxEntries removals the oldest half is forgotten,
/// and the log then answers only for revisions after the last one forgotten.
class TileRemovalLog {
 public:
  static constexpr std::size_t kMaxEntries = std::size_t{1} << 16;  // 1 MiB at the most

  void record(std::uint64_t key, std::uint64_t revision);
  /// Forgets every removal: from now on the log answers only for revisions from `revision` on
  /// (Map::clear, which removes every tile without listing them).
  void restartAt(std::uint64_t revision);
  /// Whether every removal after `revision` is remembered.
  bool covers(std::uint64_t revision) const { return revision >= complete_from_; }
  /// The keys of the tiles removed after `revision` (which covers() must hold for), each once.
  std::vector<std::uint64_t> keysRemovedAfter(std::uint64_t revision) const;
  std::size_t bytes() const { return entries_.capacity() * sizeof(Entry); }

 private:
  using Entry = std::pair<std::uint64_t, std::uint64_t>;  // (revision, key), revisions ascending
  std::vector<Entry> entries_;
  std::uint64_t complete_from_ = 0;
};

/// A number that tells maps apart (incremental updates name their source map with it).
std::uint64_t newMapId();

/// How ListMerger treats a negative list under the map's rules.
inline FreeSpaceRules freeSpaceRulesOf(const ModelRules& rules) {
  return {rules.split_free_space_at_obstacles, rules.clip_free_space_at_hits};
}

}  // namespace detail

struct Map::Storage {
  using Tiles = std::unordered_map<std::uint64_t, detail::TileBlock>;
  /// By detail::tileKey; no tile is empty.
  Tiles tiles;
  detail::TileRemovalLog removals;
  /// The revision of the last decay step that rebased the tiles' mass exponents (0: none): their
  /// stored form changed, so an incremental update cannot span it.
  std::uint64_t exponents_rebased_revision = 0;
  std::uint64_t id = detail::newMapId();
  /// The latest scans' hits (InsertionConfig::hit_memory_scans): made by the first insertion
  /// that keeps them, dropped by one that does not and by Map::clear.
  std::unique_ptr<detail::RecentHits> recent_hits;

  /// Erases a tile, remembering its removal at `revision`; returns the tile after it.
  Tiles::iterator removeTile(Tiles::iterator tile, std::uint64_t revision) {
    removals.record(tile->first, revision);
    return tiles.erase(tile);
  }
  /// Gives back the tile index's buckets once most tiles are gone (the index never shrinks by
  /// itself).
  void shrinkIndex() {
    if (tiles.size() < tiles.bucket_count() / 4) tiles.rehash(0);
  }
};

}  // namespace mvog
