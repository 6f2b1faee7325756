#include "mvog_ros/runtime_reconfigure.h"

#include <array>
#include <charconv>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace mvog_ros {
namespace {

/// Heights as text that reads back to the same doubles (shortest round trip).
std::string heightsText(const std::vector<double>& heights) {
  std::string text;
  for (const double height : heights) {
    std::array<char, 32> buffer{};
    const auto written = std::to_chars(buffer.data(), buffer.data() + buffer.size(), height);
    if (!text.empty()) text += ", ";
    text.append(buffer.data(), written.ptr);
  }
  return text;
}

/// The numbers of `text`, separated by commas or spaces; exactly `count` of them.
std::vector<double> heightsFromText(const std::string& text, std::size_t count) {
  std::string separated = text;
  for (char& c : separated) {
    if (c == ',') c = ' ';
  }
  std::istringstream words(separated);
  std::vector<double> heights;
  for (std::string word; words >> word;) {
    double height = 0.0;
    const auto read = std::from_chars(word.data(), word.data() + word.size(), height);
    if (read.ec != std::errc() || read.ptr != word.data() + word.size()) {
      throw mvog::ConfigError("~cross_section_heights_text: '" + word + "' is not a number");
    }
    heights.push_back(height);
  }
  if (heights.size() != count) {
    throw mvog::ConfigError("~cross_section_heights_text: " + std::to_string(heights.size()) +
                            " heights, not " + std::to_string(count) +
                            ": the number of cross-sections (their topics) is start-only");
  }
  return heights;
}

bool sameValues(const mvog::MapperReconfigureConfig& a, const mvog::MapperReconfigureConfig& b) {
  return a.occupancy_threshold == b.occupancy_threshold && a.decay_factor == b.decay_factor &&
         a.decay_period == b.decay_period && a.forget_mass == b.forget_mass &&
         a.publish_period == b.publish_period &&
         a.cross_section_heights_text == b.cross_section_heights_text &&
         a.keep_radius == b.keep_radius && a.min_range == b.min_range &&
         a.max_range == b.max_range && a.evidence_limit == b.evidence_limit;
}

}  // namespace

mvog::MapperReconfigureConfig reconfigurableValuesOf(const MapperConfig& config) {
  mvog::MapperReconfigureConfig values = mvog::MapperReconfigureConfig::__getDefault__();
  values.occupancy_threshold = config.occupancy_threshold;
  values.decay_factor = config.decay.decay_factor;
  values.decay_period = config.decay.decay_period;
  values.forget_mass = config.lifetime.forget_mass;
  values.publish_period = config.publications.publish_period;
  values.cross_section_heights_text = heightsText(config.publications.cross_section_heights);
  values.keep_radius = config.lifetime.keep_radius;
  values.min_range = config.insertion.min_range;
  values.max_range = config.insertion.max_range;
  values.evidence_limit = config.insertion.evidence_limit;
  return values;
}

MapperConfig withReconfiguredValues(const MapperConfig& current,
                                    const mvog::MapperReconfigureConfig& values) {
  MapperConfig config = current;
  config.occupancy_threshold = values.occupancy_threshold;
  config.planning.occupancy_threshold = values.occupancy_threshold;
  config.decay.decay_factor = values.decay_factor;
  config.decay.decay_period = values.decay_period;
  config.lifetime.forget_mass = values.forget_mass;
  config.publications.publish_period = values.publish_period;
  config.publications.cross_section_heights = heightsFromText(
      values.cross_section_heights_text, current.publications.cross_section_heights.size());
  config.lifetime.keep_radius = values.keep_radius;
  config.insertion.min_range = values.min_range;
  config.insertion.max_range = values.max_range;
  config.insertion.evidence_limit = values.evidence_limit;
  config.validate();
  return config;
}

RuntimeReconfigure::RuntimeReconfigure(const ros::NodeHandle& private_nh,
                                       const MapperConfig& config, ApplyConfig apply)
    : config_(config), apply_(std::move(apply)), server_(mutex_, private_nh) {
  // The server starts from the parameter server or the .cfg's defaults: it reports the values
  // in force instead, then calls reconfigure() with them (nothing to apply).
  server_.updateConfig(reconfigurableValuesOf(config_));
  server_.setConfigDefault(reconfigurableValuesOf(config_));
  server_.setCallback([this](mvog::MapperReconfigureConfig& values, std::uint32_t level) {
    reconfigure(values, level);
  });
}

void RuntimeReconfigure::reconfigure(mvog::MapperReconfigureConfig& values, std::uint32_t) {
  // Called under mutex_ by the server, which then reports `values` as the values in force.
  const mvog::MapperReconfigureConfig in_force = reconfigurableValuesOf(config_);
  if (sameValues(values, in_force)) return;
  try {
    config_ = withReconfiguredValues(config_, values);
  } catch (const mvog::ConfigError& e) {
    ROS_WARN("mvog: dynamic_reconfigure: refused, the values in force are kept: %s", e.what());
    values = in_force;
    return;
  }
  apply_(config_);
  values = reconfigurableValuesOf(config_);  // the heights as the server reads them
  ROS_INFO(
      "mvog: dynamic_reconfigure: occupancy_threshold %g, decay_factor %g, decay_period %g "
      "s, forget_mass %g, publish_period %g s, cross_section_heights [%s], keep_radius %g m, "
      "min_range %g m, max_range %g m, evidence_limit %g",
      config_.occupancy_threshold, config_.decay.decay_factor, config_.decay.decay_period,
      config_.lifetime.forget_mass, config_.publications.publish_period,
      heightsText(config_.publications.cross_section_heights).c_str(), config_.lifetime.keep_radius,
      config_.insertion.min_range, config_.insertion.max_range, config_.insertion.evidence_limit);
}

}  // namespace mvog_ros
