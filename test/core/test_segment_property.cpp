// Property tests of the segment checks (mvog/checks.h): exact answers against dense sampling.
//
// Radius 0, against Map::occupancy sampled along the segment every 1/10 of the resolution, on
// random maps and on a real recording (kurt3d_3scans.graph in $MVOG_DATA_DIR). Sampling cannot see
// everything the exact check sees: where the segment crosses a column's stretch over less than a
// step (a cell's corner, a thin stretch crossed steeply) it may step over it. How the test tells:
// a disagreement counts as such a thin miss only if sampling at 1/1000 of the step finds what the
// exact check found (an occupied point for the state; a point that is not free within one step
// after blocked_at for the distance), and thin misses stay rare. A sample whose state changes when
// its height moves by 1e-4 of a cell lies on a stretch's face within float rounding and proves
// nothing either way.
//
// Radius > 0, against a reference that samples the distance from the segment to each occupied and
// unknown stretch of each cell (a box): that distance changes by at most the step between two
// samples, so it bounds both ways what the exact check may say, without exceptions.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "../recordings.h"
#include "input.h"  // mvog_bench's scan graph reader (src/tools/bench), ROS-free
#include "mvog/checks.h"
#include "mvog/column.h"
#include "planning_scene.h"
#include "test_util.h"

namespace mvog {
namespace {

using test::kInf;

/// The state at `point` if it stays the same when the point moves up or down by 1e-4 of a cell.
std::optional<OccupancyState> robustStateAt(const Map& map, const Eigen::Vector3d& point) {
  const Eigen::Vector3d nudge(0.0, 0.0, 1e-4 * map.resolution());
  const OccupancyState state = test::stateAt(map, point);
  if (test::stateAt(map, point + nudge) != state || test::stateAt(map, point - nudge) != state) {
    return std::nullopt;
  }
  return state;
}

/// What sampling a segment every `step` metres found.
struct Sampled {
  double first_blocked = kInf;  ///< distance of the first sample that is occupied or unknown
  bool occupied = false;
};

Sampled sample(const Map& map, const Segment& segment, double step, double from, double to,
               bool robust) {
  const double length = (segment.end - segment.start).norm();
  Sampled result;
  for (double s = from;; s += step) {
    const double at = std::min(s, to);
    const Eigen::Vector3d point =
        length > 0.0
            ? Eigen::Vector3d(segment.start + (segment.end - segment.start) * (at / length))
            : segment.start;
    std::optional<OccupancyState> state =
        robust ? robustStateAt(map, point) : test::stateAt(map, point);
    if (state && *state != OccupancyState::kFree) {
      result.first_blocked = std::min(result.first_blocked, at);
      result.occupied |= *state == OccupancyState::kOccupied;
    }
    if (at >= to) return result;
  }
}

/// Checks `segments` with radius 0 against sampling; returns the number of thin misses.
std::size_t compareWithSampling(const Map& map, const std::vector<Segment>& segments) {
  const std::vector<SegmentCheck> checks = checkSegments(map, segments, 0.0);
  const double step = map.resolution() / 10.0;
  const double fine = step / 1000.0;
  const double tolerance = 1e-6 * map.resolution();
  std::size_t thin_misses = 0;
  for (std::size_t k = 0; k < segments.size(); ++k) {
    const Segment& segment = segments[k];
    const SegmentCheck& check = checks[k];
    const double length = (segment.end - segment.start).norm();
    SCOPED_TRACE("segment " + std::to_string(k) + " from " +
                 ::testing::PrintToString(segment.start.transpose()) + " to " +
                 ::testing::PrintToString(segment.end.transpose()));
    const Sampled coarse = sample(map, segment, step, 0.0, length, true);
    // What sampling found, the exact check finds, at the same distance or before.
    if (coarse.occupied) {
      EXPECT_EQ(check.state, OccupancyState::kOccupied);
    }
    if (coarse.first_blocked < kInf) {
      EXPECT_NE(check.state, OccupancyState::kFree);
      EXPECT_LE(check.blocked_at, coarse.first_blocked + tolerance);
    }
    if (check.state == OccupancyState::kFree) continue;
    // What the exact check found beyond sampling is a thin miss.
    bool thin = false;
    if (check.state == OccupancyState::kOccupied && !coarse.occupied) {
      EXPECT_TRUE(sample(map, segment, fine, 0.0, length, false).occupied)
          << "occupied, sampling finds no occupied point";
      thin = true;
    }
    if (check.blocked_at < coarse.first_blocked - step) {
      const double to = std::min(length, check.blocked_at + step);
      EXPECT_NEAR(sample(map, segment, fine, check.blocked_at, to, false).first_blocked,
                  check.blocked_at, 2 * fine)
          << "blocked at " << check.blocked_at << ", sampling from " << coarse.first_blocked;
      thin = true;
    }
    thin_misses += thin;
  }
  return thin_misses;
}

std::vector<Segment> randomSegments(std::mt19937& rng, std::size_t count,
                                    const std::vector<Eigen::Vector3d>& near, double spread,
                                    double max_length) {
  std::uniform_int_distribution<std::size_t> which(0, near.size() - 1);
  std::uniform_real_distribution<double> offset(-spread, spread);
  std::uniform_real_distribution<double> length(0.0, max_length);
  std::normal_distribution<double> direction;
  std::vector<Segment> segments;
  for (std::size_t k = 0; k < count; ++k) {
    const Eigen::Vector3d start =
        near[which(rng)] + Eigen::Vector3d(offset(rng), offset(rng), offset(rng) / 2.0);
    Eigen::Vector3d d(direction(rng), direction(rng), direction(rng));
    // Some horizontal segments, which stay at one height over many columns.
    if (k % 5 == 0) d.z() = 0.0;
    segments.push_back({start, start + length(rng) * d.normalized()});
  }
  return segments;
}

TEST(SegmentProperty, AgreesWithSamplingOnRandomMaps) {
  std::mt19937 rng(17);
  std::size_t thin_misses = 0;
  std::size_t total = 0;
  for (unsigned seed : {1u, 2u}) {
    const Map map = test::randomMap(seed, 0.1, 3.0, 4);
    const std::vector<Segment> segments = randomSegments(rng, 1500, {{0, 0, 0}}, 3.0, 3.0);
    thin_misses += compareWithSampling(map, segments);
    total += segments.size();
  }
  EXPECT_LT(thin_misses, total / 20) << thin_misses << " thin misses";
}

TEST(SegmentProperty, AgreesWithSamplingInAScannedRoom) {
  const Map map = test::scannedRoomMap();
  std::mt19937 rng(23);
  const std::vector<Segment> segments = randomSegments(rng, 2000, {{0, 0, 1.2}}, 3.0, 4.0);
  const std::size_t thin_misses = compareWithSampling(map, segments);
  EXPECT_LT(thin_misses, segments.size() / 20) << thin_misses << " thin misses";
}

TEST(SegmentProperty, AgreesWithSamplingOnARecording) {
  const std::string path = mvog_test::dataDirectory() + "/kurt3d_3scans.graph";
  MVOG_REQUIRE_RECORDING(path);
  const mvog_bench::InputData input = mvog_bench::loadScanGraph(path);
  MapConfig config;
  config.resolution = 0.1;
  Map map(config);
  std::vector<Eigen::Vector3d> origins;
  for (const Scan& scan : input.scans) {
    map.insertScan(scan);
    origins.push_back(scan.origin);
  }
  std::mt19937 rng(3);
  const std::vector<Segment> segments = randomSegments(rng, 2000, origins, 4.0, 5.0);
  const std::size_t thin_misses = compareWithSampling(map, segments);
  EXPECT_LT(thin_misses, segments.size() / 20) << thin_misses << " thin misses";
}

// ---- Radius > 0
// --------------------------------------------------------------------------

/// Distance (grid units) from `point` to the box over `cell` spanning heights [bottom, top].
double distanceToStretch(const Eigen::Vector3d& point, const CellIndex& cell, double bottom,
                         double top) {
  auto gap = [](double v, double low, double high) { return std::max({low - v, 0.0, v - high}); };
  return std::hypot(gap(point.x(), cell.x, cell.x + 1.0), gap(point.y(), cell.y, cell.y + 1.0),
                    gap(point.z(), bottom, top));
}

/// What sampling the distance to the stretches found, for one kind of stretch: the first t at
/// which a sample lies within `reach` of one.
struct Reference {
  double first_within_radius = kInf;  // t
  double first_within_slack = kInf;   // t, radius + half a step
};

/// Checks `segments` with random radii against sampled distances to the stretches.
void compareWithDistances(const Map& map, const std::vector<Segment>& segments, std::mt19937& rng) {
  std::uniform_real_distribution<double> radius_of(0.02, 0.5);
  const double s = 1.0 / map.resolution();
  for (std::size_t k = 0; k < segments.size(); ++k) {
    const double radius = radius_of(rng);
    const SegmentCheck check = checkSegments(map, {segments[k]}, radius).at(0);
    const Eigen::Vector3d a = segments[k].start * s;
    const Eigen::Vector3d b = segments[k].end * s;
    const double length = (b - a).norm();
    const double r = radius * s;
    const double step = 0.1;  // grid units: 1/10 of the resolution
    const int samples = static_cast<int>(std::ceil(length / step)) + 1;
    std::vector<Eigen::Vector3d> points;
    for (int j = 0; j < samples; ++j) {
      points.push_back(a + (b - a) * (samples > 1 ? double(j) / (samples - 1) : 0.0));
    }
    const double t_step = length > 0.0 ? 1.0 / (samples - 1) : 1.0;
    const double slack = 0.5 * step + 1e-9;
    Reference occupied;
    Reference unknown;
    const CellIndex low = cellAt(std::min(a.x(), b.x()) - r - 1, std::min(a.y(), b.y()) - r - 1);
    const CellIndex high = cellAt(std::max(a.x(), b.x()) + r + 1, std::max(a.y(), b.y()) + r + 1);
    for (std::int32_t y = low.y; y <= high.y; ++y) {
      for (std::int32_t x = low.x; x <= high.x; ++x) {
        // The occupied stretches and the unknown gaps around the known ones.
        std::vector<std::tuple<double, double, bool>> stretches;  // bottom, top, occupied
        double known_to = -kInf;
        for (const ColumnSegment& c : columnProfile(map.cellVolumes({x, y}))) {
          if (c.bottom > known_to) stretches.emplace_back(known_to, c.bottom, false);
          if (c.probability > kDefaultOccupancyThreshold) {
            stretches.emplace_back(c.bottom, c.top, true);
          }
          known_to = c.top;
        }
        stretches.emplace_back(known_to, kInf, false);
        for (const auto& [bottom, top, is_occupied] : stretches) {
          Reference& reference = is_occupied ? occupied : unknown;
          for (int j = 0; j < samples; ++j) {
            const double d = distanceToStretch(points[j], {x, y}, bottom, top);
            const double t = j * t_step;
            if (d <= r) reference.first_within_radius = std::min(reference.first_within_radius, t);
            if (d <= r + slack) {
              reference.first_within_slack = std::min(reference.first_within_slack, t);
            }
          }
        }
      }
    }
    SCOPED_TRACE("segment " + std::to_string(k) + " radius " + std::to_string(radius));
    const double blocked_t = std::min(occupied.first_within_radius, unknown.first_within_radius);
    const double near_t = std::min(occupied.first_within_slack, unknown.first_within_slack);
    // The state: certain where sampling found it, possible only within the slack.
    if (occupied.first_within_radius < kInf) {
      EXPECT_EQ(check.state, OccupancyState::kOccupied);
    } else if (occupied.first_within_slack == kInf) {
      EXPECT_NE(check.state, OccupancyState::kOccupied);
    }
    if (blocked_t < kInf) {
      EXPECT_NE(check.state, OccupancyState::kFree);
    }
    if (near_t == kInf) {
      EXPECT_EQ(check.state, OccupancyState::kFree);
    }
    if (check.state == OccupancyState::kFree) continue;
    // The distance: no later than where sampling met a stretch, no earlier than a step before
    // the first sample within the slack.
    const double metres_per_t = length * map.resolution();
    if (blocked_t < kInf) {
      EXPECT_LE(check.blocked_at, blocked_t * metres_per_t + 1e-9);
    }
    EXPECT_GE(check.blocked_at, near_t * metres_per_t - 0.5 * step * map.resolution() - 1e-9);
  }
}

TEST(SegmentProperty, WithARadiusAgreesWithSampledDistances) {
  std::mt19937 rng(29);
  compareWithDistances(test::randomMap(7, 0.1, 3.0, 4),
                       randomSegments(rng, 200, {{0, 0, 0}}, 3.0, 1.5), rng);
  compareWithDistances(test::scannedRoomMap(), randomSegments(rng, 300, {{0, 0, 1.2}}, 2.5, 1.5),
                       rng);
}

}  // namespace
}  // namespace mvog
