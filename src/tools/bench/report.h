#pragma once

#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "backends.h"
#include "bonxai_backend.h"
#include "input.h"
#include "truth.h"

namespace mvog_bench {

/// One map's scores at a ground-truth scene's labelled points (`backend`: a backend, or the
/// labels' checks "oracle" and "endpoints-only").
struct TruthResult {
  std::string backend;
  TruthScores scores;
};

/// Everything measured at one resolution; a backend not run is empty.
struct ResolutionReport {
  double resolution = 0.0;
  std::size_t voxel_grid_cells = 0;  ///< boundingBoxVoxels()
  std::optional<MvogStats> mvog;
  std::optional<OctomapStats> octomap;
  std::optional<BonxaiStats> bonxai;
  std::optional<WalkStats> walk;
  std::optional<Quality> mvog_quality;
  std::optional<Quality> octomap_quality;
  std::optional<Quality> bonxai_quality;
  std::optional<Agreement> agreement;  ///< when MVOG and OctoMap ran
  /// MVOG with every reading's ray walked (--backend every-reading), and MVOG's agreement with
  /// it when MVOG ran too.
  std::optional<MvogStats> every_reading;
  std::optional<EveryReadingAgreement> every_reading_agreement;
  /// On a ground-truth scene (truth:NAME): the two checks, then each backend run.
  std::vector<TruthResult> truth;
};

struct BenchReport {
  std::string input_path;
  double load_seconds = 0.0;
  double max_range = 0.0;  ///< infinity: none
  mvog::ModelRules rules;
  double occupancy_threshold = 0.0;
  bool octomap_clamping = true;  ///< RunOptions::octomap_clamping
  double evidence_limit = 0.0;   ///< RunOptions::evidence_limit, as applied (infinity: none)
  int hit_memory_scans = 0;      ///< RunOptions::hit_memory_scans, as applied
  /// RunOptions::hit_memory_scope.
  mvog::HitMemoryScope hit_memory_scope = mvog::HitMemoryScope::kLineScans;
  bool out_of_range = false;  ///< the out-of-range readings were given to MVOG
  int repeat = 1;             ///< insertions per backend; the fastest is reported
  std::vector<ResolutionReport> resolutions;
};

/// The readable tables: per backend and resolution, Table I, MVOG / OctoMap ratios, agreement,
/// MVOG / Bonxai ratios, the ground truth.
void printReport(const BenchReport& report, const InputData& input, std::FILE* out);

/// {"results": [{"backend", "resolution", "readings", "insert_seconds", "readings_per_second",
/// "memory_bytes", "file_bytes", ...}, ...], "input": {...}, "table_one": [...],
/// "comparison": [...], "agreement": [...], "bonxai_comparison": [...], "truth": [...]}, written
/// atomically (temporary file, then rename). Throws std::runtime_error if it cannot be written.
void writeJson(const BenchReport& report, const InputData& input, const std::string& path);

}  // namespace mvog_bench
