#include "mvog_ros/mapper.h"

#include <algorithm>
#include <mutex>
#include <shared_mutex>
#include <utility>

namespace mvog_ros {

Mapper::Mapper(const ros::NodeHandle& nh, ros::NodeHandle private_nh)
    : config_(MapperConfig::fromParameters(private_nh)),
      map_(initialMap(config_.map_files, config_.map)),
      tf_listener_(tf_buffer_, nh),
      insertion_(config_.insertion, map_),
      markers_(private_nh, config_.publications, config_.frame_id, config_.occupancy_threshold,
               map_),
      grids_(private_nh, config_.publications, config_.planning, config_.frame_id,
             config_.occupancy_threshold, config_.max_cross_section_cells, map_),
      frontiers_and_surfaces_(private_nh, config_.publications, config_.planning, config_.frame_id,
                              map_),
      binary_map_(private_nh, config_.publications, config_.frame_id, map_),
      map_updates_(private_nh, config_.publications, config_.frame_id, map_),
      queries_(private_nh, config_.queries, config_.frame_id, config_.occupancy_threshold,
               config_.max_cross_section_cells, config_.map.max_coordinate, map_, tf_buffer_),
      checks_(private_nh, config_.queries, config_.planning, config_.frame_id, map_, tf_buffer_),
#ifdef MVOG_HAVE_OMPL
      plan_path_(private_nh, config_.queries, config_.planning, config_.frame_id, map_, tf_buffer_),
#endif
      map_files_(private_nh, config_.map_files, map_,
                 [this](mvog::Map&& map) { replaceMap(std::move(map)); }),
      map_edits_(private_nh, config_.frame_id, config_.queries.tf_timeout,
                 config_.map_files.map_directory, map_, tf_buffer_),
      window_(private_nh, config_.lifetime, config_.frame_id, config_.map_files.map_directory,
              config_.publications.publish_period, map_, tf_buffer_,
              [this] { return insertion_.latestOrigin(); }),
      decay_(private_nh, config_.decay, config_.lifetime.forget_mass, map_),
      inputs_(nh, config_.inputs, config_.frame_id, config_.insertion.max_range,
              depthNoReturnLength(config_.insertion.max_range), tf_buffer_,
              [this](SensorReadings&& readings, const std::string& source) {
                insertion_.enqueue(std::move(readings), source);
              }),
      reset_(
          private_nh, map_, [this](mvog::Map&& map) { replaceMap(std::move(map)); },
          [this] {
            inputs_.resetStatistics();
            insertion_.resetStatistics();
          }),
      statistics_(private_nh, config_.publications, config_.frame_id, map_, inputs_, insertion_),
      reconfigure_(private_nh, config_,
                   [this](const MapperConfig& config) { reconfigure(config); }) {
  ROS_INFO("mvog: mapping in '%s' at %.3f m, %zu scan, %zu cloud and %zu depth image topics",
           config_.frame_id.c_str(), map_.map.resolution(), config_.inputs.scan_topics.size() + 1,
           config_.inputs.cloud_topics.size() + 1, config_.inputs.depth_topics.size());
}

Mapper::~Mapper() {
  inputs_.stop();
  decay_.stop();
  insertion_.stop();
  window_.stop();
  // A clean shutdown loses nothing mapped since the last autosave.
  map_files_.autosaveOnShutdown();
}

void Mapper::replaceMap(mvog::Map&& map) {
  {
    std::unique_lock<WriterPreferringMutex> lock(map_.mutex);
    map_.replace(std::move(map));
  }
  markers_.restartIfReplaced();
  grids_.restartIfReplaced();
  frontiers_and_surfaces_.restartIfReplaced();
}

double Mapper::depthNoReturnLength(double max_range) const {
  // A depth image's +Inf pixels (no return) free their ray as far as the core would free any
  // out-of-range reading: ~max_range, or the map's out_of_range_free_length if shorter.
  std::shared_lock<WriterPreferringMutex> lock(map_.mutex);
  return std::min(max_range, map_.map.config().rules.out_of_range_free_length);
}

void Mapper::reconfigure(const MapperConfig& config) {
  const double publish_period = config.publications.publish_period;
  markers_.reconfigure(publish_period, config.occupancy_threshold);
  grids_.reconfigure(config.publications, config.planning, config.occupancy_threshold);
  frontiers_and_surfaces_.reconfigure(publish_period, config.planning);
  queries_.setOccupancyThreshold(config.occupancy_threshold);
  checks_.setPlanning(config.planning);
#ifdef MVOG_HAVE_OMPL
  plan_path_.setPlanning(config.planning);
#endif
  window_.reconfigure(config.lifetime.keep_radius, publish_period);
  insertion_.reconfigure(config.insertion);
  inputs_.setMaxRange(config.insertion.max_range, depthNoReturnLength(config.insertion.max_range));
  decay_.reconfigure(config.decay, config.lifetime.forget_mass);
}

}  // namespace mvog_ros
