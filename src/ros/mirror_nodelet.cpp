#include <pluginlib/class_list_macros.hpp>

#include "mvog_ros/mirror.h"
#include "mvog_ros/server_process.h"

namespace mvog_ros {

/// A mirror of another server's map as a nodelet.
class MirrorNodelet : public ServerNodelet<Mirror> {};

}  // namespace mvog_ros

PLUGINLIB_EXPORT_CLASS(mvog_ros::MirrorNodelet, nodelet::Nodelet)
