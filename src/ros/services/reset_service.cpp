#include "mvog_ros/services/reset_service.h"

#include <shared_mutex>
#include <utility>

namespace mvog_ros {

ResetService::ResetService(ros::NodeHandle& private_nh, const SharedMap& shared_map,
                           ReplaceMap replace_map, std::function<void()> reset_statistics)
    : map_(shared_map),
      replace_map_(std::move(replace_map)),
      reset_statistics_(std::move(reset_statistics)),
      service_(private_nh.advertiseService("reset", &ResetService::reset, this)) {}

bool ResetService::reset(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& response) {
  mvog::MapConfig config;
  {
    std::shared_lock<WriterPreferringMutex> lock(map_.mutex);
    config = map_.map.config();
  }
  replace_map_(mvog::Map(config));
  reset_statistics_();
  response.success = true;
  response.message = "the map is empty";
  return true;
}

}  // namespace mvog_ros
