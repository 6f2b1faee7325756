#include "mvog_ros/publications/change_publication.h"

#include <shared_mutex>

namespace mvog_ros {

ChangePublication::ChangePublication(const SharedMap& shared_map) : map_(shared_map) {}

ChangePublication::~ChangePublication() { stop(); }

void ChangePublication::start(ros::NodeHandle& private_nh, double period) {
  timer_ = private_nh.createTimer(ros::Duration(period), &ChangePublication::publishChanges, this);
}

void ChangePublication::stop() { timer_.stop(); }

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

std::optional<std::vector<mvog::TileIndex>> ChangePublication::changedSincePublished() const {
  std::optional<std::vector<mvog::TileIndex>> changed =
      map_.map.tilesRemovedSince(published_.revision);
  if (!changed) return std::nullopt;
  const std::vector<mvog::TileIndex> modified = map_.map.tilesModifiedSince(published_.revision);
  changed->insert(changed->end(), modified.begin(), modified.end());
  return changed;
}

void ChangePublication::publishChanges(const ros::TimerEvent&) {
  std::lock_guard<std::mutex> publication_lock(mutex_);
  std::shared_lock<WriterPreferringMutex> lock(map_.mutex);
  restartIfReplacedLocked();
  if (map_.version() == published_) return;
  std::optional<std::vector<mvog::TileIndex>> changed = changedSincePublished();
  if (!changed) {
    clearPublished();
    changed = map_.map.tilesModifiedSince(0);
  }
  published_ = map_.version();
  publishTiles(*changed);
}

}  // namespace mvog_ros
