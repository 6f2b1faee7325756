// Exports the rays of an OctoMap ScanGraph recording as numpy files, with the map the core builds
// from them and its answers at their ends (no ROS needed):
//   mvog_ray_export GRAPH OUT_DIR [--resolution R] [--threads N] [--repeat K]
// writes into OUT_DIR (which must exist):
//   origins.npy        (S, 3) float64   each scan's sensor origin (m, map frame)
//   scan_sizes.npy     (S,) uint64      each scan's number of hits
//   hits.npy           (N, 3) float32   every scan's hits in order (m, map frame)
//   map.mvog                            the map the scans build (default MapConfig at R, default
//                                       InsertionConfig with N threads), saved by mvog::saveMap
//   states.npy         (N,) uint8       its OccupancyState at each hit (default threshold)
//   probabilities.npy  (N,) float32     its eq. (9) at each hit, NaN where unknown
// and prints one JSON line: {"scans": S, "readings": N, "insert_seconds": T}, T the fastest of K
// insertions of every scan into a new map. The Python module's tests and benchmark compare
// against these (test/python, scripts/python_insertion_benchmark.py).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>
#include <vector>

#include "input.h"
#include "mvog/map.h"
#include "mvog/map_io.h"

namespace {

/// Writes an array as a .npy file (format 1.0, little-endian C order), atomically.
void writeNpy(const std::string& path, const char* descr, const std::string& shape,
              const void* data, std::size_t bytes) {
  std::string header =
      std::string("{'descr': '") + descr + "', 'fortran_order': False, 'shape': " + shape + ", }";
  // Magic (6) + version (2) + header length (2) + header, padded with spaces to 64 bytes, '\n'.
  const std::size_t unpadded = 10 + header.size() + 1;
  header.append((64 - unpadded % 64) % 64, ' ');
  header += '\n';
  std::string file("\x93NUMPY\x01\x00", 8);
  file += static_cast<char>(header.size() & 0xff);
  file += static_cast<char>(header.size() >> 8);
  file += header;
  file.append(static_cast<const char*>(data), bytes);
  mvog::writeFileAtomically(file.data(), file.size(), path);
}

std::string shapeOf(std::size_t rows) { return "(" + std::to_string(rows) + ",)"; }
std::string shapeOf(std::size_t rows, std::size_t columns) {
  return "(" + std::to_string(rows) + ", " + std::to_string(columns) + ")";
}

int usage(const char* program) {
  std::fprintf(stderr, "usage: %s GRAPH OUT_DIR [--resolution R] [--threads N] [--repeat K]\n",
               program);
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) return usage(argv[0]);
  const std::string graph = argv[1];
  const std::string out = argv[2];
  mvog::MapConfig map_config;
  mvog::InsertionConfig insertion;
  int repeat = 1;
  for (int k = 3; k + 1 < argc; k += 2) {
    const std::string option = argv[k];
    if (option == "--resolution") {
      map_config.resolution = std::atof(argv[k + 1]);
    } else if (option == "--threads") {
      insertion.insertion_threads = std::atoi(argv[k + 1]);
    } else if (option == "--repeat") {
      repeat = std::max(1, std::atoi(argv[k + 1]));
    } else {
      return usage(argv[0]);
    }
  }
  if ((argc - 3) % 2 != 0) return usage(argv[0]);
  try {
    const mvog_bench::InputData input = mvog_bench::loadScanGraph(graph);
    std::vector<double> origins;
    std::vector<std::uint64_t> sizes;
    std::vector<float> hits;
    for (const mvog::Scan& scan : input.scans) {
      origins.insert(origins.end(), scan.origin.data(), scan.origin.data() + 3);
      sizes.push_back(scan.hits.size());
      for (const Eigen::Vector3f& hit : scan.hits)
        hits.insert(hits.end(), hit.data(), hit.data() + 3);
    }
    const std::size_t readings = hits.size() / 3;

    mvog::Map map(map_config);
    double fastest = std::numeric_limits<double>::infinity();
    for (int run = 0; run < repeat; ++run) {
      map = mvog::Map(map_config);
      const auto start = std::chrono::steady_clock::now();
      for (const mvog::Scan& scan : input.scans) map.insertScan(scan, insertion);
      fastest = std::min(
          fastest, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }

    std::vector<std::uint8_t> states(readings);
    std::vector<float> probabilities(readings);
    for (std::size_t k = 0; k < readings; ++k) {
      const mvog::PointOccupancy at = map.occupancy(
          Eigen::Vector3f(hits[3 * k], hits[3 * k + 1], hits[3 * k + 2]).cast<double>());
      states[k] = static_cast<std::uint8_t>(at.state(mvog::kDefaultOccupancyThreshold));
      probabilities[k] = at.probability.value_or(std::numeric_limits<float>::quiet_NaN());
    }

    writeNpy(out + "/origins.npy", "<f8", shapeOf(input.scans.size(), 3), origins.data(),
             origins.size() * sizeof(double));
    writeNpy(out + "/scan_sizes.npy", "<u8", shapeOf(sizes.size()), sizes.data(),
             sizes.size() * sizeof(std::uint64_t));
    writeNpy(out + "/hits.npy", "<f4", shapeOf(readings, 3), hits.data(),
             hits.size() * sizeof(float));
    writeNpy(out + "/states.npy", "|u1", shapeOf(readings), states.data(), states.size());
    writeNpy(out + "/probabilities.npy", "<f4", shapeOf(readings), probabilities.data(),
             probabilities.size() * sizeof(float));
    mvog::saveMap(map, out + "/map.mvog");
    std::printf("{\"scans\": %zu, \"readings\": %zu, \"insert_seconds\": %.9g}\n",
                input.scans.size(), readings, fastest);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mvog_ray_export: %s\n", e.what());
    return 1;
  }
  return 0;
}
