#include <pluginlib/class_list_macros.hpp>

#include "mvog_ros/mapper.h"
#include "mvog_ros/server_process.h"

namespace mvog_ros {

/// The mapping server as a nodelet.
class MapperNodelet : public ServerNodelet<Mapper> {};

}  // namespace mvog_ros

PLUGINLIB_EXPORT_CLASS(mvog_ros::MapperNodelet, nodelet::Nodelet)
