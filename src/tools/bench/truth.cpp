#include "truth.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <stdexcept>

#include <Eigen/Geometry>

namespace mvog_bench {
namespace {

constexpr std::size_t kLabelledRays = 30000;  ///< rays sampled evenly over the input
constexpr int kUniformPointsPerRay = 5;       ///< free candidates uniformly along each
constexpr int kOverhangPointsPerRay = 2;      ///< on each ray's stretch under an overhang
constexpr double kInsideSurface = 0.001;      ///< m beyond the exact hit
constexpr double kUnobservedMargin = 1.0;     ///< m around the rays' bounding box
constexpr std::size_t kUnobservedPoints = 10000;
constexpr std::size_t kUnobservedCandidates = 400000;

/// The space at most kOverhangDepth under `overhang`, within its footprint.
mvog_scene::Box zoneUnder(const mvog_scene::Box& overhang) {
  mvog_scene::Box zone = overhang;
  zone.max.z() = overhang.min.z();
  zone.min.z() = overhang.min.z() - kOverhangDepth;
  return zone;
}

bool inside(const mvog_scene::Box& box, const Eigen::Vector3d& p) {
  return (p.array() >= box.min.array()).all() && (p.array() < box.max.array()).all();
}

bool underAnOverhang(const TruthScene& truth, const Eigen::Vector3d& p) {
  return std::any_of(
      truth.overhangs.begin(), truth.overhangs.end(),
      [&](const mvog_scene::Box& overhang) { return inside(zoneUnder(overhang), p); });
}

/// Random points more than kCoverageReach voxels of `coverage` from every ray: half in the
/// rays' bounding box grown by kUnobservedMargin, half inside the scene's finite boxes (closed
/// furniture, buildings, walls).
std::vector<Eigen::Vector3d> unobservedPoints(const TruthScene& truth, const InputData& input,
                                              const RayCoverage& coverage) {
  Eigen::AlignedBox3d box;
  for (const mvog::Scan& scan : input.scans) {
    box.extend(scan.origin);
    for (const Eigen::Vector3f& hit : scan.hits) box.extend(hit.cast<double>());
  }
  box.min().array() -= kUnobservedMargin;
  box.max().array() += kUnobservedMargin;
  std::vector<mvog_scene::Box> solids;
  for (const mvog_scene::Box& solid : truth.scene.boxes) {
    const mvog_scene::Box clipped{solid.min.cwiseMax(box.min()), solid.max.cwiseMin(box.max())};
    if ((clipped.min.array() < clipped.max.array()).all()) solids.push_back(clipped);
  }
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto within = [&](const Eigen::Vector3d& low, const Eigen::Vector3d& high) {
    return Eigen::Vector3d(low.x() + unit(rng) * (high.x() - low.x()),
                           low.y() + unit(rng) * (high.y() - low.y()),
                           low.z() + unit(rng) * (high.z() - low.z()));
  };
  std::vector<Eigen::Vector3d> points;
  for (std::size_t k = 0; k < kUnobservedCandidates && points.size() < kUnobservedPoints; ++k) {
    Eigen::Vector3d p;
    if (k % 2 == 0 || solids.empty()) {
      p = within(box.min(), box.max());
    } else {
      const mvog_scene::Box& solid = solids[rng() % solids.size()];
      p = within(solid.min, solid.max);
    }
    if (!coverage.near(p, kCoverageReach)) points.push_back(p);
  }
  return points;
}

}  // namespace

TruthLabels labelPoints(const TruthScene& truth, const InputData& input,
                        const RayCoverage& coverage, double resolution) {
  TruthLabels labels;
  const double free_margin = kFreeMarginCells * resolution;
  const double near_surface = kNearSurfaceCells * resolution;
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto addFree = [&](const Eigen::Vector3d& p) {
    const double distance = truth.scene.distance(p);
    if (distance <= free_margin) return;
    if (underAnOverhang(truth, p)) {
      labels.free_under_overhang.push_back(p);
    } else {
      (distance <= near_surface ? labels.free_near_surface : labels.free_far_from_surfaces)
          .push_back(p);
    }
  };
  const std::size_t stride =
      std::max<std::size_t>(1, (input.readings() + kLabelledRays - 1) / kLabelledRays);
  std::size_t index = 0;
  for (const mvog::Scan& scan : input.scans) {
    for (const Eigen::Vector3f& hit : scan.hits) {
      if (index++ % stride != 0) continue;
      // A noisy hit lies on its exact ray (mvog_scene::DepthCamera): the scene says where
      // that ray really meets a surface.
      const Eigen::Vector3d direction = (hit.cast<double>() - scan.origin).normalized();
      const double range = truth.scene.castRay(scan.origin, direction);
      if (!std::isfinite(range)) continue;
      const Eigen::Vector3d surface = scan.origin + (range + kInsideSurface) * direction;
      if (truth.scene.distance(surface) < 0.0) {  // else a ray grazing an edge: no label
        labels.surface.push_back(surface);
        if (truth.thin_objects.distance(surface) < 0.0) labels.thin.push_back(surface);
      }
      for (int k = 0; k < kUniformPointsPerRay; ++k) {
        addFree(scan.origin + unit(rng) * range * direction);
      }
      for (double cells : {2.0, 3.0, 4.0}) {
        if (cells * resolution < range) {
          addFree(scan.origin + (range - cells * resolution) * direction);
        }
      }
      for (const mvog_scene::Box& overhang : truth.overhangs) {
        double t_near = 0.0;
        double t_far = 0.0;
        if (!mvog_scene::rayThroughBox(zoneUnder(overhang), scan.origin, direction, t_near,
                                       t_far)) {
          continue;
        }
        t_far = std::min(t_far, range);
        for (int k = 0; k < kOverhangPointsPerRay && t_near < t_far; ++k) {
          addFree(scan.origin + (t_near + unit(rng) * (t_far - t_near)) * direction);
        }
      }
    }
  }
  labels.unobserved = unobservedPoints(truth, input, coverage);
  return labels;
}

double TruthScores::share(const StateCounts& counts, mvog::OccupancyState state) {
  return counts.percent(state) / 100.0;
}

double TruthScores::occupancyF1() const {
  const auto occupied = static_cast<std::size_t>(mvog::OccupancyState::kOccupied);
  const double hits = static_cast<double>(surface.counts[occupied]);
  const double misses = static_cast<double>(surface.points()) - hits;
  const double false_alarms = static_cast<double>(free_near_surface.counts[occupied] +
                                                  free_far_from_surfaces.counts[occupied] +
                                                  free_under_overhang.counts[occupied]);
  const double denominator = 2.0 * hits + misses + false_alarms;
  return denominator > 0.0 ? 2.0 * hits / denominator : std::nan("");
}

mvog::OccupancyState oracleState(const TruthScene& truth, const RayCoverage& coverage,
                                 const Eigen::Vector3d& point) {
  if (!coverage.near(point, kCoverageReach)) return mvog::OccupancyState::kUnknown;
  return truth.scene.distance(point) <= 0.0 ? mvog::OccupancyState::kOccupied
                                            : mvog::OccupancyState::kFree;
}

EndpointsMap::EndpointsMap(const InputData& input, double max_range, double resolution)
    : resolution_(resolution) {
  for (const mvog::Scan& scan : input.scans) {
    for (const Eigen::Vector3f& hit : scan.hits) {
      if ((hit.cast<double>() - scan.origin).norm() > max_range) continue;  // free space only
      voxels_.insert(voxelKey((hit.cast<double>() / resolution).array().floor().cast<int>()));
    }
  }
}

mvog::OccupancyState EndpointsMap::state(const Eigen::Vector3d& point) const {
  return voxels_.count(voxelKey((point / resolution_).array().floor().cast<int>())) != 0
             ? mvog::OccupancyState::kOccupied
             : mvog::OccupancyState::kUnknown;
}

namespace {

/// Pixels per panel of a slice.
Eigen::Vector2i sliceSize(const SlicePlane& plane) {
  return {static_cast<int>(std::lround(plane.across.norm() / plane.pixel_size)),
          static_cast<int>(std::lround(plane.down.norm() / plane.pixel_size))};
}

Eigen::Vector3d slicePoint(const SlicePlane& plane, const Eigen::Vector2i& size, int column,
                           int row) {
  return plane.corner + plane.across * ((column + 0.5) / size.x()) +
         plane.down * ((row + 0.5) / size.y());
}

constexpr int kPanelGap = 4;  ///< pixels of mid grey between panels

}  // namespace

SlicePanel slicePanel(const SlicePlane& plane, double resolution,
                      const std::function<mvog::OccupancyState(const Eigen::Vector3d&)>& state_of) {
  const Eigen::Vector2i size = sliceSize(plane);
  SlicePanel panel;
  panel.resolution = resolution;
  panel.states.reserve(static_cast<std::size_t>(size.x()) * static_cast<std::size_t>(size.y()));
  for (int row = 0; row < size.y(); ++row) {
    for (int column = 0; column < size.x(); ++column) {
      panel.states.push_back(state_of(slicePoint(plane, size, column, row)));
    }
  }
  return panel;
}

void writeTruthSlice(const TruthScene& truth, const RayCoverage& coverage,
                     const std::vector<SlicePanel>& panels, const std::string& path) {
  using RGB = std::array<unsigned char, 3>;
  constexpr RGB kBlack{0, 0, 0}, kWhite{255, 255, 255}, kRed{230, 30, 30}, kBlue{40, 90, 240},
      kYellow{250, 210, 40}, kDarkGrey{90, 90, 90}, kLightGrey{200, 200, 200};
  const Eigen::Vector2i size = sliceSize(truth.slice);
  std::vector<double> distances;  // to the nearest obstacle, at each pixel
  std::vector<bool> reached;      // a ray crossed the pixel's voxel of the coverage
  for (int row = 0; row < size.y(); ++row) {
    for (int column = 0; column < size.x(); ++column) {
      const Eigen::Vector3d p = slicePoint(truth.slice, size, column, row);
      distances.push_back(truth.scene.distance(p));
      reached.push_back(coverage.near(p, 0));
    }
  }
  const int height = static_cast<int>(panels.size()) * (size.y() + kPanelGap) - kPanelGap;
  std::string pixels;
  pixels.reserve(static_cast<std::size_t>(size.x()) * static_cast<std::size_t>(height) * 3);
  for (std::size_t panel = 0; panel < panels.size(); ++panel) {
    if (panel > 0) pixels.append(static_cast<std::size_t>(size.x()) * kPanelGap * 3, '\x80');
    const double margin = kFreeMarginCells * panels[panel].resolution;
    for (std::size_t k = 0; k < distances.size(); ++k) {
      const bool obstacle = distances[k] <= 0.0;
      RGB rgb = kLightGrey;
      switch (panels[panel].states[k]) {
        case mvog::OccupancyState::kOccupied:
          rgb = distances[k] <= margin ? kBlack : kRed;
          break;
        case mvog::OccupancyState::kFree:
          rgb = obstacle ? kBlue : kWhite;
          break;
        default:
          rgb = obstacle ? kDarkGrey : reached[k] ? kYellow : kLightGrey;
      }
      pixels.append(reinterpret_cast<const char*>(rgb.data()), rgb.size());
    }
  }
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  file << "P6\n" << size.x() << " " << height << "\n255\n" << pixels;
  file.close();
  if (!file) throw std::runtime_error(path + ": cannot write the slice");
}

}  // namespace mvog_bench
