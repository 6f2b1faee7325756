// Helpers shared by the core's tests: building maps, reading every volume of a map, and checking
// the Sec. III-A constraints independently of mvog::checkVolumeList.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <sstream>
#include <tuple>
#include <vector>

#include "mvog/map.h"
#include "mvog/volume.h"

namespace mvog {
namespace test {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr float kFloatNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kFloatInf = std::numeric_limits<float>::infinity();

// ---- The byte formats (map files, map updates), written independently of the core ----------

/// FNV-1a, 64 bits: the checksum that ends a map file and a map update.
inline std::uint64_t fnv1a64(const std::uint8_t* data, std::size_t size) {
  std::uint64_t hash = 0xcbf29ce484222325ull;
  for (std::size_t k = 0; k < size; ++k) hash = (hash ^ data[k]) * 0x100000001b3ull;
  return hash;
}

/// Writes the `size` low bytes of `value` at `offset`, little-endian.
inline void putLe(std::vector<std::uint8_t>& bytes, std::size_t offset, std::uint64_t value,
                  int size) {
  for (int k = 0; k < size; ++k) bytes[offset + k] = static_cast<std::uint8_t>(value >> (8 * k));
}

/// Rewrites the checksum (the last 8 bytes) to match the bytes before it.
inline void fixChecksum(std::vector<std::uint8_t>& bytes) {
  putLe(bytes, bytes.size() - 8, fnv1a64(bytes.data(), bytes.size() - 8), 8);
}

/// A map at resolution 1 (s = 1): grid units are metres, as in the paper's Fig. 3; by default
/// with the paper's exact model.
inline MapConfig unitConfig(double max_coordinate = 10000.0,
                            const ModelRules& rules = ModelRules::paper()) {
  MapConfig config;
  config.resolution = 1.0;
  config.max_coordinate = max_coordinate;
  config.rules = rules;
  return config;
}

/// The state eq. (9) gives at `point` with the default threshold.
inline OccupancyState stateAt(const Map& map, const Eigen::Vector3d& point) {
  return map.occupancy(point).state(kDefaultOccupancyThreshold);
}

/// What a map says of a scan's hits: how many it calls occupied, how many of those `marked(k)`
/// picks (hit k: a thin object's, say) there are and how many of them it calls occupied, and at
/// how many rays' midpoints it calls free.
struct HitStates {
  std::size_t occupied = 0;
  std::size_t marked = 0;
  std::size_t marked_occupied = 0;
  std::size_t free_midpoints = 0;
};

template <class Marked>
HitStates hitStates(const Map& map, const Scan& scan, const Marked& marked) {
  HitStates states;
  for (std::size_t k = 0; k < scan.hits.size(); ++k) {
    const Eigen::Vector3d hit = scan.hits[k].cast<double>();
    const bool occupied = stateAt(map, hit) == OccupancyState::kOccupied;
    states.occupied += occupied;
    states.marked += marked(k);
    states.marked_occupied += marked(k) && occupied;
    states.free_midpoints += stateAt(map, 0.5 * (scan.origin + hit)) == OccupancyState::kFree;
  }
  return states;
}

/// Tolerance for heights and masses computed by hand in double from numbers stored as floats.
constexpr double kTolerance = 1e-5;

/// `v` spans [bottom, top] with mass `mass`, up to kTolerance.
inline ::testing::AssertionResult volumeIs(const Volume& v, double bottom, double top,
                                           double mass) {
  if (std::fabs(v.bottom - bottom) <= kTolerance && std::fabs(v.top - top) <= kTolerance &&
      std::fabs(v.mass - mass) <= kTolerance) {
    return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure()
         << "volume [" << v.bottom << ", " << v.top << "] mass " << v.mass << ", expected ["
         << bottom << ", " << top << "] mass " << mass;
}

/// One volume of a map: cell x, cell y, sign, bottom, top, mass. Compared with ==, i.e. exactly.
using VolumeRecord = std::tuple<std::int32_t, std::int32_t, int, float, float, float>;

/// Every volume of `map`, in forEachVolume's order.
inline std::vector<VolumeRecord> allVolumes(const Map& map) {
  std::vector<VolumeRecord> records;
  map.forEachVolume([&](const CellIndex& cell, VolumeSign sign, const Volume& v) {
    records.emplace_back(cell.x, cell.y, static_cast<int>(sign), v.bottom, v.top, v.mass);
  });
  return records;
}

/// Two lists of volume records are equal; otherwise says how many differ, and the first.
inline ::testing::AssertionResult sameVolumes(const std::vector<VolumeRecord>& a,
                                              const std::vector<VolumeRecord>& b) {
  const std::size_t common = std::min(a.size(), b.size());
  std::size_t differences = std::max(a.size(), b.size()) - common;
  std::size_t first = common;
  for (std::size_t k = 0; k < common; ++k) {
    if (a[k] == b[k]) continue;
    ++differences;
    first = std::min(first, k);
  }
  if (differences == 0) return ::testing::AssertionSuccess();
  auto failure = ::testing::AssertionFailure();
  failure << a.size() << " and " << b.size() << " volumes, " << differences << " differ";
  if (first < common) {
    failure << ", the first: " << ::testing::PrintToString(a[first]) << " vs "
            << ::testing::PrintToString(b[first]);
  }
  return failure;
}

/// Sum of every volume's mass.
inline double totalMass(const Map& map) {
  double total = 0.0;
  map.forEachVolume([&](const CellIndex&, VolumeSign, const Volume& v) { total += v.mass; });
  return total;
}

/// The cells holding at least one volume.
inline std::vector<CellIndex> observedCells(const Map& map) {
  std::vector<CellIndex> cells;
  map.forEachVolume([&](const CellIndex& cell, VolumeSign, const Volume&) {
    if (cells.empty() || cells.back() != cell) cells.push_back(cell);
  });
  return cells;
}

/// Sec. III-A written out again, without mvog::checkColumn: sorted, heights >= 1, no overlap,
/// gaps > 1 (in float, as the map computes them), finite non-negative masses. Two volumes may
/// touch where one of `boundaries` begins or ends (ModelRules::split_free_space_at_obstacles:
/// negative volumes cut at the positive ones).
inline ::testing::AssertionResult satisfiesConstraints(const std::vector<Volume>& list,
                                                       const std::vector<Volume>& boundaries = {}) {
  for (std::size_t k = 0; k < list.size(); ++k) {
    const Volume& v = list[k];
    std::ostringstream where;
    where << "volume " << k << " [" << v.bottom << ", " << v.top << "] mass " << v.mass << ": ";
    if (!std::isfinite(v.bottom) || !std::isfinite(v.top) || !(v.top - v.bottom >= 1.0f)) {
      return ::testing::AssertionFailure() << where.str() << "height below 1";
    }
    if (!std::isfinite(v.mass) || v.mass < 0.0f) {
      return ::testing::AssertionFailure() << where.str() << "mass not finite and >= 0";
    }
    if (k > 0) {
      const Volume& below = list[k - 1];
      const bool at_a_boundary =
          below.top == v.bottom &&
          std::any_of(boundaries.begin(), boundaries.end(),
                      [&](const Volume& b) { return b.bottom == v.bottom || b.top == v.bottom; });
      if (at_a_boundary) continue;
      if (!(below.bottom < v.bottom) || !(below.top < v.bottom)) {
        return ::testing::AssertionFailure() << where.str() << "unsorted or overlapping";
      }
      if (!(v.bottom - below.top > 1.0f)) {
        return ::testing::AssertionFailure() << where.str() << "gap to the one below is <= 1";
      }
    }
  }
  return ::testing::AssertionSuccess();
}

/// Both the independent check and mvog::checkColumn hold for every column of `map`.
inline ::testing::AssertionResult mapSatisfiesConstraints(const Map& map) {
  const bool split = map.config().rules.split_free_space_at_obstacles;
  for (const CellIndex& cell : observedCells(map)) {
    const CellVolumes volumes = map.cellVolumes(cell);
    for (const std::vector<Volume>* list : {&volumes.positive, &volumes.negative}) {
      const char* name = list == &volumes.positive ? "positive" : "negative";
      const bool may_touch = split && list == &volumes.negative;
      const ::testing::AssertionResult own =
          satisfiesConstraints(*list, may_touch ? volumes.positive : std::vector<Volume>{});
      if (!own) {
        return ::testing::AssertionFailure()
               << "cell (" << cell.x << ", " << cell.y << ") " << name << ": " << own.message();
      }
    }
    const std::string problem =
        checkColumn(volumes.positive.data(), volumes.positive.size(), volumes.negative.data(),
                    volumes.negative.size(), split);
    if (!problem.empty()) {
      return ::testing::AssertionFailure()
             << "cell (" << cell.x << ", " << cell.y << "): checkColumn: " << problem;
    }
  }
  return ::testing::AssertionSuccess();
}

/// Marks an unknown probability in probabilityBits (no probability has this NaN pattern).
constexpr std::uint32_t kUnknownBits = 0xffffffffu;

/// The probability at the points of a lattice over [-half_extent, half_extent]^2 x
/// [-half_height, half_height] (m) as float bits, kUnknownBits where unknown: equal vectors mean
/// bit-for-bit equal probabilities everywhere on the lattice.
inline std::vector<std::uint32_t> probabilityBits(const Map& map, double half_extent,
                                                  double half_height) {
  std::vector<std::uint32_t> bits;
  for (double x = -half_extent; x <= half_extent; x += 0.13) {
    for (double y = -half_extent; y <= half_extent; y += 0.17) {
      for (double z = -half_height; z <= half_height; z += 0.11) {
        const PointOccupancy p = map.occupancy({x, y, z});
        std::uint32_t b = kUnknownBits;
        if (p.known()) std::memcpy(&b, &*p.probability, sizeof b);
        bits.push_back(b);
      }
    }
  }
  return bits;
}

/// Two probabilityBits vectors are equal; otherwise says how many points differ, and the first.
inline ::testing::AssertionResult sameProbabilities(const std::vector<std::uint32_t>& a,
                                                    const std::vector<std::uint32_t>& b) {
  if (a.size() != b.size()) return ::testing::AssertionFailure() << "different lattices";
  std::size_t differences = 0;
  std::size_t first = a.size();
  for (std::size_t k = 0; k < a.size(); ++k) {
    if (a[k] == b[k]) continue;
    ++differences;
    first = std::min(first, k);
  }
  if (differences == 0) return ::testing::AssertionSuccess();
  float p_a;
  float p_b;
  std::memcpy(&p_a, &a[first], sizeof p_a);
  std::memcpy(&p_b, &b[first], sizeof p_b);
  return ::testing::AssertionFailure()
         << differences << " of " << a.size() << " probabilities differ, the first " << p_a
         << " vs " << p_b << " (NaN: unknown)";
}

/// A point uniformly in [-half_extent, half_extent]^2 x [-half_height, half_height].
inline Eigen::Vector3d randomPoint(std::mt19937& rng, double half_extent, double half_height) {
  std::uniform_real_distribution<double> horizontal(-half_extent, half_extent);
  std::uniform_real_distribution<double> vertical(-half_height, half_height);
  const double x = horizontal(rng);
  const double y = horizontal(rng);
  return {x, y, vertical(rng)};
}

/// A scan from `origin` with `num_hits` obstacle readings and `num_free` out-of-range readings at
/// random points within half_extent (m) of the origin horizontally, and z in [-3, 3] (m).
inline Scan randomScan(std::mt19937& rng, const Eigen::Vector3d& origin, std::size_t num_hits,
                       std::size_t num_free, double half_extent) {
  Scan scan;
  scan.origin = origin;
  const auto point = [&] {
    const Eigen::Vector3d p =
        randomPoint(rng, half_extent, 3.0) + Eigen::Vector3d(origin.x(), origin.y(), 0.0);
    return p.cast<float>().eval();
  };
  for (std::size_t k = 0; k < num_hits; ++k) scan.hits.push_back(point());
  for (std::size_t k = 0; k < num_free; ++k) scan.out_of_range.push_back(point());
  return scan;
}

/// A map built from `num_scans` random scans from near the origin, each of 1200 hits and 400
/// out-of-range readings within half_extent (m).
inline Map randomMap(unsigned seed, double resolution, double half_extent, int num_scans = 3,
                     const ModelRules& rules = {}) {
  MapConfig config;
  config.resolution = resolution;
  config.max_coordinate = 1000.0;
  config.rules = rules;
  Map map(config);
  std::mt19937 rng(seed);
  for (int k = 0; k < num_scans; ++k) {
    map.insertScan(randomScan(rng, randomPoint(rng, 1.0, 0.5), 1200, 400, half_extent));
  }
  return map;
}

/// The random map of the tests of whole maps: resolution 0.2 m, readings within about 6 m.
inline Map coarseRandomMap(unsigned seed, int num_scans = 3) {
  return randomMap(seed, 0.2, 5.0, num_scans);
}

}  // namespace test
}  // namespace mvog
