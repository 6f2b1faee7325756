#pragma once

#include <mutex>
#include <string>

#include <ros/ros.h>

#include "mvog/MapBinary.h"
#include "mvog_ros/mapper_config.h"
#include "mvog_ros/shared_map.h"

namespace mvog_ros {

/// ~map (mvog/MapBinary, latched): the whole map in the file format, every ~binary_map_period
/// when it changed (0: only to new subscribers). Serialised under the map's lock, sent after.
class BinaryMapPublication {
 public:
  BinaryMapPublication(ros::NodeHandle& private_nh, const PublicationsConfig& config,
                       const std::string& frame_id, const SharedMap& shared_map);

 private:
  void publishIfChanged(const ros::TimerEvent&);
  void send(const ros::SingleSubscriberPublisher& subscriber);
  /// The whole map as a message; the caller holds the map's lock.
  mvog::MapBinary message() const;

  const std::string frame_id_;
  const SharedMap& map_;

  std::mutex mutex_;      // published_, and one publication at a time
  MapVersion published_;  // the map last published
  ros::Publisher publisher_;
  ros::Timer timer_;
};

}  // namespace mvog_ros
