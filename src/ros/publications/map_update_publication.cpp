#include "mvog_ros/publications/map_update_publication.h"

#include <shared_mutex>
#include <utility>

#include "mvog/map_io.h"

namespace mvog_ros {

MapUpdatePublication::MapUpdatePublication(ros::NodeHandle& private_nh,
                                           const PublicationsConfig& config,
                                           const std::string& frame_id, const SharedMap& shared_map)
    : frame_id_(frame_id),
      map_(shared_map),
      publisher_(private_nh.advertise<mvog::MapUpdate>("map_updates", 10)),
      service_(private_nh.advertiseService("get_map_update", &MapUpdatePublication::getMapUpdate,
                                           this)) {
  if (config.binary_map_period > 0.0) {
    timer_ = private_nh.createTimer(ros::Duration(config.binary_map_period),
                                    &MapUpdatePublication::publishIfChanged, this);
  }
}

mvog::MapUpdate MapUpdatePublication::message(std::vector<std::uint8_t>&& bytes) const {
  const mvog::MapUpdateInfo info = mvog::readMapUpdateInfo(bytes.data(), bytes.size());
  mvog::MapUpdate message;
  message.header.frame_id = frame_id_;
  message.header.stamp = ros::Time::now();
  message.resolution = info.resolution;
  message.format_version = mvog::kMapUpdateFormatVersion;
  message.full = info.full;
  message.source = info.source;
  message.from_revision = info.from_revision;
  message.to_revision = info.to_revision;
  message.tiles_changed = info.tiles_changed;
  message.tiles_removed = info.tiles_removed;
  message.data = std::move(bytes);
  return message;
}

void MapUpdatePublication::publishIfChanged(const ros::TimerEvent&) {
  std::lock_guard<std::mutex> publication_lock(mutex_);
  std::vector<std::uint8_t> bytes;
  {
    std::shared_lock<WriterPreferringMutex> lock(map_.mutex);
    const MapVersion now = map_.version();
    if (now == sent_) return;
    // Unheard, an update still counts as sent: a mirror that subscribes later asks for what it
    // lacks (~get_map_update), and the next update stays small. The revisions of a map that
    // replaced another say nothing of the other's: then the update is full.
    if (publisher_.getNumSubscribers() > 0) {
      bytes = mvog::serializeMapUpdate(map_.map,
                                       now.generation == sent_.generation ? sent_.revision : 0);
    }
    sent_ = now;
  }
  if (!bytes.empty()) publisher_.publish(message(std::move(bytes)));
}

bool MapUpdatePublication::getMapUpdate(mvog::GetMapUpdate::Request& request,
                                        mvog::GetMapUpdate::Response& response) {
  std::vector<std::uint8_t> bytes;
  {
    std::shared_lock<WriterPreferringMutex> lock(map_.mutex);
    bytes = mvog::serializeMapUpdate(map_.map, request.since_revision);
    const mvog::MapUpdateInfo info = mvog::readMapUpdateInfo(bytes.data(), bytes.size());
    // Revisions of another map than the mirror's say nothing of what it holds.
    if (!info.full && info.source != request.source) bytes = mvog::serializeMapUpdate(map_.map, 0);
  }
  response.update = message(std::move(bytes));
  return true;
}

}  // namespace mvog_ros
