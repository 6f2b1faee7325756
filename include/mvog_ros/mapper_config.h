#pragma once

#include <limits>
#include <string>
#include <vector>

#include <ros/node_handle.h>

#include "mvog/config.h"
#include "mvog/planning_config.h"

namespace mvog_ros {

/// s between two warnings of one kind (ROS_WARN_THROTTLE): bad input is counted in ~statistics
/// and warned about now and then, not once per message.
constexpr double kWarningPeriod = 5.0;

// Every parameter of the mapping server, with its default, in one slice per part of the server.
// Every field is named as its parameter. Read in one place (MapperConfig::fromParameters) and
// validated at start: an invalid value refuses to start, naming the parameter.

/// The sensor inputs (SensorInputs): the topics they subscribe to and what they accept.
struct SensorInputsConfig {
  std::vector<std::string> scan_topics;   // LaserScan topics besides `scan`
  std::vector<std::string> cloud_topics;  // PointCloud2 topics besides `cloud_in`
  std::vector<std::string> depth_topics;  // depth images, each with its sibling `camera_info`
  int sensor_queue_size = 5;              // messages per topic waiting for their transform
  double voxel_filter_size = 0.0;         // m; > 0 downsamples clouds before insertion
  int depth_stride = 1;                   // every k-th pixel of depth images in both directions
  int max_points_per_message = 2000000;   // larger messages are refused

  void validate() const;
};

/// The insertion worker (InsertionWorker): the core's insertion parameters (~min_range,
/// ~max_range, ~insert_out_of_range, ~model_negative_space, ~insertion_threads,
/// ~free_space_rays, ~evidence_limit, ~hit_memory_scans, ~hit_memory_scope), and its queue.
/// The model's rules are the map's (MapperConfig::map: ~model, ~clip_free_space_at_hits, ...).
struct InsertionWorkerConfig : mvog::InsertionConfig {
  int insertion_queue_size = 3;  // converted messages waiting to be inserted
  // Threads per insertion of a scan of 10,000 readings or more while another message waits
  // behind it, if more than insertion_threads (the map is the same for any count): a sensor that
  // outpaces one core gets both of a 2-core robot's.
  int backlog_insertion_threads = 2;

  void validate() const;
};

/// ~free_space_rays: `one_per_end_voxel` (FreeSpaceRays::kOnePerEndVoxel, the default),
/// `one_path_per_end_column` (kOnePathPerEndColumn) or `every_reading` (kEveryReading). Throws
/// mvog::ConfigError naming the parameter for any other name.
mvog::FreeSpaceRays freeSpaceRaysFromName(const std::string& name);

/// ~hit_memory_scope: `line_scans` (HitMemoryScope::kLineScans, the default) or `every_scan`
/// (kEveryScan). Throws mvog::ConfigError naming the parameter for any other name.
mvog::HitMemoryScope hitMemoryScopeFromName(const std::string& name);

/// Decay (Sec. III-E): masses times decay_factor every decay_period seconds.
struct DecayConfig {
  double decay_factor = 1.0;
  double decay_period = 0.0;  // s (0: off)

  bool enabled() const { return decay_period > 0.0 && decay_factor < 1.0; }
  void validate() const;
};

/// A map's lifetime: forgetting after each decay step (Mapper) and the local window
/// (LocalWindow).
struct LifetimeConfig {
  double forget_mass = 0.0;  // after each decay step, volumes lighter than this go (0: off)
  double keep_radius = 0.0;  // m (xy) around the robot: tiles wholly farther are dropped (0: off)
  std::string robot_frame;   // the window's centre; empty: where the latest scan was taken from
  // In map_directory: the dropped tiles are merged into it (empty: they are discarded).
  std::string keep_radius_save_file = "dropped_tiles.mvog";

  /// `decay`: forgetting needs it (nothing else makes volumes lighter).
  void validate(const DecayConfig& decay) const;
};

/// The publications (MarkerPublication, GridPublication, BinaryMapPublication,
/// MapUpdatePublication, StatisticsPublication).
struct PublicationsConfig {
  std::vector<double> cross_section_heights;  // m, one ~cross_section_K grid each
  double projection_min_z = -std::numeric_limits<double>::infinity();  // band of ~projected_map
  double projection_max_z = std::numeric_limits<double>::infinity();
  double publish_period = 1.0;  // s, markers and grids (only what changed)
  double binary_map_period =
      5.0;  // s, the whole map on ~map, what changed on ~map_updates (0: off)
  double statistics_period = 1.0;  // s, ~statistics and /diagnostics

  /// `map`: the cross-section heights must lie within its max_coordinate.
  void validate(const mvog::MapConfig& map) const;
};

/// The query services (QueryServices, PlanningServices).
struct QueryServicesConfig {
  double tf_timeout = 0.2;  // s to wait for the transform of a query's frame
  // larger ~get_occupancy requests are refused, and ~check_segments, ~check_boxes requests of
  // more segments or boxes
  int max_query_points = 1000000;

  void validate() const;
};

/// Map files (MapFileServices): the root of ~save_map and ~load_map, the map loaded at start,
/// autosave.
struct MapFilesConfig {
  std::string map_directory;     // default $ROS_HOME/mvog_maps
  std::string map_file;          // loaded at start if set (relative to map_directory)
  double autosave_period = 0.0;  // s (0: off)
  std::string autosave_file = "autosave.mvog";

  void validate() const;
};

/// Every parameter of the mapping server: the map's, those several parts share, and one slice
/// per part.
struct MapperConfig {
  mvog::MapConfig map;           // ~resolution, ~max_coordinate
  std::string frame_id = "map";  // the map frame
  // p above it is occupied: markers, grids, queries (~model: paper makes it the paper's 0.5)
  double occupancy_threshold = mvog::kDefaultOccupancyThreshold;
  int max_cross_section_cells = 16000000;  // the largest grid published or sent on request

  SensorInputsConfig inputs;
  InsertionWorkerConfig insertion;
  DecayConfig decay;
  LifetimeConfig lifetime;
  PublicationsConfig publications;
  QueryServicesConfig queries;
  MapFilesConfig map_files;
  // What planners and explorers ask (PlanningServices, PlanningPublication, the traversable map
  // of GridPublication): ~max_query_cells, ~frontier_min_z, ~frontier_max_z (by default the
  // projection band), ~frontier_min_cells, ~robot_height, ~max_step, ~traversable_min_z,
  // ~traversable_max_z; its occupancy_threshold is ~occupancy_threshold (fromParameters sets it).
  mvog::PlanningConfig planning;

  /// Throws mvog::ConfigError naming the first invalid parameter.
  void validate() const;
  /// Reads every parameter from the private node handle and validates them.
  static MapperConfig fromParameters(const ros::NodeHandle& private_nh);
};

}  // namespace mvog_ros
