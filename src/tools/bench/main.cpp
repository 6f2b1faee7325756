// mvog_bench: MVOG against OctoMap on the same rays from a ROS bag or an OctoMap scan graph.
//   mvog_bench --input FILE [--resolution R]... [--max-range M] [--threads N]
//              [--backend mvog|octomap|both] [--json OUT] [--fixed-frame FRAME]
//              [--clear-conflicting-free-space]
// Everything is read first; only the insertion is timed. See BENCHMARKS.md.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "backends.h"
#include "input.h"
#include "report.h"

namespace {

/// Rays sampled for the occupancy agreement of the two maps (a few seconds of queries at most).
constexpr std::size_t kAgreementRays = 20000;

struct Arguments {
  std::string input;
  std::vector<double> resolutions;
  double max_range = std::numeric_limits<double>::infinity();
  int threads = 1;
  bool clear_conflicting_free_space = false;
  bool run_mvog = true;
  bool run_octomap = true;
  std::string json;
  std::string fixed_frame = "map";
};

class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

constexpr const char* kUsage =
    "usage: mvog_bench --input FILE [--resolution R]... [--max-range M] [--threads N]\n"
    "                  [--backend mvog|octomap|both] [--json OUT] [--fixed-frame FRAME]\n"
    "                  [--clear-conflicting-free-space]\n"
    "  FILE        a ROS bag (LaserScan and/or PointCloud2, poses from /tf and /tf_static)\n"
    "              or an OctoMap ScanGraph (.graph)\n"
    "  R           cell size in metres, repeatable (default 0.1)\n"
    "  M           hits further than M metres insert free space only, truncated (default: none)\n"
    "  N           MVOG insertion threads (default 1; OctoMap always uses one)\n"
    "  FRAME       the bag's world frame (default map)\n"
    "  --clear-conflicting-free-space  MVOG's Sec. V.B option: a scan's free space never\n"
    "              overlaps its own hits (OctoMap's insertPointCloud does the same per voxel)\n";

double positiveNumber(const std::string& option, const std::string& text) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(value) || value <= 0.0) {
    throw UsageError(option + " needs a positive number, got '" + text + "'");
  }
  return value;
}

Arguments parseArguments(int argc, char** argv) {
  Arguments arguments;
  for (int k = 1; k < argc; ++k) {
    const std::string option = argv[k];
    if (option == "--help" || option == "-h") throw UsageError("");
    if (option == "--clear-conflicting-free-space") {
      arguments.clear_conflicting_free_space = true;
      continue;
    }
    if (k + 1 >= argc) throw UsageError("unknown option or missing value: " + option);
    const std::string value = argv[++k];
    if (option == "--input") {
      arguments.input = value;
    } else if (option == "--resolution") {
      arguments.resolutions.push_back(positiveNumber(option, value));
    } else if (option == "--max-range") {
      arguments.max_range = positiveNumber(option, value);
    } else if (option == "--threads") {
      const double threads = positiveNumber(option, value);
      if (threads != std::floor(threads) || threads > 256) {
        throw UsageError("--threads needs a whole number in [1, 256], got '" + value + "'");
      }
      arguments.threads = static_cast<int>(threads);
    } else if (option == "--backend") {
      if (value != "mvog" && value != "octomap" && value != "both") {
        throw UsageError("--backend must be mvog, octomap or both, got '" + value + "'");
      }
      arguments.run_mvog = value != "octomap";
      arguments.run_octomap = value != "mvog";
    } else if (option == "--json") {
      arguments.json = value;
    } else if (option == "--fixed-frame") {
      arguments.fixed_frame = value;
    } else {
      throw UsageError("unknown option: " + option);
    }
  }
  if (arguments.input.empty()) throw UsageError("--input is required");
  if (arguments.resolutions.empty()) arguments.resolutions.push_back(0.1);
  return arguments;
}

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

mvog_bench::ResolutionReport benchmarkResolution(const Arguments& arguments,
                                                 const mvog_bench::InputData& input,
                                                 double resolution) {
  mvog_bench::RunOptions options;
  options.resolution = resolution;
  options.max_range = arguments.max_range;
  options.threads = arguments.threads;
  options.clear_conflicting_free_space = arguments.clear_conflicting_free_space;
  mvog_bench::ResolutionReport report;
  report.resolution = resolution;
  report.voxel_grid_cells = mvog_bench::boundingBoxVoxels(input, options);
  std::optional<mvog_bench::MvogRun> mvog;
  std::optional<mvog_bench::OctomapRun> octomap;
  if (arguments.run_mvog) {
    mvog = mvog_bench::runMvog(input, options);
    report.mvog = mvog->stats;
    std::fprintf(stderr, "mvog_bench: %.3f m: mvog inserted in %.3f s\n", resolution,
                 mvog->stats.insert_seconds);
  }
  if (arguments.run_octomap) {
    octomap = mvog_bench::runOctomap(input, options);
    std::fprintf(stderr, "mvog_bench: %.3f m: octomap inserted in %.3f s\n", resolution,
                 octomap->stats.insert_seconds);
  }
  if (mvog && octomap) {
    report.agreement =
        mvog_bench::compareMaps(input, options, mvog->map, *octomap->tree, kAgreementRays);
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
  try {
    mvog_bench::BenchReport report;
    report.input_path = arguments.input;
    report.max_range = arguments.max_range;
    report.clear_conflicting_free_space = arguments.clear_conflicting_free_space;
    const auto start = std::chrono::steady_clock::now();
    const mvog_bench::InputData input =
        mvog_bench::loadInput(arguments.input, arguments.fixed_frame);
    report.load_seconds = secondsSince(start);
    for (double resolution : arguments.resolutions) {
      report.resolutions.push_back(benchmarkResolution(arguments, input, resolution));
    }
    mvog_bench::printReport(report, input, stdout);
    if (!arguments.json.empty()) mvog_bench::writeJson(report, input, arguments.json);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mvog_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
