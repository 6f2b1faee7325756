#pragma once

#include <memory>

#include <nodelet/nodelet.h>
#include <ros/ros.h>

namespace mvog_ros {

/// The main() of a server's node (Mapper, Mirror): the server on a 4-thread spinner (queries and
/// publication beside its inputs) until shutdown. Returns 1 if it refuses to start.
template <class Server>
int runServerNode(int argc, char** argv, const char* default_name) {
  ros::init(argc, argv, default_name);
  // Held until main returns: when the last NodeHandle goes, roscpp shuts down, logging with it,
  // and a refusal to start would go unreported.
  ros::NodeHandle nh;
  ros::NodeHandle private_nh("~");
  try {
    Server server(nh, private_nh);
    ros::AsyncSpinner spinner(4);
    spinner.start();
    ros::waitForShutdown();
  } catch (const std::exception& e) {
    ROS_FATAL("mvog: cannot start: %s", e.what());
    return 1;
  }
  return 0;
}

/// A server as a nodelet: callbacks run on the manager's worker threads.
template <class Server>
class ServerNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    try {
      server_ = std::make_unique<Server>(getMTNodeHandle(), getMTPrivateNodeHandle());
    } catch (const std::exception& e) {
      NODELET_FATAL("mvog: cannot start: %s", e.what());
      throw;
    }
  }

  std::unique_ptr<Server> server_;
};

}  // namespace mvog_ros
