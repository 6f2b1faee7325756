#pragma once

#include <cstdint>
#include <utility>

#include "mvog/map.h"
#include "mvog_ros/writer_preferring_mutex.h"

namespace mvog_ros {

/// Which state of the server's map something saw: the map that replaced the first one
/// `generation` times (~load_map, ~reset), at its `revision` (Map::revision counts within one
/// map only).
struct MapVersion {
  std::uint64_t generation = 0;
  std::uint64_t revision = 0;

  friend bool operator==(const MapVersion& a, const MapVersion& b) {
    return a.generation == b.generation && a.revision == b.revision;
  }
  friend bool operator!=(const MapVersion& a, const MapVersion& b) { return !(a == b); }
};

/// The server's map and the lock that guards it (RELIABILITY.md, section 3): writers (insertion,
/// decay, ~load_map, ~reset) hold `mutex` exclusively, readers (queries, publications, saves)
/// share it. Owned by Mapper; its parts hold a reference.
struct SharedMap {
  explicit SharedMap(mvog::Map&& initial) : map(std::move(initial)) {}
  SharedMap(const SharedMap&) = delete;
  SharedMap& operator=(const SharedMap&) = delete;

  /// The caller holds `mutex`.
  MapVersion version() const { return {generation, map.revision()}; }
  /// Puts `next` in place of the map; the caller holds `mutex` exclusively.
  void replace(mvog::Map&& next) {
    map = std::move(next);
    ++generation;
  }

  mutable WriterPreferringMutex mutex;
  mvog::Map map;
  std::uint64_t generation = 0;  // how many times the map was replaced
};

}  // namespace mvog_ros
