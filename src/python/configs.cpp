// The configuration structs as keyword-argument classes: the C++ defaults, and the core's own
// validation on construction and on every assignment of a field (ConfigError, a ValueError that
// names the field; the object keeps its previous value).
#include <pybind11/eigen.h>
#include <pybind11/operators.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

#include "bindings.h"
#include "mvog/config.h"
#include "mvog/depth_image.h"
#include "mvog/map.h"
#include "mvog/map_io.h"
#include "mvog/planning_config.h"

namespace mvog_python {

namespace {

void validate(const mvog::MapConfig& config) { config.validate(); }
// ModelRules have no validation of their own: MapConfig's checks their field.
void validate(const mvog::ModelRules& rules) {
  mvog::MapConfig config;
  config.rules = rules;
  config.validate();
}
void validate(const mvog::InsertionConfig& config) { config.validate(); }
void validate(const mvog::PlanningConfig& config) { config.validate(); }
void validate(const mvog::DepthImageConfig& config) { config.validate(); }
void validate(const mvog::PinholeCamera& camera) { camera.validate(); }
void validate(const mvog::GridTransform& /*transform*/) {}  // every value is a transform

/// A keyword-argument class of a config struct: its fields, each validated when set, and a repr.
template <class Config>
class ConfigClass {
 public:
  ConfigClass(py::module_& module, const char* name, const char* doc) : class_(module, name, doc) {}

  template <class Field>
  ConfigClass& field(const char* name, Field Config::*member, const char* doc) {
    // A struct field (MapConfig.rules) is returned by reference, so that `config.rules.x = v`
    // changes the config (each of its own fields validated as it is set); other fields by value.
    py::cpp_function getter;
    if constexpr (std::is_class_v<Field>) {
      getter = py::cpp_function([member](Config& config) -> Field& { return config.*member; },
                                py::return_value_policy::reference_internal);
    } else {
      getter = py::cpp_function([member](const Config& config) { return config.*member; });
    }
    class_.def_property(
        name, getter,
        [member](Config& config, const Field& value) {
          Config changed = config;
          changed.*member = value;
          validate(changed);
          config = changed;
        },
        doc);
    names_.emplace_back(name);
    return *this;
  }
  /// Adds __repr__ (ClassName(field=value, ...)) and the copy protocol.
  py::class_<Config>& done() {
    const std::vector<std::string> names = names_;
    class_.def("__repr__", [names](const py::object& self) {
      std::string text = py::str(self.attr("__class__").attr("__name__")).cast<std::string>() + "(";
      for (std::size_t k = 0; k < names.size(); ++k) {
        if (k > 0) text += ", ";
        text += names[k] + "=" + py::repr(self.attr(names[k].c_str())).cast<std::string>();
      }
      return text + ")";
    });
    class_.def("__copy__", [](const Config& config) { return config; });
    class_.def(
        "__deepcopy__", [](const Config& config, const py::dict&) { return config; },
        py::arg("memo"));
    return class_;
  }
  py::class_<Config>& cls() { return class_; }

 private:
  py::class_<Config> class_;
  std::vector<std::string> names_;
};

/// `config` validated (the constructors' last step).
template <class Config>
Config validated(const Config& config) {
  validate(config);
  return config;
}

}  // namespace

void bindErrors(py::module_& module) {
  py::register_exception<mvog::ConfigError>(module, "ConfigError", PyExc_ValueError);
  py::register_exception<mvog::MapFileError>(module, "MapFileError", PyExc_OSError);
}

void bindConfigs(py::module_& module) {
  module.attr("DEFAULT_OCCUPANCY_THRESHOLD") = mvog::kDefaultOccupancyThreshold;
  module.attr("PAPER_OCCUPANCY_THRESHOLD") = mvog::kPaperOccupancyThreshold;

  py::enum_<mvog::MassCounting>(module, "MassCounting",
                                "How many times one scan's readings count at one height of a "
                                "column (C++ mvog::MassCounting).")
      .value("PER_READING", mvog::MassCounting::kPerReading, "the paper: every reading's volumes")
      .value("PER_SCAN", mvog::MassCounting::kPerScan, "density 1 once per scan and height");
  py::enum_<mvog::FreeSpaceRays>(module, "FreeSpaceRays",
                                 "Which rays of a scan are walked for free space.")
      .value("EVERY_READING", mvog::FreeSpaceRays::kEveryReading)
      .value("ONE_PER_END_VOXEL", mvog::FreeSpaceRays::kOnePerEndVoxel)
      .value("ONE_PATH_PER_END_COLUMN", mvog::FreeSpaceRays::kOnePathPerEndColumn);
  py::enum_<mvog::HitMemoryScope>(module, "HitMemoryScope",
                                  "Which scans hit_memory_scans groups (Sec. V.B's scan groups).")
      .value("LINE_SCANS", mvog::HitMemoryScope::kLineScans,
             "scans whose readings lie in one plane through the origin (a 2D laser's)")
      .value("EVERY_SCAN", mvog::HitMemoryScope::kEveryScan);
  py::enum_<mvog::OccupancyState>(module, "OccupancyState",
                                  "A point's or a cell's state; arrays of states hold these "
                                  "values as uint8 (0 unknown, 1 free, 2 occupied).")
      .value("UNKNOWN", mvog::OccupancyState::kUnknown)
      .value("FREE", mvog::OccupancyState::kFree)
      .value("OCCUPIED", mvog::OccupancyState::kOccupied);
  py::enum_<mvog::ReadingKind>(module, "ReadingKind", "What a range reading saw.")
      .value("OBSTACLE", mvog::ReadingKind::kObstacle,
             "a hit: free along the ray, occupied at "
             "its end")
      .value("OUT_OF_RANGE", mvog::ReadingKind::kOutOfRange, "no return: free along the ray only");

  const mvog::ModelRules rules;
  ConfigClass<mvog::ModelRules>(module, "ModelRules",
                                "The rules of the model where it departs from the paper (the "
                                "README's decisions table). ModelRules.paper() is the paper's "
                                "exact model; the defaults are the measured best.")
      .field("clip_free_space_at_hits", &mvog::ModelRules::clip_free_space_at_hits,
             "Sec. V.B: a scan's free space is clipped around the same scan's hits.")
      .field("mass_counting", &mvog::ModelRules::mass_counting, "See MassCounting.")
      .field("split_free_space_at_obstacles", &mvog::ModelRules::split_free_space_at_obstacles,
             "Sec. V.C: negative volumes are split at the bottoms and tops of positive ones.")
      .field("out_of_range_free_length", &mvog::ModelRules::out_of_range_free_length,
             "How far (m) a reading without a return frees its ray; > 0, inf for no limit.")
      .done()
      .def(py::init([](bool clip, mvog::MassCounting counting, bool split, double free_length) {
             return validated(mvog::ModelRules{clip, counting, split, free_length});
           }),
           py::kw_only(), py::arg("clip_free_space_at_hits") = rules.clip_free_space_at_hits,
           py::arg("mass_counting") = rules.mass_counting,
           py::arg("split_free_space_at_obstacles") = rules.split_free_space_at_obstacles,
           py::arg("out_of_range_free_length") = rules.out_of_range_free_length)
      .def_static("paper", &mvog::ModelRules::paper, "The model exactly as the paper describes it.")
      .def(py::self == py::self);

  const mvog::MapConfig map_config;
  ConfigClass<mvog::MapConfig>(module, "MapConfig", "The map itself (C++ mvog::MapConfig).")
      .field("resolution", &mvog::MapConfig::resolution,
             "Edge of a square cell (m); s = 1 / resolution. Finite, > 0.")
      .field("max_coordinate", &mvog::MapConfig::max_coordinate,
             "Readings whose origin or end lies further than this from the map origin along any "
             "axis (m) are rejected. Finite, > 0, at most 4194304 cells.")
      .field("rules", &mvog::MapConfig::rules, "The ModelRules (saved with the map).")
      .done()
      .def(py::init([](double resolution, double max_coordinate, const mvog::ModelRules& r) {
             return validated(mvog::MapConfig{resolution, max_coordinate, r});
           }),
           py::kw_only(), py::arg("resolution") = map_config.resolution,
           py::arg("max_coordinate") = map_config.max_coordinate,
           py::arg("rules") = map_config.rules);

  const mvog::InsertionConfig insertion;
  ConfigClass<mvog::InsertionConfig>(module, "InsertionConfig",
                                     "How readings are turned into volumes (Sec. III-B).")
      .field("min_range", &mvog::InsertionConfig::min_range,
             "Hits closer than this to the sensor (m) are dropped. Finite, >= 0.")
      .field("max_range", &mvog::InsertionConfig::max_range,
             "Hits further than this (m) become out-of-range readings truncated to it; > 0, "
             "inf for no limit.")
      .field("insert_out_of_range", &mvog::InsertionConfig::insert_out_of_range,
             "Whether out-of-range readings add free space.")
      .field("model_negative_space", &mvog::InsertionConfig::model_negative_space,
             "Whether negative (free-space) volumes are created at all.")
      .field("insertion_threads", &mvog::InsertionConfig::insertion_threads,
             "Threads of one insertion, in [1, 256]; the map is the same for any count.")
      .field("free_space_rays", &mvog::InsertionConfig::free_space_rays, "See FreeSpaceRays.")
      .field("evidence_limit", &mvog::InsertionConfig::evidence_limit,
             "Scans of evidence a height keeps (bounded evidence, OctoMap's clamping); >= 1, inf "
             "for none. Unbounded with per-reading masses (the paper's rules).")
      .field("hit_memory_scans", &mvog::InsertionConfig::hit_memory_scans,
             "Scans before a scan whose hits clip its free space as its own do (Sec. V.B's scan "
             "groups, with clip_free_space_at_hits); 0 (its own only) to 100.")
      .field("hit_memory_scope", &mvog::InsertionConfig::hit_memory_scope, "See HitMemoryScope.")
      .done()
      .def(py::init([](double min_range, double max_range, bool insert_out_of_range,
                       bool model_negative_space, int threads, mvog::FreeSpaceRays rays,
                       double evidence_limit, int hit_memory_scans, mvog::HitMemoryScope scope) {
             return validated(mvog::InsertionConfig{min_range, max_range, insert_out_of_range,
                                                    model_negative_space, threads, rays,
                                                    evidence_limit, hit_memory_scans, scope});
           }),
           py::kw_only(), py::arg("min_range") = insertion.min_range,
           py::arg("max_range") = insertion.max_range,
           py::arg("insert_out_of_range") = insertion.insert_out_of_range,
           py::arg("model_negative_space") = insertion.model_negative_space,
           py::arg("insertion_threads") = insertion.insertion_threads,
           py::arg("free_space_rays") = insertion.free_space_rays,
           py::arg("evidence_limit") = insertion.evidence_limit,
           py::arg("hit_memory_scans") = insertion.hit_memory_scans,
           py::arg("hit_memory_scope") = insertion.hit_memory_scope);

  const mvog::PlanningConfig planning;
  ConfigClass<mvog::PlanningConfig>(module, "PlanningConfig",
                                    "What planners and explorers ask the map: segment and box "
                                    "checks, frontiers, surfaces, the traversable map. Heights "
                                    "in metres, map frame.")
      .field("occupancy_threshold", &mvog::PlanningConfig::occupancy_threshold,
             "Occupied where eq. (9) gives p above it. In [0, 1).")
      .field("max_query_cells", &mvog::PlanningConfig::max_query_cells,
             "The most cells one segment or box check may visit (a larger one is refused). >= 1.")
      .field("frontier_min_z", &mvog::PlanningConfig::frontier_min_z,
             "Frontiers: lowest height (m) searched.")
      .field("frontier_max_z", &mvog::PlanningConfig::frontier_max_z,
             "Frontiers: highest height (m) searched.")
      .field("frontier_min_cells", &mvog::PlanningConfig::frontier_min_cells,
             "Frontiers: smaller connected pieces are dropped. >= 1.")
      .field("robot_height", &mvog::PlanningConfig::robot_height,
             "Traversable map: the free height (m) the robot needs above a surface.")
      .field("max_step", &mvog::PlanningConfig::max_step,
             "Traversable map: the largest step (m) between neighbouring surfaces.")
      .field("traversable_min_z", &mvog::PlanningConfig::traversable_min_z,
             "Traversable map: lowest height (m) of the ground.")
      .field("traversable_max_z", &mvog::PlanningConfig::traversable_max_z,
             "Traversable map: highest height (m) of the ground.")
      .done()
      .def(py::init([](double threshold, std::int64_t max_query_cells, double frontier_min_z,
                       double frontier_max_z, int frontier_min_cells, double robot_height,
                       double max_step, double traversable_min_z, double traversable_max_z) {
             return validated(mvog::PlanningConfig{threshold, max_query_cells, frontier_min_z,
                                                   frontier_max_z, frontier_min_cells, robot_height,
                                                   max_step, traversable_min_z, traversable_max_z});
           }),
           py::kw_only(), py::arg("occupancy_threshold") = planning.occupancy_threshold,
           py::arg("max_query_cells") = planning.max_query_cells,
           py::arg("frontier_min_z") = planning.frontier_min_z,
           py::arg("frontier_max_z") = planning.frontier_max_z,
           py::arg("frontier_min_cells") = planning.frontier_min_cells,
           py::arg("robot_height") = planning.robot_height, py::arg("max_step") = planning.max_step,
           py::arg("traversable_min_z") = planning.traversable_min_z,
           py::arg("traversable_max_z") = planning.traversable_max_z);

  const mvog::DepthImageConfig depth;
  ConfigClass<mvog::DepthImageConfig>(module, "DepthImageConfig",
                                      "How a depth image becomes readings.")
      .field("stride", &mvog::DepthImageConfig::stride,
             "Every stride-th pixel in both directions is kept, from pixel (0, 0). >= 1.")
      .field("no_return_length", &mvog::DepthImageConfig::no_return_length,
             "A +inf float pixel (no return) is an out-of-range reading this far (m) along its "
             "ray; inf: such pixels are skipped.")
      .done()
      .def(py::init([](int stride, double no_return_length) {
             return validated(mvog::DepthImageConfig{stride, no_return_length});
           }),
           py::kw_only(), py::arg("stride") = depth.stride,
           py::arg("no_return_length") = depth.no_return_length);

  ConfigClass<mvog::PinholeCamera>(module, "PinholeCamera",
                                   "The pinhole camera of a rectified depth image (the K of a "
                                   "ROS CameraInfo, pixels): pixel (u, v) at depth z is the point "
                                   "((u - cx) z / fx, (v - cy) z / fy, z) of the optical frame "
                                   "(x right, y down, z forward).")
      .field("fx", &mvog::PinholeCamera::fx, "Focal length in x (pixels), finite, non-zero.")
      .field("fy", &mvog::PinholeCamera::fy, "Focal length in y (pixels), finite, non-zero.")
      .field("cx", &mvog::PinholeCamera::cx, "Principal point x (pixels), finite.")
      .field("cy", &mvog::PinholeCamera::cy, "Principal point y (pixels), finite.")
      .done()
      .def(py::init([](double fx, double fy, double cx, double cy) {
             return validated(mvog::PinholeCamera{fx, fy, cx, cy});
           }),
           py::kw_only(), py::arg("fx"), py::arg("fy"), py::arg("cx"), py::arg("cy"));

  ConfigClass<mvog::GridTransform>(module, "GridTransform",
                                   "A transform between two maps of one resolution that keeps "
                                   "the grid (Map.merge): quarter_turns x 90 degrees about z "
                                   "(counter-clockwise), then whole cells in x and y and dz "
                                   "metres in z.")
      .field("quarter_turns", &mvog::GridTransform::quarter_turns, "Any integer, modulo 4.")
      .field("dx_cells", &mvog::GridTransform::dx_cells, "Translation in x (cells).")
      .field("dy_cells", &mvog::GridTransform::dy_cells, "Translation in y (cells).")
      .field("dz", &mvog::GridTransform::dz, "Translation in z (m).")
      .done()
      .def(py::init([](int quarter_turns, std::int64_t dx, std::int64_t dy, double dz) {
             return mvog::GridTransform{quarter_turns, dx, dy, dz};
           }),
           py::kw_only(), py::arg("quarter_turns") = 0, py::arg("dx_cells") = 0,
           py::arg("dy_cells") = 0, py::arg("dz") = 0.0)
      .def_static("from_matrix", &mvog::GridTransform::fromMatrix, py::arg("this_from_other"),
                  py::arg("resolution"),
                  "The 4 x 4 homogeneous transform this_from_other (m) as a GridTransform for maps "
                  "of `resolution`; ConfigError unless it is a yaw by a multiple of 90 degrees "
                  "and whole cells in x and y.");
}

}  // namespace mvog_python
