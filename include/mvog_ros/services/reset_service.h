#pragma once

#include <functional>

#include <ros/ros.h>
#include <std_srvs/Trigger.h>

#include "mvog_ros/services/map_file_services.h"
#include "mvog_ros/shared_map.h"

namespace mvog_ros {

/// ~reset (std_srvs/Trigger): an empty map, of the same resolution and extent, in place of the
/// server's, and the statistics start again from zero.
class ResetService {
 public:
  ResetService(ros::NodeHandle& private_nh, const SharedMap& shared_map, ReplaceMap replace_map,
               std::function<void()> reset_statistics);

 private:
  bool reset(std_srvs::Trigger::Request& request, std_srvs::Trigger::Response& response);

  const SharedMap& map_;
  const ReplaceMap replace_map_;
  const std::function<void()> reset_statistics_;
  ros::ServiceServer service_;
};

}  // namespace mvog_ros
