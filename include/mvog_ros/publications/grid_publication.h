#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <ros/ros.h>

#include "mvog/planning_config.h"
#include "mvog_ros/mapper_config.h"
#include "mvog_ros/publications/change_publication.h"
#include "mvog_ros/shared_map.h"
#include "mvog_ros/visualization.h"

namespace mvog_ros {

/// ~projected_map (the band [~projection_min_z, ~projection_max_z]: occupied, free or unknown),
/// ~cross_section_K (p at the K-th of ~cross_section_heights) and ~traversable_map (where a
/// ground robot can go: mvog::traversableMap) as nav_msgs/OccupancyGrid, latched, each kept up to
/// date tile by tile (IncrementalGrid): every ~publish_period the grid if it changed, and on
/// ~..._updates (map_msgs/OccupancyGridUpdate) the rectangle that changed. No grid larger than
/// ~max_cross_section_cells is published.
class GridPublication : public ChangePublication {
 public:
  /// `planning`: the robot and the band of the traversable map.
  GridPublication(ros::NodeHandle& private_nh, const PublicationsConfig& config,
                  const mvog::PlanningConfig& planning, const std::string& frame_id,
                  double occupancy_threshold, int max_cross_section_cells,
                  const SharedMap& shared_map);
  ~GridPublication() override;

  /// New values, validated already (as many cross-section heights as at start): every grid is
  /// computed and published afresh with them at once.
  void reconfigure(const PublicationsConfig& config, const mvog::PlanningConfig& planning,
                   double occupancy_threshold);

 private:
  /// One grid: the projected map, or one cross-section.
  struct Layer {
    IncrementalGrid grid;
    /// Whether a cell's value depends on its four neighbours (the traversable map): a change of
    /// a tile changes its neighbour tiles too.
    bool reads_neighbours;
    ros::Publisher publisher;
    ros::Publisher updates_publisher;
  };

  /// Every grid as unknown: a new subscriber is not shown the previous map.
  void clearPublished() override;
  void publishTiles(const std::vector<mvog::TileIndex>& changed) override;
  void send(const ros::SingleSubscriberPublisher& subscriber, std::size_t layer);
  /// Brings `layer` up to date (IncrementalGrid::update): the rectangle that changed, or nothing
  /// (with a warning) if the map has outgrown ~max_cross_section_cells.
  std::optional<mvog::CellRange> update(Layer& layer, const std::vector<mvog::TileIndex>& changed,
                                        bool& relaid_out);

  const std::string frame_id_;
  const int max_cross_section_cells_;
  // The projected map, one per ~cross_section_heights entry, the traversable map.
  std::vector<Layer> layers_;
};

}  // namespace mvog_ros
