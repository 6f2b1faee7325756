#include "mvog_ros/publications/grid_publication.h"

#include <algorithm>
#include <shared_mutex>

#include <map_msgs/OccupancyGridUpdate.h>
#include <nav_msgs/OccupancyGrid.h>

#include "mvog/tile_changes.h"
#include "mvog_ros/planning_messages.h"

namespace mvog_ros {

namespace {

/// The grids GridPublication keeps, in the order of its layers: the projected map, one per
/// cross-section height, the traversable map.
std::vector<IncrementalGrid> makeGrids(const PublicationsConfig& config,
                                       const mvog::PlanningConfig& planning,
                                       double occupancy_threshold, int max_cross_section_cells) {
  const double min_z = config.projection_min_z;
  const double max_z = config.projection_max_z;
  std::vector<IncrementalGrid> grids;
  grids.emplace_back(
      min_z, max_cross_section_cells,
      [min_z, max_z, occupancy_threshold](const mvog::Map& map, const mvog::CellRange& cells) {
        return toOccupancyGrid(map.projection(min_z, max_z, occupancy_threshold, cells), 0.0, "",
                               ros::Time())
            .data;
      });
  for (const double height : config.cross_section_heights) {
    grids.emplace_back(
        height, max_cross_section_cells,
        [height](const mvog::Map& map, const mvog::CellRange& cells) {
          return toOccupancyGrid(map.crossSection(height, cells), height, "", ros::Time()).data;
        });
  }
  // Drawn at the height of the band nearest z = 0, the ground of a map frame by REP-105.
  grids.emplace_back(std::clamp(0.0, planning.traversable_min_z, planning.traversable_max_z),
                     max_cross_section_cells,
                     [planning](const mvog::Map& map, const mvog::CellRange& cells) {
                       return traversableGridData(map, cells, planning);
                     });
  return grids;
}

}  // namespace

GridPublication::GridPublication(ros::NodeHandle& private_nh, const PublicationsConfig& config,
                                 const mvog::PlanningConfig& planning, const std::string& frame_id,
                                 double occupancy_threshold, int max_cross_section_cells,
                                 const SharedMap& shared_map)
    : ChangePublication(shared_map),
      frame_id_(frame_id),
      max_cross_section_cells_(max_cross_section_cells) {
  std::vector<IncrementalGrid> grids =
      makeGrids(config, planning, occupancy_threshold, max_cross_section_cells);
  std::vector<std::string> topics{"projected_map"};
  for (std::size_t k = 0; k < config.cross_section_heights.size(); ++k) {
    topics.push_back("cross_section_" + std::to_string(k));
    ROS_INFO("mvog: ~%s is the cross-section at z = %.3f m", topics.back().c_str(),
             config.cross_section_heights[k]);
  }
  topics.push_back("traversable_map");
  // A subscriber's connection callback may run on another thread as soon as its topic is
  // advertised: it waits for the layers to be complete.
  std::lock_guard<std::mutex> publication_lock(mutex_);
  for (std::size_t k = 0; k < grids.size(); ++k) {
    const bool reads_neighbours = k + 1 == grids.size();  // the traversable map
    layers_.push_back({std::move(grids[k]), reads_neighbours, ros::Publisher(), ros::Publisher()});
    layers_[k].publisher = private_nh.advertise<nav_msgs::OccupancyGrid>(
        topics[k], 1,
        [this, k](const ros::SingleSubscriberPublisher& subscriber) { send(subscriber, k); },
        ros::SubscriberStatusCallback(), ros::VoidConstPtr(), true);
    layers_[k].updates_publisher =
        private_nh.advertise<map_msgs::OccupancyGridUpdate>(topics[k] + "_updates", 10);
  }
  start(private_nh, config.publish_period);
}

void GridPublication::reconfigure(const PublicationsConfig& config,
                                  const mvog::PlanningConfig& planning,
                                  double occupancy_threshold) {
  std::vector<IncrementalGrid> grids =
      makeGrids(config, planning, occupancy_threshold, max_cross_section_cells_);
  ChangePublication::reconfigure(config.publish_period, [&] {
    // As many grids as layers: the number of cross-sections (their topics) is start-only.
    for (std::size_t k = 0; k < layers_.size(); ++k) layers_[k].grid = std::move(grids.at(k));
  });
  for (std::size_t k = 0; k < config.cross_section_heights.size(); ++k) {
    ROS_INFO("mvog: ~cross_section_%zu is the cross-section at z = %.3f m", k,
             config.cross_section_heights[k]);
  }
}

GridPublication::~GridPublication() { stop(); }

void GridPublication::clearPublished() {
  // The latched grids would show the previous map to every new subscriber: replace them by
  // unknown ones until the new map has something to show.
  const ros::Time stamp = ros::Time::now();
  for (Layer& layer : layers_) {
    nav_msgs::OccupancyGrid unknown = layer.grid.grid();
    if (!unknown.data.empty()) {
      std::fill(unknown.data.begin(), unknown.data.end(), std::int8_t{-1});
      unknown.header.frame_id = frame_id_;
      unknown.header.stamp = stamp;
      unknown.info.map_load_time = stamp;
      layer.publisher.publish(unknown);
    }
    layer.grid.clear();
  }
}

void GridPublication::publishTiles(const std::vector<mvog::TileIndex>& changed) {
  const ros::Time stamp = ros::Time::now();
  for (Layer& layer : layers_) {
    bool relaid_out = false;
    const std::optional<mvog::CellRange> touched = update(layer, changed, relaid_out);
    if (!touched || touched->empty()) continue;
    nav_msgs::OccupancyGrid grid = layer.grid.grid();
    grid.header.frame_id = frame_id_;
    grid.header.stamp = stamp;
    grid.info.map_load_time = stamp;
    if (layer.publisher.getNumSubscribers() > 0) layer.publisher.publish(grid);
    if (!relaid_out && layer.updates_publisher.getNumSubscribers() > 0) {
      map_msgs::OccupancyGridUpdate update = layer.grid.updateOf(*touched);
      update.header = grid.header;
      layer.updates_publisher.publish(update);
    }
  }
}

void GridPublication::send(const ros::SingleSubscriberPublisher& subscriber, std::size_t layer) {
  std::lock_guard<std::mutex> publication_lock(mutex_);
  std::shared_lock<WriterPreferringMutex> lock(map_.mutex);
  // The grids are brought up to the map for every subscriber first: were they updated for the
  // new one alone, the next publication would find nothing changed there, and the others would
  // never be sent those cells.
  publishChangesLocked();
  const Layer& sent = layers_[layer];
  if (sent.grid.cells().empty()) return;  // nothing mapped yet, or too large from the start
  nav_msgs::OccupancyGrid grid = sent.grid.grid();
  grid.header.frame_id = frame_id_;
  grid.header.stamp = ros::Time::now();
  subscriber.publish(grid);
}

std::optional<mvog::CellRange> GridPublication::update(Layer& layer,
                                                       const std::vector<mvog::TileIndex>& changed,
                                                       bool& relaid_out) {
  try {
    return layer.grid.update(
        map_.map, layer.reads_neighbours ? mvog::withNeighbourTiles(changed) : changed, relaid_out);
  } catch (const GridTooLarge& e) {
    ROS_WARN_THROTTLE(kWarningPeriod,
                      "mvog: %s not published: %s, more than ~max_cross_section_cells (%d); "
                      "readings far away? (~max_coordinate, ~max_range)",
                      layer.publisher.getTopic().c_str(), e.what(), max_cross_section_cells_);
    return std::nullopt;
  }
}

}  // namespace mvog_ros
