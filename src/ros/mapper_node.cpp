// The mapping server as a standalone node (the same Mapper as the nodelet).
#include <ros/ros.h>

#include "mvog_ros/mapper.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "mvog_mapper");
  // Held until main returns: when the last NodeHandle goes, roscpp shuts down, logging with it,
  // and a refusal to start would go unreported.
  ros::NodeHandle nh;
  ros::NodeHandle private_nh("~");
  try {
    mvog_ros::Mapper mapper(nh, private_nh);
    ros::AsyncSpinner spinner(4);  // queries and publication beside the sensor callbacks
    spinner.start();
    ros::waitForShutdown();
  } catch (const std::exception& e) {
    ROS_FATAL("mvog: cannot start: %s", e.what());
    return 1;
  }
  return 0;
}
