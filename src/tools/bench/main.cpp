// mvog_bench: MVOG against OctoMap (and Bonxai, when built with it) on the same rays from a ROS
// bag or an OctoMap scan graph.
//   mvog_bench --input FILE [--resolution R]... [--max-range M] [--threads N] [--repeat K]
//              [--backend mvog|octomap|bonxai|walk|every-reading|both|all] [--json OUT]
//              [--fixed-frame FRAME]
//              [--model default|paper] [--clip-free-space-at-hits on|off]
//              [--mass-counting per-scan|per-reading] [--split-free-space-at-obstacles on|off]
//              [--free-space-rays one-path-per-end-column|one-per-end-voxel|every-reading]
//              [--octomap-clamping on|off] [--evidence-limit E|inf] [--hit-memory-scans S]
//              [--hit-memory-scope line-scans|every-scan]
//              [--truth-slice OUT.ppm]
// Everything is read first; only the insertion is timed. See BENCHMARKS.md.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "backends.h"
#include "bonxai_backend.h"
#include "input.h"
#include "report.h"
#include "truth.h"

namespace {

/// Rays sampled for the quality and agreement of the maps (a few seconds of queries at most).
constexpr std::size_t kAgreementRays = 20000;

struct Arguments {
  std::string input;
  std::vector<double> resolutions;
  double max_range = std::numeric_limits<double>::infinity();
  int threads = 1;
  int repeat = 1;
  mvog::ModelRules rules;
  std::optional<double> occupancy_threshold;
  bool out_of_range = false;  ///< default: the rules' (the paper's for --model paper)
  mvog::FreeSpaceRays free_space_rays = mvog::InsertionConfig{}.free_space_rays;
  bool octomap_clamping = true;
  double evidence_limit = mvog::InsertionConfig{}.evidence_limit;
  int hit_memory_scans = mvog::InsertionConfig{}.hit_memory_scans;
  mvog::HitMemoryScope hit_memory_scope = mvog::InsertionConfig{}.hit_memory_scope;
  bool run_mvog = false;
  bool run_octomap = false;
  bool run_bonxai = false;
  bool run_walk = false;
  bool bonxai_skipped = false;  ///< --backend all, built without Bonxai
  bool run_every_reading = false;
  std::string json;
  std::string fixed_frame = "map";
  std::string truth_slice;  ///< a ground-truth scene's slice is drawn here
};

class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

constexpr const char* kUsage =
    "usage: mvog_bench --input FILE [--resolution R]... [--max-range M] [--threads N]\n"
    "                  [--repeat K] [--backend mvog|octomap|bonxai|walk|every-reading|both|all]\n"
    "                  [--json OUT] [--fixed-frame FRAME]\n"
    "                  [--model default|paper] [--clip-free-space-at-hits on|off]\n"
    "                  [--mass-counting per-scan|per-reading]\n"
    "                  [--split-free-space-at-obstacles on|off] [--occupancy-threshold T]\n"
    "                  [--out-of-range-free-length L|inf]\n"
    "                  [--free-space-rays one-path-per-end-column|one-per-end-voxel|\n"
    "                                     every-reading]\n"
    "                  [--octomap-clamping on|off] [--evidence-limit E|inf]\n"
    "                  [--hit-memory-scans S] [--hit-memory-scope line-scans|every-scan]\n"
    "                  [--truth-slice OUT.ppm]\n"
    "  FILE        a ROS bag (LaserScan, PointCloud2 and/or depth Image 16UC1 or 32FC1 with\n"
    "              CameraInfo; poses from /tf and /tf_static)\n"
    "              or an OctoMap ScanGraph (.graph), or synthetic:NAME, a sensor cast into a\n"
    "              scene built in code (rotating-lidar-16, rotating-lidar-16-firing-order,\n"
    "              rotating-lidar-32, tilting-laser), or truth:NAME, a scene with exact geometry\n"
    "              and its sensor, every backend's map scored at points labelled from it\n"
    "              (room-depth-camera, bridge-lidar-16, car-lidar, corridor-2d-laser,\n"
    "              tilting-laser)\n"
    "  R           cell size in metres, repeatable (default 0.1)\n"
    "  M           hits further than M metres insert free space only, truncated (default: none)\n"
    "  N           MVOG insertion threads (default 1; OctoMap and Bonxai always use one)\n"
    "  K           each backend inserts K times, the backends taking turns, and the fastest\n"
    "              run of each is reported (default 1)\n"
    "  --backend   repeatable: mvog, octomap, bonxai (only when built with Bonxai's sources,\n"
    "              CMake's MVOG_PEERS_DIR), walk (the bare ray walk, MVOG's floor),\n"
    "              every-reading (MVOG walking every reading's ray; with mvog, the agreement\n"
    "              of the two maps), both (mvog and octomap, the default) or all (every one\n"
    "              built)\n"
    "  FRAME       the bag's world frame (default map)\n"
    "  T           MVOG is occupied where p > T (default: mvog::kDefaultOccupancyThreshold,\n"
    "              the paper's 0.5 with --model paper)\n"
    "  L           MVOG also inserts the out-of-range readings, freeing L m of each (OctoMap\n"
    "              and Bonxai take none: by default every backend disregards them, as the\n"
    "              paper's Table I)\n"
    "  --model     MVOG's rules: the defaults, or the paper's exact model; the options after\n"
    "              it change one rule each (mvog::ModelRules, README's decisions table)\n"
    "  --free-space-rays  MVOG walks one ray per end voxel (the default), one path per end\n"
    "              column's run of end voxels or every reading's (mvog::FreeSpaceRays)\n"
    "  E           MVOG's evidence limit in scans, with per-scan masses\n"
    "              (mvog::InsertionConfig::evidence_limit; default 14)\n"
    "  S           MVOG clips a scan's free space around the hits of the S scans before it\n"
    "              too, with clip_free_space_at_hits (Sec. V.B's scan groups;\n"
    "              mvog::InsertionConfig::hit_memory_scans; default 5; 0: its own only)\n"
    "  --hit-memory-scope  the scans S groups: line scans (the default: their readings in\n"
    "              one plane through the origin) or every scan (mvog::HitMemoryScope)\n"
    "  --octomap-clamping  OctoMap's log-odds clamped at each update (on, its default) or\n"
    "              not (off: every hit and miss counts, as MVOG's masses do)\n"
    "  --truth-slice  with truth:NAME, a cross-section of the scene with each map's errors\n"
    "              coloured, as a binary PPM: a panel per resolution and map (mvog, octomap,\n"
    "              bonxai, those run), top to bottom\n";

double positiveNumber(const std::string& option, const std::string& text) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(value) || value <= 0.0) {
    throw UsageError(option + " needs a positive number, got '" + text + "'");
  }
  return value;
}

int wholeNumber(const std::string& option, const std::string& text, int min, int max) {
  char* end = nullptr;
  const long value = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || value < min || value > max) {
    throw UsageError(option + " needs a whole number in [" + std::to_string(min) + ", " +
                     std::to_string(max) + "], got '" + text + "'");
  }
  return static_cast<int>(value);
}

bool onOff(const std::string& option, const std::string& value) {
  if (value != "on" && value != "off") {
    throw UsageError(option + " must be on or off, got '" + value + "'");
  }
  return value == "on";
}

Arguments parseArguments(int argc, char** argv) {
  Arguments arguments;
  for (int k = 1; k < argc; ++k) {
    const std::string option = argv[k];
    if (option == "--help" || option == "-h") throw UsageError("");
    if (k + 1 >= argc) throw UsageError("unknown option or missing value: " + option);
    const std::string value = argv[++k];
    if (option == "--input") {
      arguments.input = value;
    } else if (option == "--resolution") {
      arguments.resolutions.push_back(positiveNumber(option, value));
    } else if (option == "--max-range") {
      arguments.max_range = positiveNumber(option, value);
    } else if (option == "--threads") {
      arguments.threads = wholeNumber(option, value, 1, 256);
    } else if (option == "--repeat") {
      arguments.repeat = wholeNumber(option, value, 1, 100);
    } else if (option == "--backend") {
      if (value != "mvog" && value != "octomap" && value != "bonxai" && value != "walk" &&
          value != "every-reading" && value != "both" && value != "all") {
        throw UsageError(
            "--backend must be mvog, octomap, bonxai, walk, every-reading, both or all, got '" +
            value + "'");
      }
      if (value == "bonxai" && !mvog_bench::kBonxaiBuilt) {
        throw UsageError(mvog_bench::kBonxaiMissing);
      }
      arguments.run_mvog |= value == "mvog" || value == "both" || value == "all";
      arguments.run_octomap |= value == "octomap" || value == "both" || value == "all";
      arguments.run_bonxai |= (value == "bonxai" || value == "all") && mvog_bench::kBonxaiBuilt;
      arguments.bonxai_skipped |= value == "all" && !mvog_bench::kBonxaiBuilt;
      arguments.run_walk |= value == "walk" || value == "all";
      arguments.run_every_reading |= value == "every-reading" || value == "all";
    } else if (option == "--occupancy-threshold") {
      const double threshold = positiveNumber(option, value);
      if (threshold >= 1.0) throw UsageError("--occupancy-threshold must be in (0, 1)");
      arguments.occupancy_threshold = threshold;
    } else if (option == "--out-of-range-free-length") {
      arguments.rules.out_of_range_free_length =
          value == "inf" ? std::numeric_limits<double>::infinity() : positiveNumber(option, value);
      arguments.out_of_range = true;
    } else if (option == "--model") {
      if (value != "default" && value != "paper") {
        throw UsageError("--model must be default or paper, got '" + value + "'");
      }
      arguments.rules = value == "paper" ? mvog::ModelRules::paper() : mvog::ModelRules{};
    } else if (option == "--clip-free-space-at-hits") {
      arguments.rules.clip_free_space_at_hits = onOff(option, value);
    } else if (option == "--split-free-space-at-obstacles") {
      arguments.rules.split_free_space_at_obstacles = onOff(option, value);
    } else if (option == "--mass-counting") {
      if (value != "per-scan" && value != "per-reading") {
        throw UsageError("--mass-counting must be per-scan or per-reading, got '" + value + "'");
      }
      arguments.rules.mass_counting =
          value == "per-scan" ? mvog::MassCounting::kPerScan : mvog::MassCounting::kPerReading;
    } else if (option == "--free-space-rays") {
      if (value == "one-path-per-end-column") {
        arguments.free_space_rays = mvog::FreeSpaceRays::kOnePathPerEndColumn;
      } else if (value == "one-per-end-voxel") {
        arguments.free_space_rays = mvog::FreeSpaceRays::kOnePerEndVoxel;
      } else if (value == "every-reading") {
        arguments.free_space_rays = mvog::FreeSpaceRays::kEveryReading;
      } else {
        throw UsageError(
            "--free-space-rays must be one-path-per-end-column, one-per-end-voxel or "
            "every-reading, got '" +
            value + "'");
      }
    } else if (option == "--evidence-limit") {
      arguments.evidence_limit =
          value == "inf" ? std::numeric_limits<double>::infinity() : positiveNumber(option, value);
    } else if (option == "--hit-memory-scans") {
      arguments.hit_memory_scans = wholeNumber(option, value, 0, mvog::kMaxHitMemoryScans);
    } else if (option == "--hit-memory-scope") {
      if (value == "line-scans") {
        arguments.hit_memory_scope = mvog::HitMemoryScope::kLineScans;
      } else if (value == "every-scan") {
        arguments.hit_memory_scope = mvog::HitMemoryScope::kEveryScan;
      } else {
        throw UsageError("--hit-memory-scope must be line-scans or every-scan, got '" + value +
                         "'");
      }
    } else if (option == "--octomap-clamping") {
      arguments.octomap_clamping = onOff(option, value);
    } else if (option == "--json") {
      arguments.json = value;
    } else if (option == "--fixed-frame") {
      arguments.fixed_frame = value;
    } else if (option == "--truth-slice") {
      arguments.truth_slice = value;
    } else {
      throw UsageError("unknown option: " + option);
    }
  }
  if (arguments.input.empty()) throw UsageError("--input is required");
  if (!arguments.truth_slice.empty() &&
      arguments.input.compare(0, mvog_bench::kTruthPrefix.size(), mvog_bench::kTruthPrefix) != 0) {
    throw UsageError("--truth-slice needs --input truth:NAME");
  }
  if (arguments.resolutions.empty()) arguments.resolutions.push_back(0.1);
  if (!arguments.run_mvog && !arguments.run_octomap && !arguments.run_bonxai &&
      !arguments.run_walk && !arguments.run_every_reading) {
    arguments.run_mvog = arguments.run_octomap = true;
  }
  return arguments;
}

double occupancyThreshold(const Arguments& arguments) {
  return arguments.occupancy_threshold.value_or(arguments.rules == mvog::ModelRules::paper()
                                                    ? mvog::kPaperOccupancyThreshold
                                                    : mvog::kDefaultOccupancyThreshold);
}

/// Keeps in `fastest` the faster of it and `next` (a shared machine only ever slows a run down);
/// every run builds the same map, so the one kept stands for all.
template <class Run, class SecondsOf>
void keepFaster(std::optional<Run>& fastest, Run next, SecondsOf seconds_of) {
  if (!fastest || seconds_of(next) < seconds_of(*fastest)) fastest = std::move(next);
}

/// A ground-truth scene's geometry, where its rays went, and the panels of its slice so far.
struct TruthContext {
  mvog_bench::TruthScene scene;
  mvog_bench::RayCoverage coverage;
  std::vector<mvog_bench::SlicePanel> slice_panels;
};

mvog_bench::ResolutionReport benchmarkResolution(const Arguments& arguments,
                                                 const mvog_bench::InputData& input,
                                                 const mvog_bench::SamplePoints& points,
                                                 double resolution, TruthContext* truth) {
  mvog_bench::RunOptions options;
  options.resolution = resolution;
  options.max_range = arguments.max_range;
  options.threads = arguments.threads;
  options.rules = arguments.rules;
  options.occupancy_threshold = occupancyThreshold(arguments);
  options.out_of_range = arguments.out_of_range;
  options.free_space_rays = arguments.free_space_rays;
  options.octomap_clamping = arguments.octomap_clamping;
  options.evidence_limit = arguments.evidence_limit;
  options.hit_memory_scans = arguments.hit_memory_scans;
  options.hit_memory_scope = arguments.hit_memory_scope;
  mvog_bench::ResolutionReport report;
  report.resolution = resolution;
  report.voxel_grid_cells = mvog_bench::boundingBoxVoxels(input, options);
  std::optional<mvog_bench::MvogRun> mvog;
  std::optional<mvog_bench::OctomapRun> octomap;
  std::optional<mvog_bench::BonxaiRun> bonxai;
  std::optional<mvog_bench::MvogRun> every_reading;
  mvog_bench::RunOptions every_reading_options = options;
  every_reading_options.free_space_rays = mvog::FreeSpaceRays::kEveryReading;
  // The backends take turns, one insertion each a round, so that a slow spell of a shared
  // machine falls on all of them alike rather than on the repeats of one: the ratios of their
  // fastest insertions are then measured over the same time.
  for (int round = 0; round < arguments.repeat; ++round) {
    if (arguments.run_mvog) {
      keepFaster(mvog, mvog_bench::runMvog(input, options),
                 [](const mvog_bench::MvogRun& r) { return r.stats.insert_seconds; });
    }
    if (arguments.run_octomap) {
      keepFaster(octomap, mvog_bench::runOctomap(input, options),
                 [](const mvog_bench::OctomapRun& r) { return r.stats.insert_seconds; });
    }
    if constexpr (mvog_bench::kBonxaiBuilt) {  // runBonxai is defined only then
      if (arguments.run_bonxai) {
        keepFaster(bonxai, mvog_bench::runBonxai(input, options),
                   [](const mvog_bench::BonxaiRun& r) { return r.stats.insert_seconds; });
      }
    }
    if (arguments.run_every_reading) {
      keepFaster(every_reading, mvog_bench::runMvog(input, every_reading_options),
                 [](const mvog_bench::MvogRun& r) { return r.stats.insert_seconds; });
    }
    if (arguments.run_walk) {
      keepFaster(report.walk, mvog_bench::runWalk(input, options),
                 [](const mvog_bench::WalkStats& r) { return r.insert_seconds; });
    }
  }
  if (mvog) {
    report.mvog = mvog->stats;
    std::fprintf(stderr, "mvog_bench: %.3f m: mvog inserted in %.3f s\n", resolution,
                 mvog->stats.insert_seconds);
  }
  if (octomap) {
    std::fprintf(stderr, "mvog_bench: %.3f m: octomap inserted in %.3f s\n", resolution,
                 octomap->stats.insert_seconds);
  }
  if (bonxai) {
    std::fprintf(stderr, "mvog_bench: %.3f m: bonxai inserted in %.3f s\n", resolution,
                 bonxai->stats.insert_seconds);
  }
  if (every_reading) {
    report.every_reading = every_reading->stats;
    std::fprintf(stderr,
                 "mvog_bench: %.3f m: mvog walking every reading's ray inserted in %.3f s\n",
                 resolution, every_reading->stats.insert_seconds);
    if (mvog) {
      report.every_reading_agreement = mvog_bench::compareWithEveryReading(
          points, resolution, options.occupancy_threshold, mvog->map, every_reading->map);
    }
  }
  if (report.walk) {
    std::fprintf(stderr, "mvog_bench: %.3f m: the bare walk took %.3f s\n", resolution,
                 report.walk->insert_seconds);
  }
  if (mvog) {
    report.mvog_quality = mvog_bench::mvogQuality(mvog->map, options.occupancy_threshold, points);
  }
  if (octomap) report.octomap_quality = mvog_bench::octomapQuality(*octomap->tree, points);
  if constexpr (mvog_bench::kBonxaiBuilt) {  // bonxaiQuality is defined only then
    if (bonxai) {
      report.bonxai = bonxai->stats;
      report.bonxai_quality = mvog_bench::bonxaiQuality(*bonxai->map, points);
    }
  }
  if (mvog && octomap) {
    report.agreement =
        mvog_bench::compareMaps(points, mvog->map, options.occupancy_threshold, *octomap->tree);
  }
  if (truth != nullptr) {
    const mvog_bench::TruthLabels labels =
        mvog_bench::labelPoints(truth->scene, input, truth->coverage, resolution);
    // Each map's scores, and its panel of the slice when asked (the checks and every-reading
    // have none).
    auto score = [&](const char* backend, const auto& state_of, bool in_slice) {
      report.truth.push_back({backend, mvog_bench::scoreMap(labels, state_of)});
      if (in_slice && !arguments.truth_slice.empty()) {
        truth->slice_panels.push_back(
            mvog_bench::slicePanel(truth->scene.slice, resolution, state_of));
      }
    };
    score(
        "oracle",
        [&](const Eigen::Vector3d& p) {
          return mvog_bench::oracleState(truth->scene, truth->coverage, p);
        },
        false);
    const mvog_bench::EndpointsMap endpoints(input, options.max_range, resolution);
    score(
        "endpoints-only", [&](const Eigen::Vector3d& p) { return endpoints.state(p); }, false);
    const auto mvog_state = [&](const mvog::Map& map) {
      return [&map, &options](const Eigen::Vector3d& p) {
        return map.occupancy(p).state(options.occupancy_threshold);
      };
    };
    if (mvog) score("mvog", mvog_state(mvog->map), true);
    if (octomap) {
      score(
          "octomap",
          [&](const Eigen::Vector3d& p) { return mvog_bench::octomapState(*octomap->tree, p); },
          true);
    }
    if constexpr (mvog_bench::kBonxaiBuilt) {  // bonxaiState is defined only then
      if (bonxai) {
        score(
            "bonxai",
            [&](const Eigen::Vector3d& p) { return mvog_bench::bonxaiState(*bonxai->map, p); },
            true);
      }
    }
    if (every_reading) score("every-reading", mvog_state(every_reading->map), false);
  }
  if (octomap) {  // last: writeBinary turns the tree into its maximum-likelihood estimate
    octomap->stats.binary_file_bytes = mvog_bench::octomapBinaryFileBytes(*octomap->tree);
    report.octomap = octomap->stats;
  }
  return report;
}

}  // namespace

int main(int argc, char** argv) {
  Arguments arguments;
  try {
    arguments = parseArguments(argc, argv);
  } catch (const UsageError& e) {
    const bool help = e.what()[0] == '\0';
    if (!help) std::fprintf(stderr, "mvog_bench: %s\n", e.what());
    std::fputs(kUsage, help ? stdout : stderr);
    return help ? 0 : 2;
  }
  if (arguments.bonxai_skipped) {
    std::fprintf(stderr, "mvog_bench: --backend all skips Bonxai: %s\n",
                 mvog_bench::kBonxaiMissing);
  }
  try {
    mvog_bench::BenchReport report;
    report.input_path = arguments.input;
    report.max_range = arguments.max_range;
    report.rules = arguments.rules;
    report.octomap_clamping = arguments.octomap_clamping;
    report.occupancy_threshold = occupancyThreshold(arguments);
    mvog::InsertionConfig insertion;
    insertion.evidence_limit = arguments.evidence_limit;
    report.evidence_limit = insertion.appliedEvidenceLimit(arguments.rules);
    insertion.hit_memory_scans = arguments.hit_memory_scans;
    report.hit_memory_scans = insertion.appliedHitMemoryScans(arguments.rules);
    report.hit_memory_scope = arguments.hit_memory_scope;
    report.out_of_range = arguments.out_of_range;
    report.repeat = arguments.repeat;
    const auto start = std::chrono::steady_clock::now();
    // A depth image's +Inf pixels end where the server ends them (README, ~depth_topics).
    const mvog_bench::InputData input = mvog_bench::loadInput(
        arguments.input, arguments.fixed_frame,
        std::min(arguments.max_range, arguments.rules.out_of_range_free_length));
    report.load_seconds = mvog_bench::secondsSince(start);
    mvog_bench::RunOptions sampling;
    sampling.max_range = arguments.max_range;
    const mvog_bench::SamplePoints points =
        mvog_bench::samplePoints(input, sampling, kAgreementRays);
    std::optional<TruthContext> truth;
    if (input.format == "truth") {
      truth.emplace(TruthContext{
          mvog_bench::truthScene(arguments.input.substr(mvog_bench::kTruthPrefix.size())),
          mvog_bench::RayCoverage(input, arguments.max_range, mvog_bench::kCoverageVoxel),
          {}});
    }
    for (double resolution : arguments.resolutions) {
      report.resolutions.push_back(
          benchmarkResolution(arguments, input, points, resolution, truth ? &*truth : nullptr));
    }
    if (!arguments.truth_slice.empty()) {
      mvog_bench::writeTruthSlice(truth->scene, truth->coverage, truth->slice_panels,
                                  arguments.truth_slice);
    }
    mvog_bench::printReport(report, input, stdout);
    if (!arguments.json.empty()) mvog_bench::writeJson(report, input, arguments.json);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mvog_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
