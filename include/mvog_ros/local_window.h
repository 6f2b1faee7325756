#pragma once

#include <atomic>
#include <functional>
#include <mutex>
#include <optional>
#include <string>

#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <Eigen/Core>

#include "mvog/map.h"
#include "mvog_ros/mapper_config.h"
#include "mvog_ros/shared_map.h"

namespace mvog_ros {

/// Where the latest scan inserted was taken from (InsertionWorker::latestOrigin).
using LatestScanOrigin = std::function<std::optional<Eigen::Vector3d>()>;

/// ~keep_radius: every ~publish_period, the tiles wholly farther than ~keep_radius in xy from the
/// robot (the origin of ~robot_frame, or where the latest scan was taken from) leave the map
/// (mvog::Map::dropTilesFartherThan) and are merged into ~keep_radius_save_file in
/// ~map_directory (mvog::mergeIntoMapFile), written without the map's lock. Tiles that could not
/// be written are kept and written with the next ones.
class LocalWindow {
 public:
  /// Throws mvog::ConfigError if ~keep_radius_save_file is refused (map_paths.h).
  LocalWindow(ros::NodeHandle& private_nh, const LifetimeConfig& config,
              const std::string& frame_id, const std::string& map_directory, double period,
              SharedMap& shared_map, const tf2_ros::Buffer& tf_buffer,
              LatestScanOrigin latest_scan_origin);

  /// Validated already: the next look drops the tiles farther than `keep_radius` (0: none), every
  /// `period` s from then on.
  void reconfigure(double keep_radius, double period);
  /// Stops dropping tiles, and writes those not written yet (a clean shutdown loses none).
  void stop();

 private:
  void dropFarTiles(const ros::TimerEvent&);
  std::optional<Eigen::Vector2d> robotPosition() const;
  /// Merges the tiles not written yet into the save file; keeps them if that fails (under
  /// save_mutex_).
  void writeUnsaved();

  const LifetimeConfig config_;  // its keep_radius: the one at start (keep_radius_ follows)
  std::atomic<double> keep_radius_;
  const std::string frame_id_;
  const std::string save_path_;  // empty: dropped tiles are discarded
  SharedMap& map_;
  const tf2_ros::Buffer& tf_buffer_;
  const LatestScanOrigin latest_scan_origin_;

  std::mutex save_mutex_;             // one save at a time; guards unsaved_
  std::optional<mvog::Map> unsaved_;  // dropped tiles the file does not hold yet
  ros::Timer timer_;
};

}  // namespace mvog_ros
