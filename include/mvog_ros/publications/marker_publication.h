#pragma once

#include <string>
#include <vector>

#include <ros/ros.h>

#include "mvog_ros/mapper_config.h"
#include "mvog_ros/publications/change_publication.h"
#include "mvog_ros/shared_map.h"

namespace mvog_ros {

/// ~volumes (positive and negative volumes) and ~occupied (space with p > ~occupancy_threshold,
/// coloured by height) as visualization_msgs/MarkerArray, latched: every ~publish_period the
/// markers of the tiles changed since the last publication, and to a new subscriber all of them
/// after a DELETEALL.
class MarkerPublication : public ChangePublication {
 public:
  MarkerPublication(ros::NodeHandle& private_nh, const PublicationsConfig& config,
                    const std::string& frame_id, double occupancy_threshold,
                    const SharedMap& shared_map);
  ~MarkerPublication() override;

  /// New values, validated already: the markers are published afresh with them at once.
  void reconfigure(double publish_period, double occupancy_threshold);

 private:
  void clearPublished() override;
  void publishTiles(const std::vector<mvog::TileIndex>& changed) override;
  void sendAll(const ros::SingleSubscriberPublisher& subscriber, bool occupied_only);

  const std::string frame_id_;
  double occupancy_threshold_;  // under mutex_
  ros::Publisher volumes_publisher_;
  ros::Publisher occupied_publisher_;
};

}  // namespace mvog_ros
