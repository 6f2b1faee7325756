#include <memory>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include "mvog_ros/mapper.h"

namespace mvog_ros {

/// The mapping server as a nodelet: callbacks run on the manager's worker threads.
class MapperNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    try {
      mapper_ = std::make_unique<Mapper>(getMTNodeHandle(), getMTPrivateNodeHandle());
    } catch (const std::exception& e) {
      NODELET_FATAL("mvog: cannot start: %s", e.what());
      throw;
    }
  }

  std::unique_ptr<Mapper> mapper_;
};

}  // namespace mvog_ros

PLUGINLIB_EXPORT_CLASS(mvog_ros::MapperNodelet, nodelet::Nodelet)
