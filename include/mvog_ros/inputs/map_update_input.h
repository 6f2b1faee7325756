#pragma once

#include <atomic>
#include <cstdint>
#include <optional>
#include <vector>

#include <ros/ros.h>

#include "mvog/MapUpdate.h"
#include "mvog/map_io.h"
#include "mvog_ros/shared_map.h"

namespace mvog_ros {

/// A mirror's input: the updates of another server's map (`map_updates`, mvog/MapUpdate,
/// remappable) applied to the shared map (mvog::MapMirror), which then equals the source's map
/// bit for bit. It starts from a full update asked for with the source's `get_map_update`
/// (remappable), and asks again, for what it lacks, whenever an update shows that it missed one.
/// Updates that cannot be read are refused with a throttled warning, the map unchanged.
class MapUpdateInput {
 public:
  MapUpdateInput(ros::NodeHandle& nh, SharedMap& shared_map);
  /// Takes no more updates.
  void stop();

 private:
  void receive(const mvog::MapUpdate::ConstPtr& update);
  /// Applies an update under the map's write lock. Nothing if it was refused (corrupt or
  /// foreign bytes).
  std::optional<mvog::MapUpdateStatus> apply(const std::vector<std::uint8_t>& bytes);
  /// Asks the source for what the mirror lacks, if it needs something (wall timer: the source
  /// answers whatever the clock does).
  void askForWhatIsMissing(const ros::WallTimerEvent&);

  SharedMap& map_;
  mvog::MapMirror mirror_;    // under the map's lock; its map is swapped in only to apply
  std::uint64_t source_ = 0;  // the source of the updates applied (under the map's lock)
  std::atomic<bool> behind_{true};
  std::atomic<std::uint64_t> refused_{0};
  ros::ServiceClient get_map_update_;
  ros::Subscriber subscriber_;
  ros::WallTimer timer_;
};

}  // namespace mvog_ros
