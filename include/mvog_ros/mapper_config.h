#pragma once

#include <limits>
#include <string>
#include <vector>

#include <ros/node_handle.h>

#include "mvog/config.h"

namespace mvog_ros {

/// Every parameter of the mapping server, with its default. Read in one place (fromParameters)
/// and validated at start: an invalid value refuses to start, naming the parameter.
struct MapperConfig {
  // Map and insertion (the core's own configs).
  mvog::MapConfig map;              // ~resolution, ~max_coordinate
  mvog::InsertionConfig insertion;  // ~min_range, ~max_range, ~insert_out_of_range,
                                    // ~model_negative_space, ~clear_conflicting_free_space,
                                    // ~insertion_threads
  std::string frame_id = "map";

  // Inputs.
  std::vector<std::string> scan_topics;   // ~scan_topics, besides the `scan` topic
  std::vector<std::string> cloud_topics;  // ~cloud_topics, besides the `cloud_in` topic
  int sensor_queue_size = 5;              // messages per topic waiting for their transform
  int insertion_queue_size = 3;           // transformed messages waiting to be inserted
  double tf_timeout = 0.2;                // s, for the query service's transforms
  double voxel_filter_size = 0.0;         // m; > 0 downsamples clouds before insertion
  int max_points_per_message = 2000000;   // larger messages are refused

  // Decay (Sec. III-E): masses times decay_factor every decay_period seconds (0: off).
  double decay_factor = 1.0;
  double decay_period = 0.0;

  // Outputs.
  double occupancy_threshold = 0.5;
  std::vector<double> cross_section_heights;
  double projection_min_z = -std::numeric_limits<double>::infinity();
  double projection_max_z = std::numeric_limits<double>::infinity();
  double publish_period = 1.0;     // s, markers and grids (only what changed)
  double binary_map_period = 5.0;  // s, the whole map on ~map (0: off)
  double statistics_period = 1.0;  // s

  // Files.
  std::string map_directory;     // save/load root; default $ROS_HOME/mvog_maps
  std::string map_file;          // loaded at start if set (relative to map_directory)
  double autosave_period = 0.0;  // s (0: off)
  std::string autosave_file = "autosave.mvog";

  // Service limits.
  int max_query_points = 1000000;
  int max_cross_section_cells = 16000000;  // also the largest grid published

  /// Throws mvog::ConfigError naming the first invalid parameter.
  void validate() const;
  /// Reads every parameter from the private node handle and validates them.
  static MapperConfig fromParameters(const ros::NodeHandle& private_nh);
};

}  // namespace mvog_ros
