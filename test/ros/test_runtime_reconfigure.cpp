// RuntimeReconfigure's validation (mvog_ros/runtime_reconfigure.h): the values dynamic_reconfigure
// may change round-trip, and a bad one is refused naming its parameter, exactly as at start.
// (The server itself needs a master: test/ros/reconfigure.test covers it.)
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "mvog_ros/runtime_reconfigure.h"

namespace mvog_ros {
namespace {

MapperConfig startConfig() {
  MapperConfig config;
  config.map_files.map_directory = "/tmp/mvog_maps";  // fromParameters sets the default
  config.publications.cross_section_heights = {0.1, 1.0 / 3.0};
  return config;
}

/// The message withReconfiguredValues refuses `values` with, or "" if it accepts them.
std::string refusal(const mvog::MapperReconfigureConfig& values) {
  try {
    withReconfiguredValues(startConfig(), values);
  } catch (const mvog::ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(RuntimeReconfigure, TheValuesInForceRoundTrip) {
  const MapperConfig start = startConfig();
  const mvog::MapperReconfigureConfig values = reconfigurableValuesOf(start);
  EXPECT_EQ(values.cross_section_heights_text, "0.1, 0.3333333333333333");
  const MapperConfig same = withReconfiguredValues(start, values);
  EXPECT_EQ(same.publications.cross_section_heights, start.publications.cross_section_heights);
  EXPECT_EQ(same.occupancy_threshold, start.occupancy_threshold);
  EXPECT_EQ(same.lifetime.keep_radius, start.lifetime.keep_radius);
  EXPECT_EQ(same.insertion.evidence_limit, start.insertion.evidence_limit);
}

TEST(RuntimeReconfigure, NewValuesReachEveryPartsSlice) {
  mvog::MapperReconfigureConfig values = reconfigurableValuesOf(startConfig());
  values.occupancy_threshold = 0.4;
  values.decay_factor = 0.9;
  values.decay_period = 2.0;
  values.forget_mass = 0.05;
  values.publish_period = 0.25;
  values.cross_section_heights_text = " -0.5 ,2";
  values.keep_radius = 7.5;
  values.min_range = 0.3;
  values.max_range = 6.0;
  values.evidence_limit = 30.0;
  const MapperConfig config = withReconfiguredValues(startConfig(), values);
  EXPECT_EQ(config.occupancy_threshold, 0.4);
  // The planners' threshold is the server's.
  EXPECT_EQ(config.planning.occupancy_threshold, 0.4);
  EXPECT_EQ(config.decay.decay_factor, 0.9);
  EXPECT_EQ(config.decay.decay_period, 2.0);
  EXPECT_EQ(config.lifetime.forget_mass, 0.05);
  EXPECT_EQ(config.publications.publish_period, 0.25);
  EXPECT_EQ(config.publications.cross_section_heights, (std::vector<double>{-0.5, 2.0}));
  EXPECT_EQ(config.lifetime.keep_radius, 7.5);
  EXPECT_EQ(config.insertion.min_range, 0.3);
  EXPECT_EQ(config.insertion.max_range, 6.0);
  EXPECT_EQ(config.insertion.evidence_limit, 30.0);
}

TEST(RuntimeReconfigure, BadValuesAreRefusedNamingTheirParameter) {
  struct Case {
    std::string parameter;
    std::function<void(mvog::MapperReconfigureConfig&)> change;
  };
  const Case cases[] = {
      {"occupancy_threshold", [](auto& v) { v.occupancy_threshold = 1.0; }},
      {"occupancy_threshold", [](auto& v) { v.occupancy_threshold = std::nan(""); }},
      {"decay_factor", [](auto& v) { v.decay_factor = 0.0; }},
      {"decay_period", [](auto& v) { v.decay_period = -1.0; }},
      {"forget_mass", [](auto& v) { v.forget_mass = 0.1; }},  // without decay
      {"publish_period", [](auto& v) { v.publish_period = 0.0; }},
      {"keep_radius", [](auto& v) { v.keep_radius = -1.0; }},
      {"min_range", [](auto& v) { v.min_range = -0.5; }},
      {"max_range", [](auto& v) { v.max_range = 0.0; }},
      {"evidence_limit", [](auto& v) { v.evidence_limit = 0.5; }},
      {"min_range", [](auto& v) { v.min_range = 5.0, v.max_range = 4.0; }},
      {"cross_section_heights", [](auto& v) { v.cross_section_heights_text = "0.5, 1e9"; }},
      {"cross_section_heights_text", [](auto& v) { v.cross_section_heights_text = "0.5"; }},
      {"cross_section_heights_text", [](auto& v) { v.cross_section_heights_text = "0.5 1 2"; }},
      {"cross_section_heights_text", [](auto& v) { v.cross_section_heights_text = "0.5, 1m"; }},
      {"cross_section_heights", [](auto& v) { v.cross_section_heights_text = "0.5, nan"; }},
  };
  for (const Case& bad : cases) {
    mvog::MapperReconfigureConfig values = reconfigurableValuesOf(startConfig());
    bad.change(values);
    const std::string message = refusal(values);
    EXPECT_EQ(message.rfind("~" + bad.parameter + ":", 0), 0u)
        << "~" << bad.parameter << ": got '" << message << "'";
  }
}

TEST(RuntimeReconfigure, ForgettingIsAcceptedWithDecay) {
  mvog::MapperReconfigureConfig values = reconfigurableValuesOf(startConfig());
  values.forget_mass = 0.1;
  values.decay_factor = 0.95;
  values.decay_period = 1.0;
  EXPECT_EQ(refusal(values), "");
}

}  // namespace
}  // namespace mvog_ros
