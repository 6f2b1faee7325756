// The mapping server as a standalone node (the same Mapper as the nodelet).
#include "mvog_ros/mapper.h"
#include "mvog_ros/server_process.h"

int main(int argc, char** argv) {
  return mvog_ros::runServerNode<mvog_ros::Mapper>(argc, argv, "mvog_mapper");
}
