#include "mvog_ros/publications/binary_map_publication.h"

#include <shared_mutex>

#include "mvog/map_io.h"

namespace mvog_ros {

BinaryMapPublication::BinaryMapPublication(ros::NodeHandle& private_nh,
                                           const PublicationsConfig& config,
                                           const std::string& frame_id, const SharedMap& shared_map)
    : frame_id_(frame_id), map_(shared_map) {
  publisher_ = private_nh.advertise<mvog::MapBinary>(
      "map", 1, [this](const ros::SingleSubscriberPublisher& subscriber) { send(subscriber); },
      ros::SubscriberStatusCallback(), ros::VoidConstPtr(), true);
  if (config.binary_map_period > 0.0) {
    timer_ = private_nh.createTimer(ros::Duration(config.binary_map_period),
                                    &BinaryMapPublication::publishIfChanged, this);
  }
}

mvog::MapBinary BinaryMapPublication::message() const {
  mvog::MapBinary message;
  message.data = mvog::serializeMap(map_.map);
  message.resolution = map_.map.resolution();
  message.header.frame_id = frame_id_;
  message.header.stamp = ros::Time::now();
  message.format_version = mvog::kMapFormatVersion;
  return message;
}

void BinaryMapPublication::send(const ros::SingleSubscriberPublisher& subscriber) {
  mvog::MapBinary binary;
  {
    std::shared_lock<WriterPreferringMutex> lock(map_.mutex);
    binary = message();
  }
  subscriber.publish(binary);
}

void BinaryMapPublication::publishIfChanged(const ros::TimerEvent&) {
  if (publisher_.getNumSubscribers() == 0) return;
  std::lock_guard<std::mutex> publication_lock(mutex_);
  mvog::MapBinary binary;
  {
    std::shared_lock<WriterPreferringMutex> lock(map_.mutex);
    if (map_.version() == published_) return;
    published_ = map_.version();
    binary = message();
  }
  publisher_.publish(binary);
}

}  // namespace mvog_ros
