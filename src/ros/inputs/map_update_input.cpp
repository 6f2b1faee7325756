#include "mvog_ros/inputs/map_update_input.h"

#include <mutex>
#include <shared_mutex>

#include "mvog/GetMapUpdate.h"
#include "mvog_ros/mapper_config.h"

namespace mvog_ros {
namespace {

constexpr double kAskPeriod = 0.2;  // wall s between two requests for what a mirror lacks

}  // namespace

MapUpdateInput::MapUpdateInput(ros::NodeHandle& nh, SharedMap& shared_map)
    : map_(shared_map),
      get_map_update_(nh.serviceClient<mvog::GetMapUpdate>("get_map_update")),
      subscriber_(nh.subscribe("map_updates", 10, &MapUpdateInput::receive, this)),
      timer_(nh.createWallTimer(ros::WallDuration(kAskPeriod), &MapUpdateInput::askForWhatIsMissing,
                                this)) {}

void MapUpdateInput::stop() {
  subscriber_.shutdown();
  timer_.stop();
}

void MapUpdateInput::receive(const mvog::MapUpdate::ConstPtr& update) {
  if (apply(update->data) == mvog::MapUpdateStatus::kMissed) behind_ = true;
}

std::optional<mvog::MapUpdateStatus> MapUpdateInput::apply(const std::vector<std::uint8_t>& bytes) {
  std::unique_lock<WriterPreferringMutex> lock(map_.mutex);
  // The mirror's map lives in the shared map, where the readers find it.
  struct SwappedIn {
    SwappedIn(mvog::MapMirror& into, mvog::Map& shared) : mirror(into), map(shared) {
      mirror.swapMap(map);
    }
    ~SwappedIn() { mirror.swapMap(map); }
    mvog::MapMirror& mirror;
    mvog::Map& map;
  };
  mvog::MapUpdateResult result;
  try {
    const SwappedIn swapped(mirror_, map_.map);
    result = mirror_.apply(bytes.data(), bytes.size());
  } catch (const mvog::MapFileError& e) {
    ++refused_;
    ROS_WARN_THROTTLE(kWarningPeriod,
                      "mvog: refused a map update, the map unchanged: %s (%llu refused so far)",
                      e.what(), static_cast<unsigned long long>(refused_.load()));
    return std::nullopt;
  }
  if (result.status == mvog::MapUpdateStatus::kApplied) source_ = result.update.source;
  if (result.status == mvog::MapUpdateStatus::kMissed) {
    ROS_INFO_THROTTLE(kWarningPeriod,
                      "mvog: missed a map update (this one starts at revision %llu, the mirror "
                      "holds %llu): asking the source for what it lacks",
                      static_cast<unsigned long long>(result.update.from_revision),
                      static_cast<unsigned long long>(mirror_.sourceRevision()));
  }
  return result.status;
}

void MapUpdateInput::askForWhatIsMissing(const ros::WallTimerEvent&) {
  if (!behind_) return;
  mvog::GetMapUpdate service;
  {
    std::shared_lock<WriterPreferringMutex> lock(map_.mutex);
    service.request.source = source_;
    service.request.since_revision = mirror_.sourceRevision();
  }
  if (!get_map_update_.call(service)) {
    ROS_WARN_THROTTLE(kWarningPeriod, "mvog: the source's %s does not answer (yet)",
                      get_map_update_.getService().c_str());
    return;
  }
  const std::optional<mvog::MapUpdateStatus> status = apply(service.response.update.data);
  behind_ = !status || *status == mvog::MapUpdateStatus::kMissed;
}

}  // namespace mvog_ros
