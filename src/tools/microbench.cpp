// Google Benchmark micro-benchmarks of the MVOG core (no ROS): one reading, one ~25k-point depth
// scan, 100k point queries, a 20 m x 20 m cross-section, a decay step, forgetting, save and load,
// 10,000 segment checks (in the room, and all free in the floor below), frontiers and surfaces
// over 40 m x 40 m.
// The scene is a 10 m x 8 m x 3 m room holding two spheres, seen by a 176 x 144 depth camera
// (the paper's SwissRanger) from 12 poses; the map is at 0.05 m. The frontiers' scene is a floor
// of 8 x 8 rooms of 5 m built cell by cell. See BENCHMARKS.md.
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <benchmark/benchmark.h>
#include <Eigen/Geometry>

#include "mvog/checks.h"
#include "mvog/frontiers.h"
#include "mvog/map.h"
#include "mvog/map_io.h"
#include "mvog/surfaces.h"
#include "mvog_scene/scene.h"

namespace {

constexpr double kResolution = 0.05;
constexpr double kMaxRange = 8.0;
const Eigen::Vector3d kRoomMin(-5.0, -4.0, 0.0);
const Eigen::Vector3d kRoomMax(5.0, 4.0, 3.0);

/// The room's walls, floor and ceiling, and two spheres.
mvog_scene::Scene roomScene() {
  mvog_scene::Scene scene;
  scene.boxes = mvog_scene::roomWalls(kRoomMin, kRoomMax, 0.1);
  scene.spheres = {{{2.0, 1.0, 0.8}, 0.6}, {{-2.5, -1.5, 1.6}, 0.9}};
  return scene;
}

/// The 12 scans of a loop through the room, each turned to look across it.
const std::vector<mvog::Scan>& roomScans() {
  static const std::vector<mvog::Scan> scans = [] {
    const mvog_scene::Scene scene = roomScene();
    std::vector<mvog::Scan> result;
    for (int k = 0; k < 12; ++k) {
      const double angle = 2.0 * M_PI * k / 12.0;
      const Eigen::Vector3d position(3.0 * std::cos(angle), 2.0 * std::sin(angle), 1.5);
      result.push_back(mvog_scene::depthScan(scene, mvog_scene::DepthCamera(), position,
                                             angle + M_PI / 2.0 + 0.3, 0.3, kMaxRange));
    }
    return result;
  }();
  return scans;
}

mvog::InsertionConfig insertionConfig(int threads) {
  mvog::InsertionConfig config;
  config.max_range = kMaxRange;
  config.insertion_threads = threads;
  return config;
}

mvog::Map roomMap() {
  mvog::MapConfig config;
  config.resolution = kResolution;
  mvog::Map map(config);
  for (const mvog::Scan& scan : roomScans()) map.insertScan(scan, insertionConfig(1));
  return map;
}

/// The full room map, built once and shared by the read-only benchmarks.
const mvog::Map& sharedRoomMap() {
  static const mvog::Map map = roomMap();
  return map;
}

void BM_InsertReading(benchmark::State& state) {
  mvog::Map map = roomMap();
  const mvog::Scan& scan = roomScans().front();
  const mvog::InsertionConfig config = insertionConfig(1);
  std::size_t next = 0;
  for (auto _ : state) {
    const Eigen::Vector3d end = scan.hits[next].cast<double>();
    benchmark::DoNotOptimize(
        map.insertReading(scan.origin, end, mvog::ReadingKind::kObstacle, config));
    next = (next + 997) % scan.hits.size();  // spread over the image
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_InsertReading);

void BM_InsertScan(benchmark::State& state) {
  mvog::Map map = roomMap();
  const std::vector<mvog::Scan>& scans = roomScans();
  const mvog::InsertionConfig config = insertionConfig(static_cast<int>(state.range(0)));
  std::size_t next = 0;
  std::size_t readings = 0;
  for (auto _ : state) {
    const mvog::Scan& scan = scans[next];
    benchmark::DoNotOptimize(map.insertScan(scan, config));
    readings += scan.hits.size() + scan.out_of_range.size();
    next = (next + 1) % scans.size();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(readings));
  state.counters["readings_per_scan"] =
      static_cast<double>(readings) / static_cast<double>(state.iterations());
}
BENCHMARK(BM_InsertScan)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Query100k(benchmark::State& state) {
  const mvog::Map& map = sharedRoomMap();
  std::mt19937 random(42);
  std::uniform_real_distribution<double> x(kRoomMin.x(), kRoomMax.x());
  std::uniform_real_distribution<double> y(kRoomMin.y(), kRoomMax.y());
  std::uniform_real_distribution<double> z(kRoomMin.z(), kRoomMax.z());
  std::vector<Eigen::Vector3d> points(100000);
  for (Eigen::Vector3d& p : points) p = {x(random), y(random), z(random)};
  for (auto _ : state) {
    std::size_t occupied = 0;
    for (const Eigen::Vector3d& p : points) {
      occupied += map.occupancy(p).state(0.5) == mvog::OccupancyState::kOccupied;
    }
    benchmark::DoNotOptimize(occupied);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(points.size()));
}
BENCHMARK(BM_Query100k)->Unit(benchmark::kMillisecond);

void BM_CrossSection20m(benchmark::State& state) {
  const mvog::Map& map = sharedRoomMap();
  const mvog::CellRange cells =
      map.cellsInRectangle(-10.0, -10.0, 10.0 - kResolution / 2, 10.0 - kResolution / 2);
  for (auto _ : state) benchmark::DoNotOptimize(map.crossSection(1.0, cells));
  state.counters["cells"] = static_cast<double>(cells.width() * cells.height());
}
BENCHMARK(BM_CrossSection20m)->Unit(benchmark::kMillisecond);

/// One decay step, amortised: a full pass over the masses happens every few thousand steps.
void BM_Decay(benchmark::State& state) {
  mvog::Map map = roomMap();
  for (auto _ : state) map.decay(0.99);
}
BENCHMARK(BM_Decay);

/// A decay step that renormalises every stored mass (the rare full pass of BM_Decay).
void BM_DecayRenormalise(benchmark::State& state) {
  mvog::Map map = roomMap();
  for (auto _ : state) map.decay(0x1p-65);
}
BENCHMARK(BM_DecayRenormalise)->Unit(benchmark::kMillisecond);

/// `rooms` x `rooms` copies of the room map side by side (Map::merge): a large map.
mvog::Map roomsMap(int rooms) {
  const mvog::Map& room = sharedRoomMap();
  mvog::Map map(room.config());
  const std::int64_t cells = static_cast<std::int64_t>(std::lround(12.0 / kResolution));
  for (int i = 0; i < rooms; ++i) {
    for (int j = 0; j < rooms; ++j)
      map.merge(room, mvog::GridTransform{0, i * cells, j * cells, 0.0});
  }
  return map;
}

/// Forgetting what is lighter than 1e-6 (not inlined: callgrind --toggle-collect='*forgetStep*'
/// counts the benchmarks' steps alone, without their set-up).
[[gnu::noinline]] mvog::ForgetResult forgetStep(mvog::Map& map) { return map.forget(1e-6); }

/// A decay step and forgetting, with nothing light enough to forget: what forgetting costs on
/// every decay step of a large map (each tile's lightest mass is remembered from the last call).
void BM_DecayAndForgetNothing(benchmark::State& state) {
  mvog::Map map = roomsMap(static_cast<int>(state.range(0)));
  map.forget(1e-6);
  for (auto _ : state) {
    map.decay(0.999999);
    benchmark::DoNotOptimize(forgetStep(map));
  }
  state.counters["tiles"] = static_cast<double>(map.memoryUsage().tiles);
}
BENCHMARK(BM_DecayAndForgetNothing)->Arg(1)->Arg(5)->Unit(benchmark::kMicrosecond);

/// Forgetting after a scan: the tiles the scan wrote are looked at again.
void BM_ScanThenForget(benchmark::State& state) {
  mvog::Map map = roomsMap(5);
  map.forget(1e-6);
  std::size_t k = 0;
  for (auto _ : state) {
    state.PauseTiming();
    map.insertScan(roomScans()[k++ % roomScans().size()], insertionConfig(1));
    state.ResumeTiming();
    benchmark::DoNotOptimize(forgetStep(map));
  }
}
BENCHMARK(BM_ScanThenForget)->Unit(benchmark::kMicrosecond);

void BM_Save(benchmark::State& state) {
  const mvog::Map& map = sharedRoomMap();
  std::size_t bytes = 0;
  for (auto _ : state) {
    const std::vector<std::uint8_t> data = mvog::serializeMap(map);
    bytes = data.size();
  }
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(bytes));
  state.counters["file_bytes"] = static_cast<double>(bytes);
}
BENCHMARK(BM_Save)->Unit(benchmark::kMillisecond);

void BM_Load(benchmark::State& state) {
  const std::vector<std::uint8_t> data = mvog::serializeMap(sharedRoomMap());
  for (auto _ : state) benchmark::DoNotOptimize(mvog::deserializeMap(data.data(), data.size()));
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(data.size()));
}
BENCHMARK(BM_Load)->Unit(benchmark::kMillisecond);

/// A 40 m x 40 m floor at 0.05 m (800 x 800 cells): 8 x 8 rooms of 5 m, each with a floor, free
/// space up to 2.5 m and a ceiling, walls one cell thick with a door of 1 m in each, and a desk;
/// a third of the rooms never observed, so that frontiers lie in the doors leading to them.
mvog::Map floorMap() {
  mvog::MapConfig config;
  config.resolution = kResolution;
  mvog::Map map(config);
  auto volume = [](float bottom, float top, float density) {
    return mvog::Volume{bottom, top, density * (top - bottom)};
  };
  const mvog::CellVolumes room{{volume(-1, 0, 4), volume(50, 52, 4)}, {volume(0, 50, 3)}};
  const mvog::CellVolumes desk{{volume(-1, 0, 4), volume(14, 15, 4), volume(50, 52, 4)},
                               {volume(0, 14, 3), volume(14, 15, 0.1f), volume(15, 50, 3)}};
  const mvog::CellVolumes wall{{volume(-1, 52, 4)}, {}};
  constexpr int kRoom = 100;  // cells
  std::vector<mvog::Map::CellAssignment> cells;
  for (int y = 0; y <= 8 * kRoom; ++y) {
    for (int x = 0; x <= 8 * kRoom; ++x) {
      const int along_x = x % kRoom;
      const int along_y = y % kRoom;
      const bool explored = (x / kRoom + y / kRoom) % 3 != 0;
      const bool in_wall = along_x == 0 || along_y == 0;
      const bool in_door = in_wall && (along_x == 0) != (along_y == 0) &&
                           std::abs((along_x == 0 ? along_y : along_x) - kRoom / 2) < 10;
      if (in_wall && !in_door) {
        cells.push_back({{x, y}, wall});
      } else if (explored || in_door) {
        const bool at_desk = along_x >= 20 && along_x < 40 && along_y >= 20 && along_y < 30;
        cells.push_back({{x, y}, at_desk ? desk : room});
      }
    }
  }
  map.setCellVolumes(cells);
  return map;
}

const mvog::Map& sharedFloorMap() {
  static const mvog::Map map = floorMap();
  return map;
}

/// Checks `segments` with radius range(0) cm, by a SegmentChecker made for each call
/// (range(1) = 0) or kept from call to call (1: the map does not change); reports the share found
/// free.
void checkSegments(benchmark::State& state, const mvog::Map& map,
                   const std::vector<mvog::Segment>& segments) {
  const double radius = static_cast<double>(state.range(0)) / 100.0;
  mvog::SegmentChecker kept;
  std::vector<mvog::SegmentCheck> checks;
  for (auto _ : state) {
    checks = state.range(1) != 0 ? kept.check(map, segments, radius)
                                 : mvog::checkSegments(map, segments, radius);
    benchmark::DoNotOptimize(checks.data());
  }
  double free = 0;
  for (const mvog::SegmentCheck& check : checks) free += check.state == mvog::OccupancyState::kFree;
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(segments.size()));
  state.counters["free"] = free / static_cast<double>(segments.size());
}

/// Radius 0 and 0.3 m by a checker made for the call, and 0.3 m by one kept from call to call.
void segmentCheckArgs(benchmark::internal::Benchmark* benchmark) {
  benchmark->Args({0, 0})->Args({30, 0})->Args({30, 1})->Unit(benchmark::kMillisecond);
}

/// 10,000 segments of 5 m from random points of the room in random directions: most leave the
/// room, meet a sphere or the space the camera never saw.
void BM_CheckSegments10k(benchmark::State& state) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> x(kRoomMin.x(), kRoomMax.x());
  std::uniform_real_distribution<double> y(kRoomMin.y(), kRoomMax.y());
  std::uniform_real_distribution<double> z(kRoomMin.z(), kRoomMax.z());
  std::normal_distribution<double> direction;
  std::vector<mvog::Segment> segments(10000);
  for (mvog::Segment& segment : segments) {
    segment.start = {x(random), y(random), z(random)};
    const Eigen::Vector3d d(direction(random), direction(random), direction(random));
    segment.end = segment.start + 5.0 * d.normalized();
  }
  checkSegments(state, sharedRoomMap(), segments);
}
BENCHMARK(BM_CheckSegments10k)->Apply(segmentCheckArgs);

/// 10,000 segments of 5 m within the floor's observed rooms, clear of walls, desks, floor and
/// ceiling by more than 0.3 m: all free, so every cell of every footprint is looked at.
void BM_CheckFreeSegments10k(benchmark::State& state) {
  std::mt19937 random(7);
  std::uniform_int_distribution<int> room(0, 7);
  std::uniform_real_distribution<double> within(0.4, 4.6);  // of a room's 5 m
  std::uniform_real_distribution<double> height(1.1, 2.1);
  std::uniform_real_distribution<double> angle(0.0, 2.0 * M_PI);
  std::vector<mvog::Segment> segments;
  while (segments.size() < 10000) {
    const int rx = room(random);
    const int ry = room(random);
    if ((rx + ry) % 3 == 0) continue;  // never observed
    const Eigen::Vector3d start(5.0 * rx + within(random), 5.0 * ry + within(random),
                                height(random));
    const double a = angle(random);
    const double climb = height(random) - start.z();
    const Eigen::Vector3d end =
        start + Eigen::Vector3d(std::cos(a), std::sin(a), 0.0) * std::sqrt(25.0 - climb * climb) +
        Eigen::Vector3d(0.0, 0.0, climb);
    const Eigen::Vector2d inside = end.head<2>() - Eigen::Vector2d(5.0 * rx, 5.0 * ry);
    if (inside.minCoeff() < 0.4 || inside.maxCoeff() > 4.6) continue;
    segments.push_back({start, end});
  }
  checkSegments(state, sharedFloorMap(), segments);
}
BENCHMARK(BM_CheckFreeSegments10k)->Apply(segmentCheckArgs);

std::size_t pointsOf(const mvog::Frontiers& frontiers) { return frontiers.points().size(); }
std::size_t pointsOf(const mvog::Surfaces& surfaces) { return surfaces.surfaces().size(); }

/// Frontiers (Kept = Frontiers) or surfaces (Surfaces) over the whole 40 m x 40 m floor, from
/// scratch; reports the frontier voxels or the surfaces.
template <class Kept>
void BM_Pass40m(benchmark::State& state) {
  const mvog::Map& map = sharedFloorMap();
  std::size_t points = 0;
  for (auto _ : state) {
    Kept kept;
    kept.update(map);
    points = pointsOf(kept);
  }
  state.counters["points"] = static_cast<double>(points);
}
BENCHMARK_TEMPLATE(BM_Pass40m, mvog::Frontiers)->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_Pass40m, mvog::Surfaces)->Unit(benchmark::kMillisecond);

/// An update of the floor's frontiers after one cell changed: its tile and four neighbours, then
/// the clustering of every frontier voxel.
void BM_FrontierUpdateOneTile40m(benchmark::State& state) {
  mvog::Map map = floorMap();
  mvog::Frontiers frontiers;
  frontiers.update(map);
  const mvog::CellVolumes original = map.cellVolumes({250, 250});
  for (auto _ : state) {
    state.PauseTiming();
    map.setCellVolumes({250, 250}, map.cellVolumes({250, 250}).positive.size() == 2
                                       ? mvog::CellVolumes{}
                                       : original);
    state.ResumeTiming();
    frontiers.update(map);
  }
}
BENCHMARK(BM_FrontierUpdateOneTile40m)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
