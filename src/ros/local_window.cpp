#include "mvog_ros/local_window.h"

#include <mutex>
#include <utility>

#include "mvog/map_io.h"
#include "mvog_ros/frames.h"
#include "mvog_ros/map_paths.h"

namespace mvog_ros {
namespace {

std::string savePath(const LifetimeConfig& config, const std::string& map_directory) {
  if (config.keep_radius == 0.0 || config.keep_radius_save_file.empty()) return "";
  try {
    return resolveMapPath(map_directory, config.keep_radius_save_file, true);
  } catch (const PathRefused& e) {
    throw mvog::ConfigError("~keep_radius_save_file: " + std::string(e.what()));
  }
}

}  // namespace

LocalWindow::LocalWindow(ros::NodeHandle& private_nh, const LifetimeConfig& config,
                         const std::string& frame_id, const std::string& map_directory,
                         double period, SharedMap& shared_map, const tf2_ros::Buffer& tf_buffer,
                         LatestScanOrigin latest_scan_origin)
    : config_(config),
      keep_radius_(config.keep_radius),
      frame_id_(frame_id),
      save_path_(savePath(config, map_directory)),
      map_(shared_map),
      tf_buffer_(tf_buffer),
      latest_scan_origin_(std::move(latest_scan_origin)) {
  // Running even with ~keep_radius 0 (nothing dropped), which reconfigure() may change.
  timer_ = private_nh.createTimer(ros::Duration(period), &LocalWindow::dropFarTiles, this);
  if (config_.keep_radius == 0.0) return;
  const std::string centre =
      config_.robot_frame.empty() ? "the latest scan's origin" : "'" + config_.robot_frame + "'";
  const std::string where = save_path_.empty() ? "are discarded" : "go into '" + save_path_ + "'";
  ROS_INFO("mvog: keeping the map within %.1f m of %s; tiles farther %s", config_.keep_radius,
           centre.c_str(), where.c_str());
}

void LocalWindow::reconfigure(double keep_radius, double period) {
  keep_radius_ = keep_radius;
  timer_.setPeriod(ros::Duration(period));
}

void LocalWindow::stop() {
  timer_.stop();
  std::lock_guard<std::mutex> save_lock(save_mutex_);
  writeUnsaved();
}

std::optional<Eigen::Vector2d> LocalWindow::robotPosition() const {
  if (config_.robot_frame.empty()) {
    const std::optional<Eigen::Vector3d> origin = latest_scan_origin_();
    if (!origin) return std::nullopt;
    return origin->head<2>();
  }
  try {
    return latestTransform(tf_buffer_, frame_id_, config_.robot_frame, 0.0).translation().head<2>();
  } catch (const TransformUnavailable& e) {
    ROS_WARN_THROTTLE(kWarningPeriod, "mvog: ~keep_radius: no tiles dropped: %s", e.what());
    return std::nullopt;
  }
}

void LocalWindow::dropFarTiles(const ros::TimerEvent&) {
  const double keep_radius = keep_radius_;
  if (keep_radius == 0.0) return;
  const std::optional<Eigen::Vector2d> centre = robotPosition();
  if (!centre) return;
  mvog::Map dropped;
  try {
    std::unique_lock<WriterPreferringMutex> lock(map_.mutex);
    dropped = map_.map.dropTilesFartherThan(*centre, keep_radius);
  } catch (const mvog::ConfigError& e) {  // a centre that is not finite
    ROS_WARN_THROTTLE(kWarningPeriod, "mvog: ~keep_radius: no tiles dropped: %s", e.what());
    return;
  }
  if (dropped.empty() || save_path_.empty()) return;
  // The dropped tiles are a map of their own: written without the map's lock.
  std::lock_guard<std::mutex> save_lock(save_mutex_);
  if (!unsaved_) {
    unsaved_ = std::move(dropped);
  } else {
    try {
      unsaved_->merge(dropped);
    } catch (const mvog::ConfigError& e) {  // ~load_map changed the resolution meanwhile
      ROS_WARN_THROTTLE(kWarningPeriod,
                        "mvog: ~keep_radius: tiles dropped from the map loaded are lost: the "
                        "tiles of the map before, not written yet, cannot take them: %s",
                        e.what());
    }
  }
  writeUnsaved();
}

void LocalWindow::writeUnsaved() {
  if (!unsaved_) return;
  try {
    mvog::mergeIntoMapFile(*unsaved_, save_path_);
    unsaved_.reset();
  } catch (const mvog::MapFileError& e) {
    ROS_WARN_THROTTLE(kWarningPeriod,
                      "mvog: ~keep_radius: could not merge the tiles dropped into '%s' (kept in "
                      "memory, tried again with the next ones): %s",
                      save_path_.c_str(), e.what());
  }
}

}  // namespace mvog_ros
