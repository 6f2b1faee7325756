#pragma once

#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include "mvog_ros/inputs/map_update_input.h"
#include "mvog_ros/mapper_config.h"
#include "mvog_ros/publications/binary_map_publication.h"
#include "mvog_ros/publications/grid_publication.h"
#include "mvog_ros/publications/map_update_publication.h"
#include "mvog_ros/publications/marker_publication.h"
#include "mvog_ros/services/map_file_services.h"
#include "mvog_ros/services/query_services.h"
#include "mvog_ros/shared_map.h"

namespace mvog_ros {

/// A mirror of another server's map, shared by the nodelet mvog/MirrorNodelet and the node
/// mvog_mirror: the base station's view of a robot's map. Its map follows the source's updates
/// bit for bit (MapUpdateInput: `map_updates` and `get_map_update`, remappable) and it serves the
/// server's queries and publications with the server's parts, configured by the server's
/// parameters: markers, grids, ~map, ~map_updates and ~get_map_update (for mirrors further on),
/// ~get_occupancy, ~get_cross_section, ~save_map and autosave. It has no sensors, and nothing but
/// the updates writes its map: ~load_map is refused. Its map takes the source's configuration;
/// until the first update it is ~map_file if set (say, its last autosave), else empty.
class Mirror {
 public:
  /// Throws mvog::ConfigError naming the parameter at fault.
  Mirror(ros::NodeHandle nh, ros::NodeHandle private_nh);
  /// Takes no more updates, and autosaves once more (with autosave on).
  ~Mirror();
  Mirror(const Mirror&) = delete;
  Mirror& operator=(const Mirror&) = delete;

 private:
  const MapperConfig config_;
  SharedMap map_;
  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;

  MarkerPublication markers_;
  GridPublication grids_;
  BinaryMapPublication binary_map_;
  MapUpdatePublication map_updates_;
  QueryServices queries_;
  MapFileServices map_files_;
  MapUpdateInput input_;  // last: it writes the map the others read
};

}  // namespace mvog_ros
