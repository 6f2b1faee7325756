#include "mvog_ros/decay.h"

namespace mvog_ros {

Decay::Decay(ros::NodeHandle& private_nh, const DecayConfig& config, double forget_mass,
             SharedMap& shared_map)
    : config_(config), forget_mass_(forget_mass), map_(shared_map) {
  // Created stopped with any positive period: reconfigure() may turn decay on later.
  timer_ = private_nh.createTimer(ros::Duration(config.enabled() ? config.decay_period : 1.0),
                                  &Decay::step, this, false, config.enabled());
}

Decay::~Decay() { stop(); }

void Decay::reconfigure(const DecayConfig& config, double forget_mass) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    config_ = config;
    forget_mass_ = forget_mass;
  }
  if (!config.enabled()) {
    timer_.stop();
    return;
  }
  timer_.setPeriod(ros::Duration(config.decay_period));
  timer_.start();
}

void Decay::stop() { timer_.stop(); }

void Decay::step(const ros::TimerEvent&) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!config_.enabled()) return;  // turned off while this step waited
  std::unique_lock<WriterPreferringMutex> map_lock(map_.mutex);
  map_.map.decay(config_.decay_factor);
  // Only decay makes volumes lighter: forgetting follows each step (~forget_mass 0: nothing).
  map_.map.forget(forget_mass_);
}

}  // namespace mvog_ros
