// Merging maps (Map::merge): exact under transforms that keep the grid, refused otherwise; the
// merge of two halves of a set of scans against the map of all of them.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "../recordings.h"
#include "input.h"  // mvog_bench's scan graph reader (src/tools/bench), ROS-free
#include "mvog/map.h"
#include "mvog/map_io.h"
#include "test_util.h"

namespace mvog {
namespace {

using Bytes = std::vector<std::uint8_t>;
using test::allVolumes;
using test::kNaN;
using test::VolumeRecord;

constexpr double kPi = 3.14159265358979323846;

Map copyOf(const Map& map) {
  const Bytes bytes = serializeMap(map);
  return deserializeMap(bytes.data(), bytes.size());
}

std::vector<VolumeRecord> sortedVolumes(const Map& map) {
  std::vector<VolumeRecord> records = allVolumes(map);
  std::sort(records.begin(), records.end());
  return records;
}

/// The share of `points` where two maps give the same state (occupied, free or unknown), among
/// the points where at least one of them knows something.
double agreement(const Map& a, const Map& b, const std::vector<Eigen::Vector3d>& points,
                 std::size_t& known) {
  std::size_t same = 0;
  known = 0;
  for (const Eigen::Vector3d& p : points) {
    const OccupancyState sa = a.occupancy(p).state(kDefaultOccupancyThreshold);
    const OccupancyState sb = b.occupancy(p).state(kDefaultOccupancyThreshold);
    if (sa == OccupancyState::kUnknown && sb == OccupancyState::kUnknown) continue;
    ++known;
    same += sa == sb;
  }
  return known == 0 ? 0.0 : static_cast<double>(same) / static_cast<double>(known);
}

/// A rigid transform: yaw (rad) about z, then a translation (m).
Eigen::Matrix4d transform(double yaw, double x, double y, double z) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m(0, 0) = std::cos(yaw);
  m(0, 1) = -std::sin(yaw);
  m(1, 0) = std::sin(yaw);
  m(1, 1) = std::cos(yaw);
  m(0, 3) = x;
  m(1, 3) = y;
  m(2, 3) = z;
  return m;
}

// ---- Exactness
// ------------------------------------------------------------------------------------

TEST(Merge, IntoAnEmptyMapWithNoTransformCopiesEveryListExactly) {
  for (const ModelRules& rules : {ModelRules{}, ModelRules::paper()}) {
    Map source = test::randomMap(1, 0.2, 5.0, 4, rules);
    source.decay(0.37);  // the other map's masses are brought to this map's unit
    MapConfig config = source.config();
    Map target(config);
    target.merge(source);
    EXPECT_TRUE(test::sameVolumes(allVolumes(target), allVolumes(source)));
    EXPECT_EQ(serializeMap(target), serializeMap(source));
  }
}

TEST(Merge, WithItselfDoublesEveryMassExactly) {
  for (const ModelRules& rules : {ModelRules{}, ModelRules::paper()}) {
    Map map = test::randomMap(2, 0.2, 5.0, 4, rules);
    std::vector<VolumeRecord> doubled = allVolumes(map);
    for (VolumeRecord& r : doubled) std::get<5>(r) *= 2.0f;
    Map with_copy = copyOf(map);
    with_copy.merge(copyOf(map));
    EXPECT_TRUE(test::sameVolumes(allVolumes(with_copy), doubled));
    map.merge(map);  // the same map as the other: read whole before anything is written
    EXPECT_TRUE(test::sameVolumes(allVolumes(map), doubled));
  }
}

TEST(Merge, ATransformMovesEveryCellAsDocumented) {
  Map other(test::unitConfig(1000.0, ModelRules{}));
  other.setCellVolumes({2, 5}, CellVolumes{{{0, 1, 1}}, {{-3, -1, 2}}});
  other.setCellVolumes({-1, 0}, CellVolumes{{{4, 6, 3}}, {}});
  for (int turns = -1; turns <= 4; ++turns) {
    const GridTransform t{turns, 10, -20, 2.0};
    Map map(other.config());
    map.merge(other, t);
    for (const auto& [cell, volumes] : {std::pair{CellIndex{2, 5}, other.cellVolumes({2, 5})},
                                        std::pair{CellIndex{-1, 0}, other.cellVolumes({-1, 0})}}) {
      CellIndex target = cell;
      for (int k = 0; k < ((turns % 4) + 4) % 4; ++k) target = {-target.y - 1, target.x};
      target = {target.x + 10, target.y - 20};
      const CellVolumes moved = map.cellVolumes(target);
      ASSERT_EQ(moved.positive.size(), volumes.positive.size()) << "turns " << turns;
      for (std::size_t k = 0; k < volumes.positive.size(); ++k) {
        EXPECT_TRUE(test::volumeIs(moved.positive[k], volumes.positive[k].bottom + 2,
                                   volumes.positive[k].top + 2, volumes.positive[k].mass));
      }
    }
    EXPECT_EQ(map.memoryUsage().cells_with_volumes, 2u);
  }
}

/// `scan` turned by quarter_turns x 90 degrees about z: (x, y) -> (-y, x), exact in float.
Scan turned(Scan scan, int quarter_turns) {
  auto turn = [&](auto p) {
    for (int k = 0; k < quarter_turns; ++k) p = {-p.y(), p.x(), p.z()};
    return p;
  };
  scan.origin = turn(scan.origin);
  for (auto* points : {&scan.hits, &scan.out_of_range}) {
    for (Eigen::Vector3f& p : *points) p = turn(p);
  }
  return scan;
}

/// Four random scans from near the origin, within 6 m.
std::vector<Scan> fourScans(unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<Scan> scans;
  for (int k = 0; k < 4; ++k) {
    scans.push_back(test::randomScan(rng, test::randomPoint(rng, 2.0, 0.5), 1500, 500, 6.0));
  }
  return scans;
}

TEST(Merge, QuarterTurnsCommuteWithInsertionExactly) {
  // The map of turned scans is the map of the scans, merged turned. Exact: the turn is exact in
  // float, and the walk's arithmetic in the turned frame is the same with x and y swapped, but
  // where a ray meets a grid corner exactly, or a point lies exactly on a grid line (both of
  // probability ~0 here: random float coordinates).
  MapConfig config;
  config.resolution = 0.1;
  const std::vector<Scan> scans = fourScans(3);
  for (const ModelRules& rules : {ModelRules{}, ModelRules::paper()}) {
    config.rules = rules;
    Map original(config);
    for (const Scan& scan : scans) original.insertScan(scan);
    for (int turns = 1; turns < 4; ++turns) {
      Map of_turned(config);
      for (const Scan& scan : scans) of_turned.insertScan(turned(scan, turns));
      Map merged(config);
      merged.merge(original, GridTransform{turns, 0, 0, 0.0});
      EXPECT_TRUE(test::sameVolumes(sortedVolumes(merged), sortedVolumes(of_turned)))
          << "turns " << turns;
    }
  }
}

TEST(Merge, WholeCellShiftsCommuteWithInsertionUpToRounding) {
  // Shifted, a ray's heights are summed in another order (z0 + t dz, z0 itself shifted), so they
  // differ by float roundings, and where such a rounding decides a merge (a gap of exactly 1),
  // by a volume: compare the states at points.
  MapConfig config;
  config.resolution = 0.1;
  const std::vector<Scan> scans = fourScans(4);
  std::mt19937 rng(5);
  const GridTransform shift{1, 17, -5, 0.3};
  const Eigen::Vector3d offset(1.7, -0.5, 0.3);
  Map original(config);
  Map of_shifted(config);
  for (const Scan& scan : scans) {
    original.insertScan(scan);
    Scan moved = turned(scan, 1);
    moved.origin += offset;
    for (auto* points : {&moved.hits, &moved.out_of_range}) {
      for (Eigen::Vector3f& p : *points) p += offset.cast<float>();
    }
    of_shifted.insertScan(moved);
  }
  Map merged(config);
  merged.merge(original, shift);
  std::vector<Eigen::Vector3d> points;
  for (int k = 0; k < 100000; ++k) points.push_back(test::randomPoint(rng, 7.0, 3.0) + offset);
  std::size_t known = 0;
  const double share = agreement(merged, of_shifted, points, known);
  const ::testing::AssertionResult lists =
      test::sameVolumes(sortedVolumes(merged), sortedVolumes(of_shifted));
  std::printf(
      "[ figure ] a quarter turn and a shift of (17, -5) cells and 0.3 m: the same state "
      "at %.4f %% of %zu known points; lists: %s\n",
      100.0 * share, known, lists ? "equal" : lists.message());
  EXPECT_GT(known, 10000u);
  EXPECT_GE(share, 0.999);
}

// ---- Two halves against the whole
// -----------------------------------------------------------------

double positiveMass(const Map& map) {
  double mass = 0.0;
  map.forEachVolume([&](const CellIndex&, VolumeSign sign, const Volume& v) {
    if (sign == VolumeSign::kPositive) mass += v.mass;
  });
  return mass;
}

/// The maps of all scans, and of the two halves merged (the first into the second half's map).
struct Halves {
  Map whole;
  Map merged;
};

Halves mapsOfHalves(const std::vector<Scan>& scans, const MapConfig& config,
                    const InsertionConfig& insertion = {}) {
  Halves maps{Map(config), Map(config)};
  Map first_half(config);
  for (std::size_t k = 0; k < scans.size(); ++k) {
    maps.whole.insertScan(scans[k], insertion);
    (k < scans.size() / 2 ? first_half : maps.merged).insertScan(scans[k], insertion);
  }
  maps.merged.merge(first_half);
  return maps;
}

/// Random points near the scans' hits (where the maps hold something to compare).
std::vector<Eigen::Vector3d> pointsNearHits(const std::vector<Scan>& scans, std::size_t count,
                                            double spread, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> offset(0.0, spread);
  std::vector<Eigen::Vector3d> points;
  for (std::size_t k = 0; k < count; ++k) {
    const Scan& scan = scans[rng() % scans.size()];
    const Eigen::Vector3d hit = scan.hits[rng() % scan.hits.size()].cast<double>();
    // Along the ray, on either side of its hit, and off it.
    const double along = std::uniform_real_distribution<double>(0.0, 1.1)(rng);
    points.push_back(scan.origin + along * (hit - scan.origin) +
                     Eigen::Vector3d(offset(rng), offset(rng), offset(rng)));
  }
  return points;
}

/// A room [-4, 4] x [-3, 3] x [0, 2.5] with a table [0.5, 1.5] x [-1, 0] x [0, 0.8], seen with
/// `rays` random rays from `origin`: the hit of each ray.
Scan roomScan(const Eigen::Vector3d& origin, int rays, std::mt19937& rng) {
  const Eigen::Vector3d room_min(-4, -3, 0), room_max(4, 3, 2.5);
  const Eigen::Vector3d table_min(0.5, -1, 0), table_max(1.5, 0, 0.8);
  std::normal_distribution<double> normal(0.0, 1.0);
  Scan scan;
  scan.origin = origin;
  for (int k = 0; k < rays; ++k) {
    const Eigen::Vector3d d = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
    double t = std::numeric_limits<double>::infinity();
    double entry = 0.0;
    double exit = t;
    for (int axis = 0; axis < 3; ++axis) {
      const double to_wall = ((d[axis] > 0 ? room_max : room_min)[axis] - origin[axis]) / d[axis];
      t = std::min(t, to_wall);
      const double a = (table_min[axis] - origin[axis]) / d[axis];
      const double b = (table_max[axis] - origin[axis]) / d[axis];
      entry = std::max(entry, std::min(a, b));
      exit = std::min(exit, std::max(a, b));
    }
    if (entry <= exit && entry > 0.0) t = std::min(t, entry);
    scan.hits.push_back((origin + t * d).cast<float>());
  }
  return scan;
}

TEST(Merge, TwoHalvesOfSyntheticScansAgreeWithTheMapOfAll) {
  std::mt19937 rng(4);
  std::vector<Scan> scans;
  for (int k = 0; k < 20; ++k) {
    const Eigen::Vector3d origin(-3.0 + 0.3 * k, 1.5 * std::sin(0.5 * k), 1.2);
    scans.push_back(roomScan(origin, 4000, rng));
  }
  MapConfig config;
  config.resolution = 0.05;
  for (const ModelRules& rules : {ModelRules{}, ModelRules::paper()}) {
    config.rules = rules;
    const Halves maps = mapsOfHalves(scans, config);
    EXPECT_TRUE(test::mapSatisfiesConstraints(maps.merged));
    std::size_t known = 0;
    const double share =
        agreement(maps.whole, maps.merged, pointsNearHits(scans, 200000, 0.05, 5), known);
    std::printf(
        "[ figure ] room, 20 scans at 0.05 m, %s rules: the halves merged agree with the "
        "whole on %.3f %% of %zu known points (%.0f differ); positive mass %.1f vs %.1f\n",
        rules == ModelRules{} ? "default" : "paper", 100.0 * share, known,
        (1.0 - share) * static_cast<double>(known), positiveMass(maps.merged),
        positiveMass(maps.whole));
    EXPECT_GT(known, 100000u);
    EXPECT_GE(share, 0.99);
  }
}

/// A recording of the shared data (OctoMap scan graphs: /work/shared/data/README.md), at a
/// resolution, with a range limit.
struct Recording {
  const char* file;
  double resolution;
  double max_range;
};

class MergeRecording : public ::testing::TestWithParam<Recording> {};

TEST_P(MergeRecording, TwoHalvesAgreeWithTheMapOfAll) {
  const Recording& recording = GetParam();
  const std::string path = mvog_test::dataDirectory() + "/" + recording.file;
  MVOG_REQUIRE_RECORDING(path);
  const mvog_bench::InputData input = mvog_bench::loadScanGraph(path);
  MapConfig config;
  config.resolution = recording.resolution;
  InsertionConfig insertion;
  insertion.max_range = recording.max_range;
  const Halves maps = mapsOfHalves(input.scans, config, insertion);
  EXPECT_TRUE(test::mapSatisfiesConstraints(maps.merged));
  std::size_t known = 0;
  const double share =
      agreement(maps.whole, maps.merged, pointsNearHits(input.scans, 300000, 0.05, 6), known);
  std::printf(
      "[ figure ] %s at %.2f m: the halves (%zu and %zu scans) merged agree with the "
      "whole on %.3f %% of %zu known points (%.0f differ); positive mass %.1f vs %.1f\n",
      recording.file, recording.resolution, input.scans.size() / 2,
      input.scans.size() - input.scans.size() / 2, 100.0 * share, known,
      (1.0 - share) * static_cast<double>(known), positiveMass(maps.merged),
      positiveMass(maps.whole));
  EXPECT_GT(known, 100000u);
  EXPECT_GE(share, 0.99);
}

INSTANTIATE_TEST_SUITE_P(SharedData, MergeRecording,
                         ::testing::Values(Recording{"tum_fr2_pioneer_slam2_10frames.graph", 0.05,
                                                     8.0},
                                           Recording{"kurt3d_3scans.graph", 0.1, 30.0}));

// ---- Refusals
// -----------------------------------------------------------------------------------------

TEST(GridTransform, AcceptsWhatKeepsTheGrid) {
  const double res = 0.05;
  for (int turns = -4; turns <= 4; ++turns) {
    const GridTransform t =
        GridTransform::fromMatrix(transform(turns * kPi / 2, 0.35, -1.2, 0.123), res);
    EXPECT_EQ(t.quarter_turns, ((turns % 4) + 4) % 4);
    EXPECT_EQ(t.dx_cells, 7);
    EXPECT_EQ(t.dy_cells, -24);
    EXPECT_EQ(t.dz, 0.123);
  }
  // A quaternion's rounding, a translation within 1e-6 of a cell.
  const GridTransform noisy =
      GridTransform::fromMatrix(transform(kPi / 2 + 1e-12, 0.35 + 1e-9, 0.0, 0.0), res);
  EXPECT_EQ(noisy.quarter_turns, 1);
  EXPECT_EQ(noisy.dx_cells, 7);
}

TEST(GridTransform, RefusesWhatWouldNeedResamplingSayingWhy) {
  auto message = [](const Eigen::Matrix4d& m, double res = 0.05) -> std::string {
    try {
      GridTransform::fromMatrix(m, res);
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "accepted";
  };
  Eigen::Matrix4d nan = transform(0, 0, 0, 0);
  nan(1, 3) = kNaN;
  EXPECT_NE(message(nan).find("not finite"), std::string::npos) << message(nan);
  EXPECT_NE(message(transform(0.3, 0, 0, 0)).find("yaw is 17.18"), std::string::npos)
      << message(transform(0.3, 0, 0, 0));
  EXPECT_NE(message(transform(kPi / 4, 0, 0, 0)).find("not a multiple of 90"), std::string::npos);
  EXPECT_NE(message(transform(0, 0.37, 0, 0)).find("not a whole number of cells"),
            std::string::npos)
      << message(transform(0, 0.37, 0, 0));
  EXPECT_NE(message(transform(0, 0, 0.026, 0)).find("y translation"), std::string::npos);
  Eigen::Matrix4d roll = Eigen::Matrix4d::Identity();
  roll(1, 1) = roll(2, 2) = std::cos(0.1);
  roll(2, 1) = std::sin(0.1);
  roll(1, 2) = -std::sin(0.1);
  EXPECT_NE(message(roll).find("roll or pitch"), std::string::npos) << message(roll);
  Eigen::Matrix4d scaled = transform(0, 0, 0, 0);
  scaled(0, 0) = scaled(1, 1) = 2.0;
  EXPECT_NE(message(scaled).find("not a rotation"), std::string::npos);
  Eigen::Matrix4d projective = transform(0, 0, 0, 0);
  projective(3, 0) = 0.5;
  EXPECT_NE(message(projective).find("not rigid"), std::string::npos);
  EXPECT_NE(message(transform(0, 0, 0, 0), kNaN).find("resolution"), std::string::npos);
}

TEST(Merge, RefusesOtherResolutionsMassCountingsAndFarCellsChangingNothing) {
  Map map = test::randomMap(7, 0.2, 5.0);
  const Bytes bytes = serializeMap(map);
  const std::uint64_t revision = map.revision();
  EXPECT_THROW(map.merge(test::randomMap(8, 0.25, 5.0)), ConfigError);
  EXPECT_THROW(map.merge(test::randomMap(8, 0.2, 5.0, 1, ModelRules::paper())), ConfigError);
  const Map other = test::randomMap(9, 0.2, 5.0);
  EXPECT_THROW(map.merge(other, GridTransform{0, 5000, 0, 0.0}), ConfigError);  // beyond 1000 m
  EXPECT_THROW(map.merge(other, GridTransform{0, 0, 0, kNaN}), ConfigError);
  EXPECT_THROW(map.merge(other, GridTransform{0, 0, 0, 1e9}), ConfigError);
  EXPECT_EQ(map.revision(), revision);
  EXPECT_EQ(serializeMap(map), bytes);
}

TEST(Merge, OtherListRulesAreReshapedByThisMapsRules) {
  // The other map's free space was not split at obstacles; this map's is: merged, its lists
  // follow this map's rules, masses summed (the free space's split in proportion).
  ModelRules no_split;
  no_split.split_free_space_at_obstacles = false;
  const Map other = test::randomMap(10, 0.2, 5.0, 4, no_split);
  Map map(MapConfig{0.2, 1000.0, ModelRules{}});
  map.merge(other);
  EXPECT_TRUE(test::mapSatisfiesConstraints(map));
  EXPECT_NEAR(test::totalMass(map), test::totalMass(other), 1e-4 * test::totalMass(other));
  EXPECT_GT(map.memoryUsage().negative_volumes, other.memoryUsage().negative_volumes);
}

// ---- A saved map as the store of dropped tiles
// -----------------------------------------------------

TEST(MergeIntoMapFile, CreatesMergesAndRefusesWithoutTouchingTheFile) {
  char directory[] = "/tmp/mvog_merge_XXXXXX";
  ASSERT_NE(::mkdtemp(directory), nullptr);
  const std::string file = std::string(directory) + "/kept.mvog";
  const Map a = test::randomMap(11, 0.2, 5.0);
  const Map b = test::randomMap(12, 0.2, 5.0);
  mergeIntoMapFile(a, file);
  EXPECT_EQ(serializeMap(loadMap(file)), serializeMap(a));
  mergeIntoMapFile(b, file);
  Map both = copyOf(a);
  both.merge(b);
  const Bytes saved = serializeMap(loadMap(file));
  EXPECT_EQ(saved, serializeMap(both));
  EXPECT_THROW(mergeIntoMapFile(test::randomMap(13, 0.1, 5.0), file), MapFileError);
  EXPECT_EQ(serializeMap(loadMap(file)), saved);
  {
    std::ofstream corrupt(file, std::ios::binary | std::ios::app);
    corrupt << "x";
  }
  EXPECT_THROW(mergeIntoMapFile(a, file), MapFileError);
  std::remove(file.c_str());
  ::rmdir(directory);
}

TEST(GridTransform, RefusesMirrorsShearsAndScalesThatMapTheGridOntoItself) {
  // None of these is rigid (GridTransform::fromMatrix: "not rigid"), though each takes whole
  // cells to whole cells: each must be refused.
  Eigen::Matrix4d swap_xy = Eigen::Matrix4d::Identity();  // a mirror: x <-> y
  swap_xy(0, 0) = swap_xy(1, 1) = 0.0;
  swap_xy(0, 1) = swap_xy(1, 0) = 1.0;
  EXPECT_THROW(GridTransform::fromMatrix(swap_xy, 0.05), ConfigError);
  Eigen::Matrix4d shear = Eigen::Matrix4d::Identity();  // x += y
  shear(0, 1) = 1.0;
  EXPECT_THROW(GridTransform::fromMatrix(shear, 0.05), ConfigError);
  Eigen::Matrix4d flip_z = Eigen::Matrix4d::Identity();  // a mirror: z -> -z
  flip_z(2, 2) = -1.0;
  EXPECT_THROW(GridTransform::fromMatrix(flip_z, 0.05), ConfigError);
  Eigen::Matrix4d stretch_z = Eigen::Matrix4d::Identity();  // z -> 2 z
  stretch_z(2, 2) = 2.0;
  EXPECT_THROW(GridTransform::fromMatrix(stretch_z, 0.05), ConfigError);
}

TEST(Merge, ClosesGapsOfAtMostOneAtDensityOneInBothLists) {
  // Eq. (8): volumes of one list 1 or less apart merge, the gap added at density 1 (8a), the
  // masses summed (8b): in the positive list as in the negative one.
  Map map(test::unitConfig());  // the paper's rules: no split, no clipping
  Map other(test::unitConfig());
  map.setCellVolumes({3, 4}, CellVolumes{{{0.0f, 1.0f, 1.0f}}, {{10.0f, 12.0f, 2.0f}}});
  other.setCellVolumes({3, 4}, CellVolumes{{{1.5f, 2.5f, 1.0f}}, {{12.5f, 14.0f, 3.0f}}});
  map.merge(other);
  const CellVolumes merged = map.cellVolumes({3, 4});
  ASSERT_EQ(merged.positive.size(), 1u);
  EXPECT_TRUE(test::volumeIs(merged.positive[0], 0.0, 2.5, 1.0 + 0.5 + 1.0));
  ASSERT_EQ(merged.negative.size(), 1u);
  EXPECT_TRUE(test::volumeIs(merged.negative[0], 10.0, 14.0, 2.0 + 0.5 + 3.0));
}

TEST(Merge, RefusesACellLandingBeyondMaxCoordinateEvenPastTheInt32Range) {
  // A shift of 2^32 cells takes cell (0, 0) far beyond max_coordinate (GridTransform::target is
  // 64-bit): refused, changing nothing, not wrapped onto a cell of the map.
  Map map(test::unitConfig(100.0));
  map.setCellVolumes({0, 0}, CellVolumes{{{5.0f, 6.0f, 1.0f}}, {}});
  Map other(test::unitConfig(100.0));
  other.setCellVolumes({0, 0}, CellVolumes{{{0.0f, 1.0f, 1.0f}}, {}});
  const Bytes bytes = serializeMap(map);
  for (const std::int64_t shift : {std::int64_t{1} << 32, -(std::int64_t{1} << 32)}) {
    EXPECT_THROW(map.merge(other, GridTransform{0, shift, 0, 0.0}), ConfigError) << shift;
    EXPECT_THROW(map.merge(other, GridTransform{0, 0, shift, 0.0}), ConfigError) << shift;
  }
  EXPECT_EQ(serializeMap(map), bytes);
}

}  // namespace
}  // namespace mvog
