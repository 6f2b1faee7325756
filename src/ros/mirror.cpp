#include "mvog_ros/mirror.h"

#include <stdexcept>

namespace mvog_ros {

Mirror::Mirror(ros::NodeHandle nh, ros::NodeHandle private_nh)
    : config_(MapperConfig::fromParameters(private_nh)),
      map_(initialMap(config_.map_files, config_.map)),
      tf_listener_(tf_buffer_, nh),
      markers_(private_nh, config_.publications, config_.frame_id, config_.occupancy_threshold,
               map_),
      grids_(private_nh, config_.publications, config_.planning, config_.frame_id,
             config_.occupancy_threshold, config_.max_cross_section_cells, map_),
      binary_map_(private_nh, config_.publications, config_.frame_id, map_),
      map_updates_(private_nh, config_.publications, config_.frame_id, map_),
      queries_(private_nh, config_.queries, config_.frame_id, config_.occupancy_threshold,
               config_.max_cross_section_cells, config_.map.max_coordinate, map_, tf_buffer_),
      map_files_(
          private_nh, config_.map_files, map_,
          [](mvog::Map&&) {
            throw std::runtime_error("refused: a mirror's map follows its source's updates only");
          }),
      input_(nh, map_) {
  ROS_INFO("mvog: mirroring the map of %s in '%s'", nh.resolveName("map_updates").c_str(),
           config_.frame_id.c_str());
}

Mirror::~Mirror() {
  input_.stop();
  map_files_.autosaveOnShutdown();
}

}  // namespace mvog_ros
