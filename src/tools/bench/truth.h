#pragma once
// mvog_bench's ground truth: scenes built in code with exact geometry (mvog_scene), each with its
// own sensor and trajectory ("truth:NAME"), query points labelled from the geometry, and every
// backend's map scored at them.

#include <array>
#include <cstddef>
#include <functional>
#include <string>
#include <string_view>
#include <unordered_set>
#include <vector>

#include <Eigen/Core>

#include "backends.h"
#include "input.h"
#include "mvog_scene/scene.h"

namespace mvog_bench {

/// What names a ground-truth scene instead of a file: "truth:NAME" (truthScene).
constexpr std::string_view kTruthPrefix = "truth:";

/// A plane of the scene drawn by writeTruthSlice: pixel (column, row) is at
/// corner + across * (column + 0.5) / width + down * (row + 0.5) / height.
struct SlicePlane {
  Eigen::Vector3d corner;
  Eigen::Vector3d across;
  Eigen::Vector3d down;
  double pixel_size = 0.01;  ///< m
};

/// A scene with exact geometry and the scans its sensor takes of it.
struct TruthScene {
  std::string name;
  mvog_scene::Scene scene;         ///< everything a ray can meet
  mvog_scene::Scene thin_objects;  ///< poles, legs, cables: also in `scene`
  /// Table tops, a bridge deck: the space right under them is free space a planner needs.
  std::vector<mvog_scene::Box> overhangs;
  SlicePlane slice;  ///< where the errors are best seen
  /// The sensor's scans (hits; out-of-range readings aside, as every input's).
  std::function<std::vector<mvog::Scan>()> scans;
};

/// The scene `name`: "room-depth-camera", "bridge-lidar-16", "car-lidar", "corridor-2d-laser"
/// or "tilting-laser". Throws InputError for an unknown name.
TruthScene truthScene(const std::string& name);

/// The scene's scans as an input of format "truth".
InputData loadTruth(const TruthScene& truth);

/// Query points labelled from the geometry, for maps at one cell size.
struct TruthLabels {
  /// Just inside a surface where a sampled ray meets it (its exact hit, 1 mm further).
  std::vector<Eigen::Vector3d> surface;
  std::vector<Eigen::Vector3d> thin;  ///< those of `surface` inside a thin object
  /// On the sampled rays (uniformly along them, and 2-4 cells in front of their exact hits),
  /// more than kFreeMarginCells from every obstacle: within kNearSurfaceCells of one, farther.
  std::vector<Eigen::Vector3d> free_near_surface;
  std::vector<Eigen::Vector3d> free_far_from_surfaces;
  /// Those free points (and more on the rays through the zone) at most kOverhangDepth below an
  /// overhang, within its footprint.
  std::vector<Eigen::Vector3d> free_under_overhang;
  /// Farther than kUnobservedDistance from every ray: around the data, behind walls, inside
  /// closed furniture.
  std::vector<Eigen::Vector3d> unobserved;
};

/// Free points keep more than this many cells from every obstacle, so that their voxel (at
/// most sqrt(3) cells across) rarely reaches one: a map with perfect knowledge of what was seen
/// would call it free.
constexpr double kFreeMarginCells = 1.0;
constexpr double kNearSurfaceCells = 4.0;
constexpr double kOverhangDepth = 0.5;  ///< m
/// The voxel edge and reach of the coverage that finds points no ray came near.
constexpr double kCoverageVoxel = 0.125;  ///< m
constexpr int kCoverageReach = 2;         ///< voxels: farther than 0.25 m from every ray

TruthLabels labelPoints(const TruthScene& truth, const InputData& input,
                        const RayCoverage& coverage, double resolution);

/// How a map did at the labelled points.
struct TruthScores {
  StateCounts surface;
  StateCounts thin;
  StateCounts free_near_surface;
  StateCounts free_far_from_surfaces;
  StateCounts free_under_overhang;
  StateCounts unobserved;

  /// Shares of the points (NaN without points).
  static double share(const StateCounts& counts, mvog::OccupancyState state);
  /// F1 of "occupied" over the surface points (positive) and every free point (negative): a
  /// surface point not called occupied is a miss, a free point called occupied a false alarm.
  double occupancyF1() const;
};

/// The scores of a map whose state at p is `state_of(p)`.
template <class StateOf>
TruthScores scoreMap(const TruthLabels& labels, const StateOf& state_of) {
  return {statesAt(labels.surface, state_of),
          statesAt(labels.thin, state_of),
          statesAt(labels.free_near_surface, state_of),
          statesAt(labels.free_far_from_surfaces, state_of),
          statesAt(labels.free_under_overhang, state_of),
          statesAt(labels.unobserved, state_of)};
}

/// The check of the labels: a classifier with perfect knowledge of the geometry and of where
/// the rays went (unknown where no ray came near, else occupied inside an obstacle, else free).
mvog::OccupancyState oracleState(const TruthScene& truth, const RayCoverage& coverage,
                                 const Eigen::Vector3d& point);

/// The map of the endpoints alone: occupied in the voxels (edge `resolution`) holding a hit,
/// unknown elsewhere, never free.
class EndpointsMap {
 public:
  EndpointsMap(const InputData& input, double max_range, double resolution);
  mvog::OccupancyState state(const Eigen::Vector3d& point) const;

 private:
  double resolution_;
  std::unordered_set<std::uint64_t> voxels_;
};

/// One panel of a slice: the states a map of cell size `resolution` gives at the pixels of a
/// plane.
struct SlicePanel {
  double resolution = 0.0;
  std::vector<mvog::OccupancyState> states;
};
SlicePanel slicePanel(const SlicePlane& plane, double resolution,
                      const std::function<mvog::OccupancyState(const Eigen::Vector3d&)>& state_of);

/// Writes the panels (each a slicePanel of truth.slice), one under the other, as a binary PPM,
/// judged as the labels are: white free space called free, black obstacles called occupied (and
/// space within kFreeMarginCells of one, called occupied or free), red free space called
/// occupied, blue obstacles called free, yellow free space the rays reached (their voxels of
/// the coverage) called unknown, dark grey obstacles called unknown, light grey space no ray
/// reached called unknown. Throws std::runtime_error if it cannot be written.
void writeTruthSlice(const TruthScene& truth, const RayCoverage& coverage,
                     const std::vector<SlicePanel>& panels, const std::string& path);

}  // namespace mvog_bench
