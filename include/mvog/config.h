#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

#include <Eigen/Core>

namespace mvog {

/// Thrown by a config's validate() and by Map for invalid arguments; the message names the field.
class ConfigError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// How many times one scan's readings count at one height of a column.
enum class MassCounting : std::uint8_t {
  /// The paper (Sec. III-B.2): every reading adds its own volumes, each of density 1, so a
  /// column that 200 rays of a scan cross gains 200 times the mass of a column one ray ends in.
  kPerReading,
  /// Each scan adds density 1 once over the union of the heights its readings saw in the column:
  /// the readings of one scan share one pose and one instant, so they are not independent
  /// observations of a column (OctoMap's insertPointCloud updates each voxel once per scan too).
  kPerScan,
};

/// The default of ModelRules::out_of_range_free_length (m), chosen by measurement (BENCHMARKS.md).
constexpr double kDefaultOutOfRangeFreeLength = 2.0;

/// The rules of the model where it departs from the paper's text (the README's decisions table).
/// ModelRules::paper() is the paper's exact model; the defaults are the measured best.
struct ModelRules {
  /// Sec. V.B: in each column, a scan's free space is clipped around the positive volumes of the
  /// same scan (a reading never frees the space where another reading of its scan hit).
  bool clip_free_space_at_hits = true;
  /// See MassCounting.
  MassCounting mass_counting = MassCounting::kPerScan;
  /// Sec. V.C: negative volumes are split at the bottoms and tops of positive volumes, so that
  /// the free space seen within an obstacle's heights keeps its own density in eq. (9) instead
  /// of the average over the whole free column (which erases surfaces under dense free space).
  bool split_free_space_at_obstacles = true;
  /// An out-of-range reading (no return) frees its ray only this far from the sensor (m): a
  /// dark or glancing surface returns nothing too, so a ray without a return may have crossed a
  /// wall the sensor did not see, and a long one (80 m for a SICK) costs a long walk. Hits
  /// truncated by InsertionConfig::max_range are returns: they keep their free space up to it.
  /// Infinity (the paper): up to the reading's end.
  double out_of_range_free_length = kDefaultOutOfRangeFreeLength;

  /// The model exactly as the paper describes it.
  static ModelRules paper() {
    return {false, MassCounting::kPerReading, false, std::numeric_limits<double>::infinity()};
  }
  friend bool operator==(const ModelRules& a, const ModelRules& b) {
    return a.clip_free_space_at_hits == b.clip_free_space_at_hits &&
           a.mass_counting == b.mass_counting &&
           a.split_free_space_at_obstacles == b.split_free_space_at_obstacles &&
           a.out_of_range_free_length == b.out_of_range_free_length;
  }
};

/// A point is occupied where eq. (9) gives p above a threshold (Sec. III-C); this is the default
/// of the server's ~occupancy_threshold and of every tool. With MassCounting::kPerScan, p is the
/// share of the scans that looked at a height and saw it hit. OctoMap's default sensor model
/// (hit 0.7, miss 0.4) calls a voxel occupied once that share of its updates exceeds
/// |logit(0.4)| / (logit(0.7) + |logit(0.4)|) = 0.324 (ignoring its clamping): the same rule. A
/// surface that rays also cross at grazing angles reflects only a part of them, free space none,
/// so occupancy does not need a majority of hits.
constexpr double kDefaultOccupancyThreshold = 0.324;
/// The paper's threshold (Fig. 4: "probability of occupancy greater than 0.5").
constexpr double kPaperOccupancyThreshold = 0.5;

/// The map itself.
struct MapConfig {
  /// Edge of a square cell in metres; s = 1 / resolution (Sec. III-A).
  double resolution = 0.1;
  /// Readings whose origin or end lies further than this from the map origin along any axis (m)
  /// are rejected, so that a wild point cannot make the map grow without bound (Sec. V.A).
  double max_coordinate = 10000.0;
  /// How readings become volumes and how the lists are kept (saved with the map).
  ModelRules rules;

  /// Whether `point` (m) is finite and within max_coordinate of the origin along every axis:
  /// the only points readings and queries may reach.
  bool withinBounds(const Eigen::Vector3d& point) const {
    // A NaN or an infinite coordinate fails its comparison, max_coordinate being finite in a
    // validated config (every Map's).
    return std::fabs(point.x()) <= max_coordinate && std::fabs(point.y()) <= max_coordinate &&
           std::fabs(point.z()) <= max_coordinate;
  }

  /// Throws ConfigError naming the first invalid field.
  void validate() const;
};

/// The default of InsertionConfig::evidence_limit (scans): OctoMap's clamping range counted in
/// misses, (logit(0.971) - logit(0.1192)) / |logit(0.4)| = 13.6 with its defaults, the evidence
/// an OctoMap voxel can hold between its two clamps.
constexpr double kDefaultEvidenceLimit = 14.0;

/// Which rays of a scan are walked for free space (Sec. III-B.1).
enum class FreeSpaceRays : std::uint8_t {
  /// Every reading's ray (the paper).
  kEveryReading,
  /// With MassCounting::kPerScan, one ray per end voxel: of the readings of a scan that end in
  /// one cell at one height cell (and alike in being a hit or not), 4 or more free space along
  /// one ray, that of the reading ending nearest the voxel's centre; fewer are walked each. Each
  /// hit still adds its own positive volume (eq. 5). A scan adds density 1 once over the union of
  /// the heights its readings saw in a column, and n readings spread over a voxel lie about
  /// 1 / sqrt(n) cells apart, from 4 on half a cell or less: their rays free nearly the same
  /// cells at nearly the same heights (eq. 6 gives each crossing a cell of height). A depth
  /// camera at 1-4 m puts tens to hundreds of pixels in a voxel. The scan's free space is a
  /// subset of every reading's. OctoMap's discretize option and Bonxai cast once per end voxel
  /// too. With MassCounting::kPerReading every reading adds its own mass and every ray is
  /// walked.
  kOnePerEndVoxel,
  /// kOnePerEndVoxel, and the rays of its voxels of 4 or more readings that end in one column
  /// (and alike in being a hit or not) walked along one path: a run of them whose end heights
  /// lie at most 2 cells apart follows the xy-path of its ray ending nearest the column's axis,
  /// each cell before the column getting the hull of the run's lowest and highest rays' crossings
  /// there (eq. 6 each). Rays from one origin whose end heights differ by d differ by at most d
  /// where they cross a cell, and each crossing is a cell high or more: the rays between those
  /// two fill that hull, and a scan's intervals a gap of kMaxMergeGap apart join. Rays that share
  /// their path free exactly what each walked alone frees. In the column each ray keeps its own
  /// last crossing (Fig. 3). Each of these rays ends near its voxel's centre, so that their paths
  /// part by less than a cell at the column and less towards the origin; a depth camera's wall
  /// puts tens of voxels in a column, whose walks become one. The readings of voxels of fewer
  /// are walked each, as kOnePerEndVoxel does: a sparse sensor's rays part by up to a cell.
  /// Not the default: it frees a little less near surfaces on the ground-truth scenes
  /// (BENCHMARKS.md section 5), for 15 % fewer instructions on a depth camera's frames.
  kOnePathPerEndColumn,
};

/// The most scans InsertionConfig::hit_memory_scans may name: their hits are kept by column.
constexpr int kMaxHitMemoryScans = 100;

/// Which scans InsertionConfig::hit_memory_scans groups (Sec. V.B's scan groups).
enum class HitMemoryScope : std::uint8_t {
  /// Line scans (their readings in one plane through the origin: a 2D laser's scan, one line of
  /// a tilting laser) remember the hits of the line scans before them; any other scan (a depth
  /// image, a lidar's sweep, a tilting laser's whole nod) is a group of its own and forgets them.
  kLineScans,
  /// Every scan: a tilting laser's nods from poses across a room keep each other's hits too (its
  /// surfaces called free fall by a third to a half), but a depth camera's noisy hits hide the
  /// free space beside surfaces for as many frames (BENCHMARKS.md section 13).
  kEveryScan,
};

/// How readings are turned into volumes (Sec. III-B).
struct InsertionConfig {
  /// Obstacle readings closer than this to the sensor (m) are dropped.
  double min_range = 0.0;
  /// Obstacle readings further than this (m) become out-of-range readings truncated to it, and
  /// out-of-range readings are truncated to it too.
  double max_range = std::numeric_limits<double>::infinity();
  /// Whether out-of-range readings add free space (Sec. III-B.1); if false they are ignored.
  bool insert_out_of_range = true;
  /// Whether negative (free-space) volumes are created at all.
  bool model_negative_space = true;
  /// Threads used by Map::insertScan; the resulting map is identical for any count.
  int insertion_threads = 1;
  /// See FreeSpaceRays (the README's decisions table: measured agreement with every reading's
  /// walk in BENCHMARKS.md).
  FreeSpaceRays free_space_rays = FreeSpaceRays::kOnePerEndVoxel;
  /// Bounded evidence (OctoMap's clamping): after a scan's update of a column, a volume whose
  /// density (eq. 2) and the highest density of the other list's volumes it overlaps sum to more
  /// than this has its mass scaled down so that they sum to it (boundEvidence). A height then
  /// remembers at most this many scans (with MassCounting::kPerScan), and each new scan weighs
  /// at least its share: a wall cell that grazing rays crossed in many scans is occupied again
  /// after a few hits, a place a person left clears within a few scans, where unbounded sums
  /// take as many scans as came before. Scaling both lists alike keeps p (eq. 9) where they
  /// overlap. Not saved in the map file (as OctoMap's clamping is not in its .ot files). With
  /// MassCounting::kPerReading (the paper's rules) densities count readings, not scans, and are
  /// unbounded whatever it says. Infinity: unbounded.
  double evidence_limit = kDefaultEvidenceLimit;
  /// Sec. V.B's scan groups: with ModelRules::clip_free_space_at_hits, a scan's free space in a
  /// column is clipped around the hits of the previous hit_memory_scans scans inserted into the
  /// map as well as around its own (joined as its own are), for the scans hit_memory_scope says.
  /// A line scan alone samples a surface along one line: a laser that grazes a wall in the lines
  /// before and after the few that hit it would erase those hits. A scan of a 2D sensor (a depth
  /// image, a sweep) is already the group the paper asks for. Every insertion into the map that
  /// inserts a reading counts as a scan (a single reading too); one with 0, one outside the
  /// scope, and Map::clear forget the hits kept. They are held beside the map (Map::memoryUsage).
  /// The default, 5: on the 2D laser's ground-truth scene the surfaces called free reach their
  /// floor at 2-3 scans and its thin objects pass OctoMap's at 5, while each further scan takes
  /// free space along the rays of the 2D laser logs (BENCHMARKS.md section 13). 0: a scan's own
  /// hits only (the paper's). At most kMaxHitMemoryScans. Not saved in the map file.
  int hit_memory_scans = 5;
  /// See HitMemoryScope.
  HitMemoryScope hit_memory_scope = HitMemoryScope::kLineScans;

  /// Throws ConfigError naming the first invalid field.
  void validate() const;
  /// The evidence limit an insertion into a map of `rules` applies: evidence_limit with
  /// MassCounting::kPerScan, none (infinity) with kPerReading.
  double appliedEvidenceLimit(const ModelRules& rules) const {
    return rules.mass_counting == MassCounting::kPerScan ? evidence_limit
                                                         : std::numeric_limits<double>::infinity();
  }
  /// The scans whose hits an insertion into a map of `rules` remembers: hit_memory_scans with
  /// ModelRules::clip_free_space_at_hits, none without (no hit clips free space then).
  int appliedHitMemoryScans(const ModelRules& rules) const {
    return rules.clip_free_space_at_hits ? hit_memory_scans : 0;
  }
};

}  // namespace mvog
