#pragma once

#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include <ros/ros.h>

#include "mvog/GetMapUpdate.h"
#include "mvog/MapUpdate.h"
#include "mvog_ros/mapper_config.h"
#include "mvog_ros/shared_map.h"

namespace mvog_ros {

/// ~map_updates (mvog/MapUpdate) every ~binary_map_period when the map changed: what changed
/// since the previous update (mvog::serializeMapUpdate; a full update after the map was
/// replaced), the size of what changed, not of the map. And ~get_map_update (mvog/GetMapUpdate):
/// the update a mirror asks for to start or after it missed one (MapUpdateInput). Serialised under
/// the map's lock, sent after.
class MapUpdatePublication {
 public:
  MapUpdatePublication(ros::NodeHandle& private_nh, const PublicationsConfig& config,
                       const std::string& frame_id, const SharedMap& shared_map);

 private:
  void publishIfChanged(const ros::TimerEvent&);
  bool getMapUpdate(mvog::GetMapUpdate::Request& request, mvog::GetMapUpdate::Response& response);
  /// An update's bytes as a message.
  mvog::MapUpdate message(std::vector<std::uint8_t>&& bytes) const;

  const std::string frame_id_;
  const SharedMap& map_;

  std::mutex mutex_;  // sent_, and one publication at a time
  MapVersion sent_;   // the map the last update brought a mirror to
  ros::Publisher publisher_;
  ros::ServiceServer service_;
  ros::Timer timer_;
};

}  // namespace mvog_ros
