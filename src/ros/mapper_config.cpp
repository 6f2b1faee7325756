#include "mvog_ros/mapper_config.h"

#include <cmath>
#include <cstdint>
#include <cstdlib>

#include <ros/console.h>
#include <ros/names.h>

namespace mvog_ros {
namespace {

// mvog::Map refuses grids of more cells than this (Map::crossSection, Map::projection).
constexpr int kMaxGridCells = 1 << 28;

void require(bool condition, const std::string& parameter, const std::string& reason) {
  if (!condition) throw mvog::ConfigError("~" + parameter + ": " + reason);
}

/// A period or timeout in seconds that ros::Duration can hold. `zero` says what 0 means, or is
/// null if 0 is refused.
void requireDuration(double seconds, const std::string& parameter, const char* zero) {
  const double max_seconds = std::numeric_limits<std::int32_t>::max();
  require((zero != nullptr ? seconds >= 0.0 : seconds > 0.0) && seconds <= max_seconds, parameter,
          std::string("must be in ") + (zero != nullptr ? "[0, " : "(0, ") +
              std::to_string(std::numeric_limits<std::int32_t>::max()) + "] s" +
              (zero != nullptr ? std::string(" (0: ") + zero + ")" : ""));
}

/// A topic name: a valid ROS graph resource name.
void requireTopics(const std::vector<std::string>& topics, const std::string& parameter) {
  for (const std::string& topic : topics) {
    std::string error;
    require(ros::names::validate(topic, error) && !topic.empty(), parameter,
            "'" + topic + "' is not a valid topic name" + (error.empty() ? "" : ": " + error));
  }
}

/// Reads an optional parameter, checking its type: a value of another type is an error, not a
/// silent default.
template <class T>
void read(const ros::NodeHandle& nh, const std::string& name, T& value) {
  if (!nh.hasParam(name)) return;
  if (!nh.getParam(name, value)) {
    throw mvog::ConfigError("~" + name + ": has the wrong type");
  }
}

template <class Integer>
void readInteger(const ros::NodeHandle& nh, const std::string& name, Integer& value) {
  if (!nh.hasParam(name)) return;
  // roscpp's getParam(int) would round a float silently: accept only whole numbers.
  XmlRpc::XmlRpcValue raw;
  nh.getParam(name, raw);
  if (raw.getType() == XmlRpc::XmlRpcValue::TypeInt) {
    value = static_cast<int>(raw);
    return;
  }
  if (raw.getType() == XmlRpc::XmlRpcValue::TypeDouble) {
    // XML-RPC integers have 32 bits: a larger whole number comes as a double. Below max + 1:
    // exact for int, and without 2^63 itself (which int64 cannot hold) for int64.
    const double number = static_cast<double>(raw);
    if (std::trunc(number) == number &&
        std::fabs(number) < static_cast<double>(std::numeric_limits<Integer>::max()) + 1.0) {
      value = static_cast<Integer>(number);
      return;
    }
  }
  throw mvog::ConfigError("~" + name + ": must be an integer");
}

void read(const ros::NodeHandle& nh, const std::string& name, int& value) {
  readInteger(nh, name, value);
}

void read(const ros::NodeHandle& nh, const std::string& name, std::int64_t& value) {
  readInteger(nh, name, value);
}

void read(const ros::NodeHandle& nh, const std::string& name, double& value) {
  if (!nh.hasParam(name)) return;
  // Accept integers and floats alike (YAML writes 1 for 1.0).
  XmlRpc::XmlRpcValue raw;
  nh.getParam(name, raw);
  if (raw.getType() == XmlRpc::XmlRpcValue::TypeInt) {
    value = static_cast<int>(raw);
  } else if (raw.getType() == XmlRpc::XmlRpcValue::TypeDouble) {
    value = static_cast<double>(raw);
  } else {
    throw mvog::ConfigError("~" + name + ": must be a number");
  }
}

void read(const ros::NodeHandle& nh, const std::string& name, std::vector<double>& values) {
  if (!nh.hasParam(name)) return;
  XmlRpc::XmlRpcValue raw;
  nh.getParam(name, raw);
  if (raw.getType() != XmlRpc::XmlRpcValue::TypeArray) {
    throw mvog::ConfigError("~" + name + ": must be a list of numbers");
  }
  values.clear();
  for (int k = 0; k < raw.size(); ++k) {
    if (raw[k].getType() == XmlRpc::XmlRpcValue::TypeInt) {
      values.push_back(static_cast<int>(raw[k]));
    } else if (raw[k].getType() == XmlRpc::XmlRpcValue::TypeDouble) {
      values.push_back(static_cast<double>(raw[k]));
    } else {
      throw mvog::ConfigError("~" + name + ": must be a list of numbers");
    }
  }
}

std::string defaultMapDirectory() {
  if (const char* ros_home = std::getenv("ROS_HOME")) return std::string(ros_home) + "/mvog_maps";
  if (const char* home = std::getenv("HOME")) return std::string(home) + "/.ros/mvog_maps";
  return "mvog_maps";
}

/// Runs a core config's own checks: they name their field, which is the parameter's name.
template <class CoreConfig>
void validateCoreConfig(const CoreConfig& config) {
  try {
    config.validate();
  } catch (const mvog::ConfigError& e) {
    throw mvog::ConfigError(std::string("~") + e.what());
  }
}

/// ~model (the rules' preset), then each rule on its own (README, the rules table).
void readModel(const ros::NodeHandle& nh, MapperConfig& config) {
  std::string model = "default";
  read(nh, "model", model);
  if (model == "paper") {
    config.map.rules = mvog::ModelRules::paper();
    config.occupancy_threshold = mvog::kPaperOccupancyThreshold;
  } else {
    require(model == "default", "model", "must be 'default' or 'paper', not '" + model + "'");
  }
  mvog::ModelRules& rules = config.map.rules;
  if (nh.hasParam("clear_conflicting_free_space")) {
    // The parameter of the first release: a scan's conflicting free space was dropped whole.
    ROS_WARN(
        "mvog: ~clear_conflicting_free_space is replaced by ~clip_free_space_at_hits (on by "
        "default): its value is taken for it");
    read(nh, "clear_conflicting_free_space", rules.clip_free_space_at_hits);
  }
  read(nh, "clip_free_space_at_hits", rules.clip_free_space_at_hits);
  read(nh, "split_free_space_at_obstacles", rules.split_free_space_at_obstacles);
  std::string counting;
  read(nh, "mass_counting", counting);
  if (!counting.empty()) {
    require(counting == "per_scan" || counting == "per_reading", "mass_counting",
            "must be 'per_scan' or 'per_reading', not '" + counting + "'");
    rules.mass_counting =
        counting == "per_scan" ? mvog::MassCounting::kPerScan : mvog::MassCounting::kPerReading;
  }
  read(nh, "out_of_range_free_length", rules.out_of_range_free_length);
}

}  // namespace

void SensorInputsConfig::validate() const {
  requireTopics(scan_topics, "scan_topics");
  requireTopics(cloud_topics, "cloud_topics");
  requireTopics(depth_topics, "depth_topics");
  require(sensor_queue_size >= 1 && sensor_queue_size <= 1000, "sensor_queue_size",
          "must be in [1, 1000]");
  require(std::isfinite(voxel_filter_size) && voxel_filter_size >= 0.0, "voxel_filter_size",
          "must be a finite number >= 0 (0: off)");
  require(depth_stride >= 1, "depth_stride", "must be >= 1");
  require(max_points_per_message >= 1, "max_points_per_message", "must be >= 1");
}

void InsertionWorkerConfig::validate() const {
  validateCoreConfig<mvog::InsertionConfig>(*this);
  require(insertion_queue_size >= 1 && insertion_queue_size <= 1000, "insertion_queue_size",
          "must be in [1, 1000]");
  require(backlog_insertion_threads >= 1 && backlog_insertion_threads <= 256,
          "backlog_insertion_threads", "must be in [1, 256]");
}

mvog::FreeSpaceRays freeSpaceRaysFromName(const std::string& name) {
  if (name == "every_reading") return mvog::FreeSpaceRays::kEveryReading;
  if (name == "one_per_end_voxel") return mvog::FreeSpaceRays::kOnePerEndVoxel;
  require(name == "one_path_per_end_column", "free_space_rays",
          "must be 'one_path_per_end_column', 'one_per_end_voxel' or 'every_reading', not '" +
              name + "'");
  return mvog::FreeSpaceRays::kOnePathPerEndColumn;
}

mvog::HitMemoryScope hitMemoryScopeFromName(const std::string& name) {
  if (name == "line_scans") return mvog::HitMemoryScope::kLineScans;
  require(name == "every_scan", "hit_memory_scope",
          "must be 'line_scans' or 'every_scan', not '" + name + "'");
  return mvog::HitMemoryScope::kEveryScan;
}

void DecayConfig::validate() const {
  require(std::isfinite(decay_factor) && decay_factor > 0.0 && decay_factor <= 1.0, "decay_factor",
          "must be in (0, 1]");
  requireDuration(decay_period, "decay_period", "off");
}

void LifetimeConfig::validate(const DecayConfig& decay) const {
  require(std::isfinite(forget_mass) && forget_mass >= 0.0, "forget_mass",
          "must be a finite number >= 0 (0: off)");
  require(forget_mass == 0.0 || decay.enabled(), "forget_mass",
          "needs decay (~decay_factor < 1 and ~decay_period > 0): nothing else makes volumes "
          "lighter");
  require(std::isfinite(keep_radius) && keep_radius >= 0.0, "keep_radius",
          "must be a finite number >= 0 (0: off)");
  require(robot_frame.empty() || robot_frame.front() != '/', "robot_frame",
          "must be a tf2 frame id (without a leading '/'), or empty");
}

void PublicationsConfig::validate(const mvog::MapConfig& map) const {
  for (double height : cross_section_heights) {
    require(std::isfinite(height) && std::fabs(height) <= map.max_coordinate,
            "cross_section_heights", "every height must be finite and within max_coordinate");
  }
  require(!std::isnan(projection_min_z), "projection_min_z", "must not be NaN");
  require(!std::isnan(projection_max_z), "projection_max_z", "must not be NaN");
  require(projection_min_z <= projection_max_z, "projection_min_z",
          "must not be above ~projection_max_z");
  requireDuration(publish_period, "publish_period", nullptr);
  requireDuration(binary_map_period, "binary_map_period", "off");
  requireDuration(statistics_period, "statistics_period", nullptr);
}

void QueryServicesConfig::validate() const {
  requireDuration(tf_timeout, "tf_timeout", "no waiting");
  require(max_query_points >= 1, "max_query_points", "must be >= 1");
}

void MapFilesConfig::validate() const {
  require(!map_directory.empty(), "map_directory", "must not be empty");
  requireDuration(autosave_period, "autosave_period", "off");
  require(autosave_period == 0.0 || !autosave_file.empty(), "autosave_file",
          "must not be empty when ~autosave_period is set");
}

void MapperConfig::validate() const {
  validateCoreConfig(map);
  require(!frame_id.empty() && frame_id.front() != '/', "frame_id",
          "must be a non-empty tf2 frame id (without a leading '/')");
  require(
      std::isfinite(occupancy_threshold) && occupancy_threshold >= 0.0 && occupancy_threshold < 1.0,
      "occupancy_threshold", "must be in [0, 1)");
  require(max_cross_section_cells >= 1 && max_cross_section_cells <= kMaxGridCells,
          "max_cross_section_cells", "must be in [1, 2^28]");
  inputs.validate();
  insertion.validate();
  decay.validate();
  lifetime.validate(decay);
  publications.validate(map);
  queries.validate();
  map_files.validate();
  validateCoreConfig(planning);
}

MapperConfig MapperConfig::fromParameters(const ros::NodeHandle& private_nh) {
  MapperConfig config;
  config.map_files.map_directory = defaultMapDirectory();
  const ros::NodeHandle& nh = private_nh;
  read(nh, "resolution", config.map.resolution);
  read(nh, "max_coordinate", config.map.max_coordinate);
  readModel(nh, config);
  read(nh, "frame_id", config.frame_id);
  read(nh, "occupancy_threshold", config.occupancy_threshold);
  read(nh, "max_cross_section_cells", config.max_cross_section_cells);

  SensorInputsConfig& inputs = config.inputs;
  read(nh, "scan_topics", inputs.scan_topics);
  read(nh, "cloud_topics", inputs.cloud_topics);
  read(nh, "depth_topics", inputs.depth_topics);
  read(nh, "sensor_queue_size", inputs.sensor_queue_size);
  read(nh, "voxel_filter_size", inputs.voxel_filter_size);
  read(nh, "depth_stride", inputs.depth_stride);
  read(nh, "max_points_per_message", inputs.max_points_per_message);

  InsertionWorkerConfig& insertion = config.insertion;
  read(nh, "min_range", insertion.min_range);
  read(nh, "max_range", insertion.max_range);
  read(nh, "insert_out_of_range", insertion.insert_out_of_range);
  read(nh, "model_negative_space", insertion.model_negative_space);
  read(nh, "insertion_threads", insertion.insertion_threads);
  std::string free_space_rays = "one_per_end_voxel";
  read(nh, "free_space_rays", free_space_rays);
  insertion.free_space_rays = freeSpaceRaysFromName(free_space_rays);
  read(nh, "evidence_limit", insertion.evidence_limit);
  read(nh, "hit_memory_scans", insertion.hit_memory_scans);
  std::string hit_memory_scope = "line_scans";
  read(nh, "hit_memory_scope", hit_memory_scope);
  insertion.hit_memory_scope = hitMemoryScopeFromName(hit_memory_scope);
  read(nh, "insertion_queue_size", insertion.insertion_queue_size);
  read(nh, "backlog_insertion_threads", insertion.backlog_insertion_threads);

  read(nh, "decay_factor", config.decay.decay_factor);
  read(nh, "decay_period", config.decay.decay_period);

  LifetimeConfig& lifetime = config.lifetime;
  read(nh, "forget_mass", lifetime.forget_mass);
  read(nh, "keep_radius", lifetime.keep_radius);
  read(nh, "robot_frame", lifetime.robot_frame);
  read(nh, "keep_radius_save_file", lifetime.keep_radius_save_file);

  PublicationsConfig& publications = config.publications;
  read(nh, "cross_section_heights", publications.cross_section_heights);
  read(nh, "projection_min_z", publications.projection_min_z);
  read(nh, "projection_max_z", publications.projection_max_z);
  read(nh, "publish_period", publications.publish_period);
  read(nh, "binary_map_period", publications.binary_map_period);
  read(nh, "statistics_period", publications.statistics_period);

  read(nh, "tf_timeout", config.queries.tf_timeout);
  read(nh, "max_query_points", config.queries.max_query_points);

  mvog::PlanningConfig& planning = config.planning;
  planning.occupancy_threshold = config.occupancy_threshold;
  planning.frontier_min_z = publications.projection_min_z;
  planning.frontier_max_z = publications.projection_max_z;
  read(nh, "max_query_cells", planning.max_query_cells);
  read(nh, "frontier_min_z", planning.frontier_min_z);
  read(nh, "frontier_max_z", planning.frontier_max_z);
  read(nh, "frontier_min_cells", planning.frontier_min_cells);
  read(nh, "robot_height", planning.robot_height);
  read(nh, "max_step", planning.max_step);
  read(nh, "traversable_min_z", planning.traversable_min_z);
  read(nh, "traversable_max_z", planning.traversable_max_z);

  MapFilesConfig& map_files = config.map_files;
  read(nh, "map_directory", map_files.map_directory);
  read(nh, "map_file", map_files.map_file);
  read(nh, "autosave_period", map_files.autosave_period);
  read(nh, "autosave_file", map_files.autosave_file);
  config.validate();
  return config;
}

}  // namespace mvog_ros
