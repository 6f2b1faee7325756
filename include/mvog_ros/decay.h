#pragma once

#include <mutex>

#include <ros/ros.h>

#include "mvog_ros/mapper_config.h"
#include "mvog_ros/shared_map.h"

namespace mvog_ros {

/// Decay (Sec. III-E): every ~decay_period the map's masses are multiplied by ~decay_factor, and
/// the volumes lighter than ~forget_mass are forgotten right after (only decay makes volumes
/// lighter). Off while decay is (DecayConfig::enabled); changed at run time by reconfigure().
class Decay {
 public:
  Decay(ros::NodeHandle& private_nh, const DecayConfig& config, double forget_mass,
        SharedMap& shared_map);
  ~Decay();
  Decay(const Decay&) = delete;
  Decay& operator=(const Decay&) = delete;

  /// Values validated already (MapperConfig::validate); the next step uses them, after a full
  /// new period.
  void reconfigure(const DecayConfig& config, double forget_mass);
  void stop();

 private:
  void step(const ros::TimerEvent&);

  std::mutex mutex_;  // config_, forget_mass_
  DecayConfig config_;
  double forget_mass_;
  SharedMap& map_;
  ros::Timer timer_;
};

}  // namespace mvog_ros
