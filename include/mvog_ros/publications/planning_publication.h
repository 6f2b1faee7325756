#pragma once

#include <string>
#include <vector>

#include <ros/ros.h>

#include "mvog/frontiers.h"
#include "mvog/planning_config.h"
#include "mvog/surfaces.h"
#include "mvog_ros/mapper_config.h"
#include "mvog_ros/publications/change_publication.h"
#include "mvog_ros/shared_map.h"

namespace mvog_ros {

/// What explorers and planners look at, latched: ~frontiers (sensor_msgs/PointCloud2: x, y, z,
/// cluster) and ~frontier_markers (visualization_msgs/MarkerArray) of the band [~frontier_min_z,
/// ~frontier_max_z], and ~surfaces (sensor_msgs/PointCloud2: x, y, z, clearance, probability).
/// Every ~publish_period, while someone subscribes, the frontiers and surfaces are brought up to
/// date tile by tile (mvog::Frontiers, mvog::Surfaces: they recompute the tiles changed since
/// their last update) and published if they changed; a new subscriber is sent them at once.
class PlanningPublication : public ChangePublication {
 public:
  /// `planning`: the frontiers' band and smallest piece, the occupancy threshold.
  PlanningPublication(ros::NodeHandle& private_nh, const PublicationsConfig& config,
                      const mvog::PlanningConfig& planning, const std::string& frame_id,
                      const SharedMap& shared_map);
  ~PlanningPublication() override;

  /// New values, validated already (the occupancy threshold): the frontiers and surfaces are
  /// recomputed and published afresh at once.
  void reconfigure(double publish_period, const mvog::PlanningConfig& planning);

 private:
  enum class Output { kFrontiers, kFrontierMarkers, kSurfaces };

  /// Empty clouds and a DELETEALL: a new subscriber is not shown the previous map.
  void clearPublished() override;
  /// The tiles changed are not needed: Frontiers and Surfaces keep track of them themselves.
  void publishTiles(const std::vector<mvog::TileIndex>& changed) override;
  void send(const ros::SingleSubscriberPublisher& subscriber, Output output);
  /// Brings the frontiers or the surfaces up to date with the map; `unpublished` becomes true if
  /// they changed (the next publication sends them to every subscriber).
  template <class Results>
  void bringUpToDate(Results& results, bool& unpublished);
  void publishFrontiers(const ros::Time& stamp);

  const std::string frame_id_;
  mvog::Frontiers frontiers_;
  mvog::Surfaces surfaces_;
  bool frontiers_unpublished_ = false;  // changed since last published (in send: to one only)
  bool surfaces_unpublished_ = false;
  ros::Publisher frontiers_publisher_;
  ros::Publisher frontier_markers_publisher_;
  ros::Publisher surfaces_publisher_;
};

}  // namespace mvog_ros
