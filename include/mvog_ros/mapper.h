#pragma once

#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include "mvog/map.h"
#include "mvog_ros/decay.h"
#include "mvog_ros/inputs/sensor_inputs.h"
#include "mvog_ros/insertion_worker.h"
#include "mvog_ros/local_window.h"
#include "mvog_ros/mapper_config.h"
#include "mvog_ros/publications/binary_map_publication.h"
#include "mvog_ros/publications/grid_publication.h"
#include "mvog_ros/publications/map_update_publication.h"
#include "mvog_ros/publications/marker_publication.h"
#include "mvog_ros/publications/planning_publication.h"
#include "mvog_ros/publications/statistics_publication.h"
#include "mvog_ros/runtime_reconfigure.h"
#include "mvog_ros/services/map_edit_services.h"
#include "mvog_ros/services/map_file_services.h"
#include "mvog_ros/services/planning_services.h"
#ifdef MVOG_HAVE_OMPL
#include "mvog_ros/services/plan_path_service.h"
#endif
#include "mvog_ros/services/query_services.h"
#include "mvog_ros/services/reset_service.h"
#include "mvog_ros/shared_map.h"

namespace mvog_ros {

/// The mapping server, shared by the nodelet and the node. It owns the map and its lock
/// (SharedMap) and composes the parts that use them, each with its slice of MapperConfig:
///   sensor inputs      subscribe, wait for tf, convert (SensorInputs: inputs/)
///   insertion worker   bounded queue and thread, the only writer of readings (InsertionWorker)
///   publications       markers, grids, frontiers and surfaces, binary map, map updates,
///                      statistics (publications/)
///   services           queries, segment and box checks, map files and autosave, clear_box and
///                      merge_map, reset, plan_path with OMPL (services/)
///   local window       tiles far from the robot dropped and saved (LocalWindow)
///   decay              decay and forgetting (Decay)
///   reconfiguration    dynamic_reconfigure (RuntimeReconfigure), applied by reconfigure()
/// Callbacks may run on several threads at once.
class Mapper {
 public:
  /// Throws mvog::ConfigError naming the parameter at fault (~map_file if it cannot be loaded).
  Mapper(const ros::NodeHandle& nh, ros::NodeHandle private_nh);
  /// Stops the inputs, inserts what is queued, writes the dropped tiles not written yet, and
  /// autosaves once more (with autosave on).
  ~Mapper();
  Mapper(const Mapper&) = delete;
  Mapper& operator=(const Mapper&) = delete;

 private:
  /// Puts `map` in place of the server's (~load_map, ~reset); the publications clear what they
  /// showed of the previous one at once.
  void replaceMap(mvog::Map&& map);
  /// Gives the parts the values in force (validated by RuntimeReconfigure), each under its lock.
  void reconfigure(const MapperConfig& config);
  /// Where a depth image's +Inf pixels (no return) end with ~max_range `max_range`.
  double depthNoReturnLength(double max_range) const;

  const MapperConfig config_;  // at start (RuntimeReconfigure holds the values in force)
  SharedMap map_;
  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;

  // The parts, in the order they start. The inputs come once everything they feed exists, the
  // reset service and the statistics once the counts they use do; they end in reverse order.
  InsertionWorker insertion_;
  MarkerPublication markers_;
  GridPublication grids_;
  PlanningPublication frontiers_and_surfaces_;
  BinaryMapPublication binary_map_;
  MapUpdatePublication map_updates_;
  QueryServices queries_;
  PlanningServices checks_;
#ifdef MVOG_HAVE_OMPL
  PlanPathService plan_path_;
#endif
  MapFileServices map_files_;
  MapEditServices map_edits_;
  LocalWindow window_;
  Decay decay_;
  SensorInputs inputs_;
  ResetService reset_;
  StatisticsPublication statistics_;
  RuntimeReconfigure reconfigure_;
};

}  // namespace mvog_ros
