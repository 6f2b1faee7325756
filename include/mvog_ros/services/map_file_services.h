#pragma once

#include <cstdint>
#include <functional>
#include <mutex>

#include <ros/ros.h>

#include "mvog/MapFile.h"
#include "mvog/map.h"
#include "mvog_ros/mapper_config.h"
#include "mvog_ros/shared_map.h"

namespace mvog_ros {

/// Creates ~map_directory if missing and returns the map a server starts with: ~map_file if set,
/// else an empty one with `map_config`. Throws mvog::ConfigError naming the parameter at fault.
mvog::Map initialMap(const MapFilesConfig& config, const mvog::MapConfig& map_config);

/// Puts a map in place of the server's (Mapper::replaceMap).
using ReplaceMap = std::function<void(mvog::Map&& map)>;

/// ~save_map and ~load_map (mvog/MapFile: paths inside ~map_directory, map_paths.h), and the
/// autosave of ~autosave_file every ~autosave_period when the map changed. Files are written
/// atomically (mvog::saveMapBytes), without the map's lock: the map is only serialised under it.
class MapFileServices {
 public:
  MapFileServices(ros::NodeHandle& private_nh, const MapFilesConfig& config,
                  const SharedMap& shared_map, ReplaceMap replace_map);

  /// With autosave on, saves the map once more if it changed (a clean shutdown loses nothing).
  void autosaveOnShutdown();

 private:
  bool saveMap(mvog::MapFile::Request& request, mvog::MapFile::Response& response);
  bool loadMap(mvog::MapFile::Request& request, mvog::MapFile::Response& response);
  /// Saves ~autosave_file if the map changed since the last autosave (a warning if it fails).
  void autosave();

  const MapFilesConfig config_;
  const SharedMap& map_;
  const ReplaceMap replace_map_;

  std::mutex autosave_mutex_;  // one autosave at a time (timer, shutdown); guards autosaved_
  MapVersion autosaved_;       // the map last autosaved
  ros::ServiceServer save_map_;
  ros::ServiceServer load_map_;
  ros::Timer autosave_timer_;
};

}  // namespace mvog_ros
