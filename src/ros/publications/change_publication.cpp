#include "mvog_ros/publications/change_publication.h"

#include <algorithm>
#include <iterator>
#include <shared_mutex>

namespace mvog_ros {

std::optional<std::vector<mvog::TileIndex>> tilesChangedSince(const mvog::Map& map,
                                                              std::uint64_t revision) {
  const std::optional<std::vector<mvog::TileIndex>> removed = map.tilesRemovedSince(revision);
  if (!removed) return std::nullopt;
  const std::vector<mvog::TileIndex> modified = map.tilesModifiedSince(revision);
  std::vector<mvog::TileIndex> changed;
  changed.reserve(modified.size() + removed->size());
  // Both lists are rows of tiles from the lowest, and no tile is in both.
  std::merge(modified.begin(), modified.end(), removed->begin(), removed->end(),
             std::back_inserter(changed), [](const mvog::TileIndex& a, const mvog::TileIndex& b) {
               return a.y != b.y ? a.y < b.y : a.x < b.x;
             });
  return changed;
}

ChangePublication::ChangePublication(const SharedMap& shared_map) : map_(shared_map) {}

ChangePublication::~ChangePublication() { stop(); }

void ChangePublication::start(ros::NodeHandle& private_nh, double period) {
  timer_ = private_nh.createTimer(ros::Duration(period), &ChangePublication::publishChanges, this);
}

void ChangePublication::stop() { timer_.stop(); }

void ChangePublication::reconfigure(double period, const std::function<void()>& change) {
  {
    std::lock_guard<std::mutex> publication_lock(mutex_);
    std::shared_lock<WriterPreferringMutex> lock(map_.mutex);
    change();
    clearPublished();
    published_ = {map_.generation, 0};
    publishChangesLocked();
  }
  // Outside the locks: the timer's callback takes them.
  timer_.setPeriod(ros::Duration(period));
}

void ChangePublication::restartIfReplaced() {
  std::lock_guard<std::mutex> publication_lock(mutex_);
  std::shared_lock<WriterPreferringMutex> lock(map_.mutex);
  restartIfReplacedLocked();
}

void ChangePublication::restartIfReplacedLocked() {
  if (map_.generation == published_.generation) return;
  clearPublished();
  published_ = {map_.generation, 0};
}

void ChangePublication::publishChanges(const ros::TimerEvent&) {
  std::lock_guard<std::mutex> publication_lock(mutex_);
  std::shared_lock<WriterPreferringMutex> lock(map_.mutex);
  publishChangesLocked();
}

void ChangePublication::publishChangesLocked() {
  restartIfReplacedLocked();
  if (map_.version() == published_) return;
  std::optional<std::vector<mvog::TileIndex>> changed =
      tilesChangedSince(map_.map, published_.revision);
  if (!changed) {  // the map no longer knows which tiles it removed: show it afresh
    clearPublished();
    changed = map_.map.tilesModifiedSince(0);
  }
  published_ = map_.version();
  publishTiles(*changed);
}

}  // namespace mvog_ros
