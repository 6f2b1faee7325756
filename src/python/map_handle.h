// The Python Map: a mvog::Map with the lock that lets its methods run without the GIL.
#pragma once

#include <pybind11/pybind11.h>

#include <memory>
#include <mutex>
#include <shared_mutex>
#include <utility>

#include "mvog/map.h"

namespace mvog_python {

/// The core's Map is not thread-safe (callers serialise writers against readers), and the
/// binding releases the GIL around every call into it: so each Python Map carries a lock, taken
/// after the GIL is released, shared by queries and exclusive for changes. Code holding it never
/// takes the GIL, so no thread waits for the GIL while holding a map.
class MapHandle {
 public:
  explicit MapHandle(mvog::Map map) : map_(std::move(map)) {}

  /// The map for reading, locked for as long as the returned lock lives.
  std::pair<const mvog::Map&, std::shared_lock<std::shared_mutex>> read() const {
    return {map_, std::shared_lock<std::shared_mutex>(mutex_)};
  }
  /// The map for changing it, locked exclusively for as long as the returned lock lives.
  std::pair<mvog::Map&, std::unique_lock<std::shared_mutex>> write() {
    return {map_, std::unique_lock<std::shared_mutex>(mutex_)};
  }
  std::shared_mutex& mutex() const { return mutex_; }
  /// Unlocked access, for callers that hold mutex() themselves (merge of two maps).
  mvog::Map& unlocked() { return map_; }
  const mvog::Map& unlocked() const { return map_; }

 private:
  mvog::Map map_;
  mutable std::shared_mutex mutex_;
};

using MapPointer = std::shared_ptr<MapHandle>;

/// Runs `work(map)` on the map locked for reading, without the GIL.
template <class Work>
auto reading(const MapHandle& handle, Work&& work) {
  pybind11::gil_scoped_release no_gil;
  auto [map, lock] = handle.read();
  return work(map);
}

/// Runs `work(map)` on the map locked for writing, without the GIL.
template <class Work>
auto writing(MapHandle& handle, Work&& work) {
  pybind11::gil_scoped_release no_gil;
  auto [map, lock] = handle.write();
  return work(map);
}

}  // namespace mvog_python
