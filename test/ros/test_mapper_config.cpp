// MapperConfig::validate (mvog_ros/mapper_config.h): every invalid parameter is refused with a
// message naming it. (fromParameters needs a master: the rostests cover it.)
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "mvog_ros/mapper_config.h"

namespace mvog_ros {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

MapperConfig validConfig() {
  MapperConfig config;
  config.map_files.map_directory = "/tmp/mvog_maps";  // fromParameters sets the default
  return config;
}

/// The message validate() refuses `config` with, or "" if it accepts it.
std::string refusal(const MapperConfig& config) {
  try {
    config.validate();
  } catch (const mvog::ConfigError& e) {
    return e.what();
  }
  return "";
}

/// Expects `read(name)` to refuse each of `names`, naming ~`parameter`.
template <class Read>
void expectNamesRefused(Read read, const std::string& parameter,
                        std::initializer_list<const char*> names) {
  for (const char* name : names) {
    std::string message;
    try {
      read(name);
    } catch (const mvog::ConfigError& e) {
      message = e.what();
    }
    EXPECT_EQ(message.rfind("~" + parameter + ":", 0), 0u)
        << "'" << name << "': got '" << message << "'";
  }
}

struct InvalidCase {
  std::string parameter;  // the parameter the message must name (without ~)
  std::string what;
  std::function<void(MapperConfig&)> change;
};

void expectRefused(const InvalidCase& invalid) {
  MapperConfig config = validConfig();
  invalid.change(config);
  const std::string message = refusal(config);
  EXPECT_EQ(message.rfind("~" + invalid.parameter + ":", 0), 0u)
      << "~" << invalid.parameter << " " << invalid.what << ": got '" << message << "'";
}

TEST(MapperConfig, DefaultsAreValid) { EXPECT_EQ(refusal(validConfig()), ""); }

TEST(MapperConfig, AcceptsSensibleNonDefaultValues) {
  MapperConfig config = validConfig();
  config.map.resolution = 0.05;
  config.insertion.min_range = 0.3;
  config.insertion.max_range = 8.0;
  config.insertion.insertion_threads = 4;
  config.inputs.scan_topics = {"front/scan", "/rear/scan", "~scan"};
  config.inputs.cloud_topics = {"camera/depth/points"};
  config.inputs.depth_topics = {"camera/depth/image_rect_raw", "/tof/depth"};
  config.inputs.depth_stride = 4;
  config.queries.tf_timeout = 0.0;
  config.inputs.voxel_filter_size = 0.05;
  config.decay.decay_factor = 0.9;
  config.decay.decay_period = 1.0;
  config.occupancy_threshold = 0.0;
  config.publications.cross_section_heights = {-1.0, 0.5, 1.5};
  config.publications.projection_min_z = 0.1;
  config.publications.projection_max_z = 2.0;
  config.publications.binary_map_period = 0.0;
  config.map_files.autosave_period = 60.0;
  config.queries.max_query_points = 1;
  config.max_cross_section_cells = 1 << 28;
  config.planning.max_query_cells = std::int64_t{1} << 40;
  config.planning.frontier_min_z = 0.2;
  config.planning.frontier_max_z = 0.2;
  config.planning.frontier_min_cells = 1;
  config.planning.robot_height = 1.8;
  config.planning.max_step = 0.0;
  config.planning.traversable_min_z = -kInf;
  config.planning.traversable_max_z = kInf;
  EXPECT_EQ(refusal(config), "");
  config.publications.projection_min_z = config.publications.projection_max_z =
      1.0;  // a single height
  EXPECT_EQ(refusal(config), "");
}

/// Cases for a number that must be finite and > 0 (or >= 0 if `zero_allowed`).
std::vector<InvalidCase> positiveNumberCases(const std::string& parameter,
                                             const std::function<double&(MapperConfig&)>& field,
                                             bool zero_allowed) {
  std::vector<InvalidCase> cases;
  std::vector<double> values = {kNaN, kInf, -kInf, -1.0, -1e-9};
  if (!zero_allowed) values.push_back(0.0);
  for (double value : values) {
    cases.push_back({parameter, "= " + std::to_string(value),
                     [field, value](MapperConfig& c) { field(c) = value; }});
  }
  return cases;
}

TEST(MapperConfig, RefusesNaNInfiniteNegativeOrZeroNumbers) {
  std::vector<InvalidCase> cases;
  auto add = [&](const std::string& parameter, const std::function<double&(MapperConfig&)>& field,
                 bool zero_allowed) {
    const std::vector<InvalidCase> more = positiveNumberCases(parameter, field, zero_allowed);
    cases.insert(cases.end(), more.begin(), more.end());
  };
  add(
      "resolution", [](MapperConfig& c) -> double& { return c.map.resolution; }, false);
  add(
      "max_coordinate", [](MapperConfig& c) -> double& { return c.map.max_coordinate; }, false);
  add(
      "min_range", [](MapperConfig& c) -> double& { return c.insertion.min_range; }, true);
  add(
      "tf_timeout", [](MapperConfig& c) -> double& { return c.queries.tf_timeout; }, true);
  add(
      "voxel_filter_size", [](MapperConfig& c) -> double& { return c.inputs.voxel_filter_size; },
      true);
  add(
      "decay_factor", [](MapperConfig& c) -> double& { return c.decay.decay_factor; }, false);
  add(
      "decay_period", [](MapperConfig& c) -> double& { return c.decay.decay_period; }, true);
  add(
      "publish_period", [](MapperConfig& c) -> double& { return c.publications.publish_period; },
      false);
  add(
      "binary_map_period",
      [](MapperConfig& c) -> double& { return c.publications.binary_map_period; }, true);
  add(
      "statistics_period",
      [](MapperConfig& c) -> double& { return c.publications.statistics_period; }, false);
  add(
      "autosave_period", [](MapperConfig& c) -> double& { return c.map_files.autosave_period; },
      true);
  add(
      "robot_height", [](MapperConfig& c) -> double& { return c.planning.robot_height; }, false);
  add(
      "max_step", [](MapperConfig& c) -> double& { return c.planning.max_step; }, true);
  for (const InvalidCase& invalid : cases) expectRefused(invalid);
}

TEST(MapperConfig, RefusesOutOfRangeValues) {
  const std::vector<InvalidCase> cases = {
      {"max_range", "NaN", [](MapperConfig& c) { c.insertion.max_range = kNaN; }},
      {"max_range", "0", [](MapperConfig& c) { c.insertion.max_range = 0.0; }},
      {"max_range", "< 0", [](MapperConfig& c) { c.insertion.max_range = -5.0; }},
      {"max_coordinate", "over 2^22 cells",
       [](MapperConfig& c) {
         c.map.resolution = 0.001;
         c.map.max_coordinate = 10000.0;
       }},
      {"insertion_threads", "0", [](MapperConfig& c) { c.insertion.insertion_threads = 0; }},
      {"insertion_threads", "< 0", [](MapperConfig& c) { c.insertion.insertion_threads = -2; }},
      {"insertion_threads", "1000", [](MapperConfig& c) { c.insertion.insertion_threads = 1000; }},
      {"backlog_insertion_threads", "0",
       [](MapperConfig& c) { c.insertion.backlog_insertion_threads = 0; }},
      {"backlog_insertion_threads", "1000",
       [](MapperConfig& c) { c.insertion.backlog_insertion_threads = 1000; }},
      {"sensor_queue_size", "0", [](MapperConfig& c) { c.inputs.sensor_queue_size = 0; }},
      {"sensor_queue_size", "< 0", [](MapperConfig& c) { c.inputs.sensor_queue_size = -1; }},
      {"sensor_queue_size", "huge", [](MapperConfig& c) { c.inputs.sensor_queue_size = 1 << 30; }},
      {"insertion_queue_size", "0", [](MapperConfig& c) { c.insertion.insertion_queue_size = 0; }},
      {"insertion_queue_size", "< 0",
       [](MapperConfig& c) { c.insertion.insertion_queue_size = -1; }},
      {"insertion_queue_size", "huge",
       [](MapperConfig& c) { c.insertion.insertion_queue_size = 1 << 30; }},
      {"max_points_per_message", "0", [](MapperConfig& c) { c.inputs.max_points_per_message = 0; }},
      {"depth_stride", "0", [](MapperConfig& c) { c.inputs.depth_stride = 0; }},
      {"depth_stride", "< 0", [](MapperConfig& c) { c.inputs.depth_stride = -2; }},
      {"max_points_per_message", "< 0",
       [](MapperConfig& c) { c.inputs.max_points_per_message = -1; }},
      {"decay_factor", "> 1", [](MapperConfig& c) { c.decay.decay_factor = 1.5; }},
      {"occupancy_threshold", "NaN", [](MapperConfig& c) { c.occupancy_threshold = kNaN; }},
      {"occupancy_threshold", "< 0", [](MapperConfig& c) { c.occupancy_threshold = -0.1; }},
      {"occupancy_threshold", "1", [](MapperConfig& c) { c.occupancy_threshold = 1.0; }},
      {"occupancy_threshold", "> 1", [](MapperConfig& c) { c.occupancy_threshold = 2.0; }},
      {"max_query_points", "0", [](MapperConfig& c) { c.queries.max_query_points = 0; }},
      {"max_query_points", "< 0", [](MapperConfig& c) { c.queries.max_query_points = -1; }},
      {"max_cross_section_cells", "0", [](MapperConfig& c) { c.max_cross_section_cells = 0; }},
      {"max_cross_section_cells", "< 0", [](MapperConfig& c) { c.max_cross_section_cells = -1; }},
      {"max_cross_section_cells", "beyond the core's 2^28",
       [](MapperConfig& c) { c.max_cross_section_cells = (1 << 28) + 1; }},
      {"publish_period", "beyond ros::Duration",
       [](MapperConfig& c) { c.publications.publish_period = 3e9; }},
      {"statistics_period", "beyond ros::Duration",
       [](MapperConfig& c) { c.publications.statistics_period = 1e300; }},
      {"tf_timeout", "beyond ros::Duration", [](MapperConfig& c) { c.queries.tf_timeout = 1e10; }},
      {"decay_period", "beyond ros::Duration",
       [](MapperConfig& c) { c.decay.decay_period = 1e10; }},
      {"binary_map_period", "beyond ros::Duration",
       [](MapperConfig& c) { c.publications.binary_map_period = 1e10; }},
      {"autosave_period", "beyond ros::Duration",
       [](MapperConfig& c) { c.map_files.autosave_period = 1e10; }},
      {"max_query_cells", "0", [](MapperConfig& c) { c.planning.max_query_cells = 0; }},
      {"max_query_cells", "< 0", [](MapperConfig& c) { c.planning.max_query_cells = -1; }},
      {"frontier_min_cells", "0", [](MapperConfig& c) { c.planning.frontier_min_cells = 0; }},
      {"occupancy_threshold", "of the planning queries",
       [](MapperConfig& c) { c.planning.occupancy_threshold = 1.0; }},
  };
  for (const InvalidCase& invalid : cases) expectRefused(invalid);
}

TEST(MapperConfig, RefusesContradictoryValues) {
  const std::vector<InvalidCase> cases = {
      {"min_range", "= max_range",
       [](MapperConfig& c) { c.insertion.min_range = c.insertion.max_range = 5.0; }},
      {"min_range", "> max_range",
       [](MapperConfig& c) {
         c.insertion.min_range = 6.0;
         c.insertion.max_range = 5.0;
       }},
      {"projection_min_z", "> projection_max_z",
       [](MapperConfig& c) {
         c.publications.projection_min_z = 2.0;
         c.publications.projection_max_z = 1.0;
       }},
      {"projection_min_z", "NaN", [](MapperConfig& c) { c.publications.projection_min_z = kNaN; }},
      {"projection_max_z", "NaN", [](MapperConfig& c) { c.publications.projection_max_z = kNaN; }},
      {"projection_min_z", "above a max of -Inf",
       [](MapperConfig& c) {
         c.publications.projection_min_z = 0.0;
         c.publications.projection_max_z = -kInf;
       }},
      {"cross_section_heights", "NaN",
       [](MapperConfig& c) {
         c.publications.cross_section_heights = {0.5, kNaN};
       }},
      {"cross_section_heights", "Inf",
       [](MapperConfig& c) { c.publications.cross_section_heights = {kInf}; }},
      {"cross_section_heights", "beyond max_coordinate",
       [](MapperConfig& c) {
         c.publications.cross_section_heights = {c.map.max_coordinate + 1.0};
       }},
      {"frontier_min_z", "> frontier_max_z",
       [](MapperConfig& c) {
         c.planning.frontier_min_z = 2.0;
         c.planning.frontier_max_z = 1.0;
       }},
      {"frontier_min_z", "NaN", [](MapperConfig& c) { c.planning.frontier_min_z = kNaN; }},
      {"frontier_min_z", "a NaN max", [](MapperConfig& c) { c.planning.frontier_max_z = kNaN; }},
      {"traversable_min_z", "> traversable_max_z",
       [](MapperConfig& c) {
         c.planning.traversable_min_z = 0.5;
         c.planning.traversable_max_z = 0.0;
       }},
      {"traversable_min_z", "NaN", [](MapperConfig& c) { c.planning.traversable_min_z = kNaN; }},
      {"autosave_file", "empty while autosaving",
       [](MapperConfig& c) {
         c.map_files.autosave_period = 10.0;
         c.map_files.autosave_file.clear();
       }},
  };
  for (const InvalidCase& invalid : cases) expectRefused(invalid);
}

TEST(MapperConfig, RefusesEmptyOrInvalidNames) {
  const std::vector<InvalidCase> cases = {
      {"frame_id", "empty", [](MapperConfig& c) { c.frame_id.clear(); }},
      {"frame_id", "with a leading slash", [](MapperConfig& c) { c.frame_id = "/map"; }},
      {"map_directory", "empty", [](MapperConfig& c) { c.map_files.map_directory.clear(); }},
      {"scan_topics", "an empty topic",
       [](MapperConfig& c) {
         c.inputs.scan_topics = {"scan2", ""};
       }},
      {"scan_topics", "an invalid topic",
       [](MapperConfig& c) { c.inputs.scan_topics = {"bad topic"}; }},
      {"cloud_topics", "an empty topic", [](MapperConfig& c) { c.inputs.cloud_topics = {""}; }},
      {"cloud_topics", "an invalid topic",
       [](MapperConfig& c) { c.inputs.cloud_topics = {"3d/pts"}; }},
      {"depth_topics", "an empty topic", [](MapperConfig& c) { c.inputs.depth_topics = {""}; }},
      {"depth_topics", "an invalid topic",
       [](MapperConfig& c) { c.inputs.depth_topics = {"depth image"}; }},
  };
  for (const InvalidCase& invalid : cases) expectRefused(invalid);
}

TEST(MapperConfig, RefusesForgettingWithoutDecayAndBadWindows) {
  const std::vector<InvalidCase> cases = {
      {"forget_mass", "without decay", [](MapperConfig& c) { c.lifetime.forget_mass = 0.1; }},
      {"forget_mass", "negative",
       [](MapperConfig& c) {
         c.decay = {0.9, 1.0};
         c.lifetime.forget_mass = -0.1;
       }},
      {"forget_mass", "NaN",
       [](MapperConfig& c) {
         c.decay = {0.9, 1.0};
         c.lifetime.forget_mass = kNaN;
       }},
      {"keep_radius", "negative", [](MapperConfig& c) { c.lifetime.keep_radius = -1.0; }},
      {"keep_radius", "infinite", [](MapperConfig& c) { c.lifetime.keep_radius = kInf; }},
      {"robot_frame", "with a leading slash",
       [](MapperConfig& c) { c.lifetime.robot_frame = "/base_link"; }},
  };
  for (const InvalidCase& invalid : cases) expectRefused(invalid);
  MapperConfig config = validConfig();
  config.decay = {0.9, 1.0};
  config.lifetime = {0.05, 30.0, "base_link", ""};
  EXPECT_EQ(refusal(config), "");
}

TEST(MapperConfig, FreeSpaceRaysDefaultsToOnePerEndVoxelAndReadsTheThreeNames) {
  EXPECT_EQ(validConfig().insertion.free_space_rays, mvog::FreeSpaceRays::kOnePerEndVoxel);
  EXPECT_EQ(freeSpaceRaysFromName("one_path_per_end_column"),
            mvog::FreeSpaceRays::kOnePathPerEndColumn);
  EXPECT_EQ(freeSpaceRaysFromName("one_per_end_voxel"), mvog::FreeSpaceRays::kOnePerEndVoxel);
  EXPECT_EQ(freeSpaceRaysFromName("every_reading"), mvog::FreeSpaceRays::kEveryReading);
  MapperConfig config = validConfig();
  config.insertion.free_space_rays = mvog::FreeSpaceRays::kEveryReading;
  EXPECT_EQ(refusal(config), "");
}

TEST(MapperConfig, RefusesAnUnknownFreeSpaceRaysNamingIt) {
  // mvog_bench's spelling, another case, empty: only the three names are read.
  expectNamesRefused(
      freeSpaceRaysFromName, "free_space_rays",
      {"every-reading", "one-path-per-end-column", "Every_Reading", "one_per_voxel", ""});
  expectRefused({"free_space_rays", "not a FreeSpaceRays", [](MapperConfig& c) {
                   c.insertion.free_space_rays = static_cast<mvog::FreeSpaceRays>(7);
                 }});
}

TEST(MapperConfig, EvidenceLimitDefaultsToTheCoresAndRefusesLessThanOneNamingIt) {
  EXPECT_EQ(validConfig().insertion.evidence_limit, mvog::kDefaultEvidenceLimit);
  MapperConfig unbounded = validConfig();
  unbounded.insertion.evidence_limit = std::numeric_limits<double>::infinity();
  EXPECT_EQ(refusal(unbounded), "");
  for (double limit : {0.5, 0.0, -1.0, std::nan("")}) {
    expectRefused({"evidence_limit", std::to_string(limit),
                   [limit](MapperConfig& c) { c.insertion.evidence_limit = limit; }});
  }
}

TEST(MapperConfig, HitMemoryDefaultsToFiveLineScansAndRefusesOutOfRangeNamingIt) {
  EXPECT_EQ(validConfig().insertion.hit_memory_scans, 5);
  EXPECT_EQ(validConfig().insertion.hit_memory_scope, mvog::HitMemoryScope::kLineScans);
  MapperConfig own_hits_only = validConfig();
  own_hits_only.insertion.hit_memory_scans = 0;
  EXPECT_EQ(refusal(own_hits_only), "");
  for (int scans : {-1, mvog::kMaxHitMemoryScans + 1}) {
    expectRefused({"hit_memory_scans", std::to_string(scans),
                   [scans](MapperConfig& c) { c.insertion.hit_memory_scans = scans; }});
  }
}

TEST(MapperConfig, HitMemoryScopeReadsItsTwoNamesAndRefusesAnyOtherNamingIt) {
  EXPECT_EQ(hitMemoryScopeFromName("line_scans"), mvog::HitMemoryScope::kLineScans);
  EXPECT_EQ(hitMemoryScopeFromName("every_scan"), mvog::HitMemoryScope::kEveryScan);
  // mvog_bench's spelling, another case, empty.
  expectNamesRefused(hitMemoryScopeFromName, "hit_memory_scope",
                     {"line-scans", "Every_Scan", "lines", ""});
  expectRefused({"hit_memory_scope", "not a HitMemoryScope", [](MapperConfig& c) {
                   c.insertion.hit_memory_scope = static_cast<mvog::HitMemoryScope>(7);
                 }});
}

TEST(MapperConfig, AnEmptyAutosaveFileIsFineWhileAutosaveIsOff) {
  MapperConfig config = validConfig();
  config.map_files.autosave_file.clear();
  EXPECT_EQ(refusal(config), "");
}

}  // namespace
}  // namespace mvog_ros
