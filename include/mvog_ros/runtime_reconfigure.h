#pragma once

#include <cstdint>
#include <functional>

#include <dynamic_reconfigure/server.h>
#include <ros/ros.h>
#include <boost/thread/recursive_mutex.hpp>

#include "mvog/MapperReconfigureConfig.h"
#include "mvog_ros/mapper_config.h"

namespace mvog_ros {

/// The values dynamic_reconfigure shows of `config` (cfg/MapperReconfigure.cfg).
mvog::MapperReconfigureConfig reconfigurableValuesOf(const MapperConfig& config);

/// `current` with the values dynamic_reconfigure may change taken from `values`, validated as at
/// start (MapperConfig::validate). Throws mvog::ConfigError naming the parameter at fault, also
/// if ~cross_section_heights_text holds something else than numbers or not as many as
/// ~cross_section_heights at start (their topics are start-only).
MapperConfig withReconfiguredValues(const MapperConfig& current,
                                    const mvog::MapperReconfigureConfig& values);

/// Applies a validated configuration to the server's parts (Mapper::reconfigure).
using ApplyConfig = std::function<void(const MapperConfig&)>;

/// The server's dynamic_reconfigure server (on its private namespace): new values are validated
/// as at start and applied at once; refused ones are reported back as the values in force, with
/// a warning naming the parameter and the reason.
class RuntimeReconfigure {
 public:
  /// `config`: the values in force at start, which the server reports at once.
  RuntimeReconfigure(const ros::NodeHandle& private_nh, const MapperConfig& config,
                     ApplyConfig apply);
  RuntimeReconfigure(const RuntimeReconfigure&) = delete;
  RuntimeReconfigure& operator=(const RuntimeReconfigure&) = delete;

 private:
  void reconfigure(mvog::MapperReconfigureConfig& values, std::uint32_t level);

  boost::recursive_mutex mutex_;  // the server's: one reconfiguration at a time
  MapperConfig config_;           // the values in force (under mutex_)
  const ApplyConfig apply_;
  dynamic_reconfigure::Server<mvog::MapperReconfigureConfig> server_;
};

}  // namespace mvog_ros
