#include "mvog_ros/services/map_file_services.h"

#include <shared_mutex>
#include <string>
#include <utility>
#include <vector>

#include "mvog/map_io.h"
#include "mvog_ros/map_paths.h"

namespace mvog_ros {

mvog::Map initialMap(const MapFilesConfig& config, const mvog::MapConfig& map_config) {
  try {
    makeDirectories(config.map_directory);
  } catch (const PathRefused& e) {
    throw mvog::ConfigError("~map_directory: " + std::string(e.what()));
  }
  if (config.map_file.empty()) return mvog::Map(map_config);
  try {
    mvog::Map map = mvog::loadMap(resolveMapPath(config.map_directory, config.map_file, false));
    ROS_INFO("mvog: loaded ~map_file '%s' (resolution %.3f m)", config.map_file.c_str(),
             map.resolution());
    return map;
  } catch (const std::exception& e) {  // PathRefused or mvog::MapFileError
    throw mvog::ConfigError("~map_file: " + std::string(e.what()));
  }
}

MapFileServices::MapFileServices(ros::NodeHandle& private_nh, const MapFilesConfig& config,
                                 const SharedMap& shared_map, ReplaceMap replace_map)
    : config_(config),
      map_(shared_map),
      replace_map_(std::move(replace_map)),
      save_map_(private_nh.advertiseService("save_map", &MapFileServices::saveMap, this)),
      load_map_(private_nh.advertiseService("load_map", &MapFileServices::loadMap, this)) {
  if (config_.autosave_period > 0.0) {
    autosave_timer_ = private_nh.createTimer(ros::Duration(config_.autosave_period),
                                             [this](const ros::TimerEvent&) { autosave(); });
  }
}

bool MapFileServices::saveMap(mvog::MapFile::Request& request, mvog::MapFile::Response& response) {
  try {
    const std::string path = resolveMapPath(config_.map_directory, request.path, true);
    std::vector<std::uint8_t> bytes;
    {
      std::shared_lock<WriterPreferringMutex> lock(map_.mutex);
      bytes = mvog::serializeMap(map_.map);
    }
    mvog::saveMapBytes(bytes, path);  // without the map's lock
    response.message = "saved " + path;
    response.success = true;
  } catch (const std::exception& e) {
    response.message = e.what();
  }
  return true;
}

bool MapFileServices::loadMap(mvog::MapFile::Request& request, mvog::MapFile::Response& response) {
  try {
    const std::string path = resolveMapPath(config_.map_directory, request.path, false);
    mvog::Map loaded = mvog::loadMap(path);  // the current map stays untouched until this worked
    response.message = "loaded " + path;
    replace_map_(std::move(loaded));
    response.success = true;
  } catch (const std::exception& e) {
    response.message = e.what();
  }
  return true;
}

void MapFileServices::autosave() {
  std::lock_guard<std::mutex> autosave_lock(autosave_mutex_);
  try {
    MapVersion version;
    std::vector<std::uint8_t> bytes;
    {
      std::shared_lock<WriterPreferringMutex> lock(map_.mutex);
      version = map_.version();
      if (version == autosaved_) return;
      bytes = mvog::serializeMap(map_.map);
    }
    // Written without the map's lock: insertion and queries go on meanwhile.
    mvog::saveMapBytes(bytes, resolveMapPath(config_.map_directory, config_.autosave_file, true));
    autosaved_ = version;
  } catch (const std::exception& e) {
    ROS_WARN_THROTTLE(kWarningPeriod, "mvog: autosave failed: %s", e.what());
  }
}

void MapFileServices::autosaveOnShutdown() {
  autosave_timer_.stop();
  if (config_.autosave_period > 0.0) autosave();
}

}  // namespace mvog_ros
