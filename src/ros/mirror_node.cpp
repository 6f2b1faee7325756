// A mirror of another server's map as a standalone node (the same Mirror as the nodelet).
#include "mvog_ros/mirror.h"
#include "mvog_ros/server_process.h"

int main(int argc, char** argv) {
  return mvog_ros::runServerNode<mvog_ros::Mirror>(argc, argv, "mvog_mirror");
}
