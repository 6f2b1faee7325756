#pragma once

#include <atomic>
#include <string>

#include <ros/ros.h>
#include <tf2_ros/buffer.h>

#include "mvog/GetCrossSection.h"
#include "mvog/GetOccupancy.h"
#include "mvog_ros/mapper_config.h"
#include "mvog_ros/shared_map.h"

namespace mvog_ros {

/// ~get_occupancy (points in any frame: occupied, free or unknown, with p) and
/// ~get_cross_section (p at a height over the map or a rectangle). Refused requests get a
/// message saying why.
class QueryServices {
 public:
  QueryServices(ros::NodeHandle& private_nh, const QueryServicesConfig& config,
                const std::string& frame_id, double occupancy_threshold,
                int max_cross_section_cells, double max_coordinate, const SharedMap& shared_map,
                const tf2_ros::Buffer& tf_buffer);

  /// Validated already: the next request uses it.
  void setOccupancyThreshold(double occupancy_threshold);

 private:
  bool getOccupancy(mvog::GetOccupancy::Request& request, mvog::GetOccupancy::Response& response);
  bool getCrossSection(mvog::GetCrossSection::Request& request,
                       mvog::GetCrossSection::Response& response);

  const QueryServicesConfig config_;
  const std::string frame_id_;
  std::atomic<double> occupancy_threshold_;  // read once per request
  const int max_cross_section_cells_;
  const double max_coordinate_;  // ~max_coordinate: no rectangle beyond it is cut
  const SharedMap& map_;
  const tf2_ros::Buffer& tf_buffer_;
  ros::ServiceServer get_occupancy_;
  ros::ServiceServer get_cross_section_;
};

}  // namespace mvog_ros
