#pragma once

#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <vector>

#include <ros/ros.h>

#include "mvog/map.h"
#include "mvog_ros/shared_map.h"

namespace mvog_ros {

/// The tiles of `map` modified after `revision` and those removed after it (which hold nothing
/// now), rows of tiles from the lowest; nothing if the map no longer knows which tiles it removed
/// since then (Map::tilesRemovedSince).
std::optional<std::vector<mvog::TileIndex>> tilesChangedSince(const mvog::Map& map,
                                                              std::uint64_t revision);

/// What MarkerPublication, GridPublication and PlanningPublication share: every ~publish_period
/// they publish what changed in the map since they last did (the tiles modified or removed
/// since: tilesChangedSince; all of them afresh if the map cannot tell), and once the map was
/// replaced (~load_map, ~reset) they first clear what they showed of the previous one. Their
/// connection callbacks take the same lock (mutex_, then the map's) to send a new subscriber
/// everything.
class ChangePublication {
 public:
  virtual ~ChangePublication();
  ChangePublication(const ChangePublication&) = delete;
  ChangePublication& operator=(const ChangePublication&) = delete;

  /// Once the map was replaced, clears what was published of the previous map. Called by Mapper
  /// right after a replacement; the next publication would do it anyway.
  void restartIfReplaced();

 protected:
  explicit ChangePublication(const SharedMap& shared_map);
  /// Starts publishing every `period` s: the last step of a derived constructor.
  void start(ros::NodeHandle& private_nh, double period);
  /// Runs `change` (new values for the derived class's state) under mutex_ and the map's lock,
  /// publishes everything afresh with them at once (what was shown followed the old values),
  /// and from then on every `period` s (dynamic_reconfigure: RuntimeReconfigure).
  void reconfigure(double period, const std::function<void()>& change);
  /// Stops publishing: the first step of a derived destructor (the timer calls the derived
  /// class).
  void stop();
  /// Under mutex_ and the map's lock.
  void restartIfReplacedLocked();
  /// Publishes what changed since the last publication, if anything (under mutex_ and the map's
  /// lock): what the timer does, and what must happen before a new subscriber is sent a state
  /// the others have not been sent yet.
  void publishChangesLocked();

  /// Clears what was published of the previous map (under mutex_ and the map's lock).
  virtual void clearPublished() = 0;
  /// Publishes the tiles changed (under mutex_ and the map's lock).
  virtual void publishTiles(const std::vector<mvog::TileIndex>& changed) = 0;

  const SharedMap& map_;
  std::mutex mutex_;      // published_, the derived class's state, one publication at a time
  MapVersion published_;  // what the publication shows

 private:
  void publishChanges(const ros::TimerEvent&);

  ros::Timer timer_;
};

}  // namespace mvog_ros
