#include "report.h"

#include <unistd.h>

#include <array>
#include <cinttypes>
#include <cmath>
#include <fstream>
#include <stdexcept>
#include <utility>

namespace mvog_bench {
namespace {

constexpr std::size_t kPointCloudBytesPerPoint = 12;  // Table I: 3 single-precision floats
constexpr std::size_t kVoxelBytes = 4;                // Table I: one single-precision float

const char* const kStateNames[] = {"unknown", "free", "occupied"};

double perSecond(std::size_t readings, double seconds) {
  return seconds > 0.0 ? static_cast<double>(readings) / seconds : 0.0;
}

double ratio(double numerator, double denominator) {
  return denominator > 0.0 ? numerator / denominator : std::nan("");
}

std::string hex(std::uint64_t value) {
  char text[19];
  std::snprintf(text, sizeof(text), "%016" PRIx64, value);
  return text;
}

/// A JSON object built key by key, rendered on one line (values are rendered when added).
class JsonObject {
 public:
  JsonObject& add(const std::string& key, double value) {
    if (!std::isfinite(value)) return raw(key, "null");
    char text[32];
    std::snprintf(text, sizeof(text), "%.9g", value);
    return raw(key, text);
  }
  JsonObject& add(const std::string& key, std::size_t value) {
    return raw(key, std::to_string(value));
  }
  JsonObject& add(const std::string& key, int value) { return raw(key, std::to_string(value)); }
  JsonObject& add(const std::string& key, bool value) { return raw(key, value ? "true" : "false"); }
  JsonObject& add(const std::string& key, const std::string& value) {
    return raw(key, quote(value));
  }
  JsonObject& add(const std::string& key, const char* value) { return raw(key, quote(value)); }
  JsonObject& add(const std::string& key, const JsonObject& value) { return raw(key, value.str()); }
  /// An array of objects, one per line, indented for a top-level object.
  JsonObject& add(const std::string& key, const std::vector<JsonObject>& values) {
    std::string text = "[";
    for (std::size_t k = 0; k < values.size(); ++k) {
      text += (k == 0 ? "\n    " : ",\n    ") + values[k].str();
    }
    return raw(key, text + (values.empty() ? "]" : "\n  ]"));
  }
  JsonObject& raw(const std::string& key, const std::string& json) {
    entries_.emplace_back(key, json);
    return *this;
  }
  /// On one line.
  std::string str() const { return render("{", ", ", "}"); }
  /// One key per line, for a top-level object.
  std::string pretty() const { return render("{\n  ", ",\n  ", "\n}\n"); }

 private:
  static std::string quote(const std::string& text) {
    std::string quoted = "\"";
    for (const char c : text) {
      if (c == '"' || c == '\\') {
        quoted += '\\';
        quoted += c;
      } else if (static_cast<unsigned char>(c) < 0x20) {
        char escaped[7];
        std::snprintf(escaped, sizeof(escaped), "\\u%04x", c);
        quoted += escaped;
      } else {
        quoted += c;
      }
    }
    return quoted + "\"";
  }

  std::string render(const char* open, const char* separator, const char* close) const {
    std::string text = open;
    for (std::size_t k = 0; k < entries_.size(); ++k) {
      text += (k == 0 ? "" : separator) + quote(entries_[k].first) + ": " + entries_[k].second;
    }
    return text + close;
  }

  std::vector<std::pair<std::string, std::string>> entries_;
};

/// The keys every backend's result starts with.
JsonObject resultJson(const char* backend, double resolution, std::size_t readings,
                      double insert_seconds) {
  JsonObject o;
  o.add("backend", backend)
      .add("resolution", resolution)
      .add("readings", readings)
      .add("insert_seconds", insert_seconds)
      .add("readings_per_second", perSecond(readings, insert_seconds));
  return o;
}

/// An MVOG run's figures as `backend` ("mvog", or "mvog_every_reading": every reading's ray).
JsonObject mvogJson(const char* backend, double resolution, std::size_t readings,
                    const MvogStats& s) {
  JsonObject o = resultJson(backend, resolution, readings, s.insert_seconds);
  o.add("memory_bytes", s.memory.bytes_held)
      .add("file_bytes", s.file_bytes)
      .add("threads", s.threads)
      .add("table_one_bytes", s.memory.table_one_bytes)
      .add("minimal_grid_cells", s.memory.minimal_grid_cells)
      .add("cells_with_volumes", s.memory.cells_with_volumes)
      .add("positive_volumes", s.memory.positive_volumes)
      .add("negative_volumes", s.memory.negative_volumes)
      .add("tiles", s.memory.tiles)
      .add("rays_walked", s.insertion.rays_walked)
      .add("obstacle_readings", s.insertion.obstacle_readings)
      .add("truncated_to_max_range", s.insertion.truncated_to_max_range)
      .add("rejected_readings", s.insertion.rejected())
      .add("map_checksum", hex(s.checksum));
  return o;
}

JsonObject octomapJson(double resolution, std::size_t readings, const OctomapStats& s) {
  JsonObject o = resultJson("octomap", resolution, readings, s.insert_seconds);
  o.add("memory_bytes", s.memory_bytes)
      .add("file_bytes", s.binary_file_bytes)
      .add("threads", 1)
      .add("full_file_bytes", s.full_file_bytes)
      .add("tree_nodes", s.tree_nodes)
      .add("leaf_nodes", s.leaf_nodes);
  return o;
}

JsonObject bonxaiJson(double resolution, std::size_t readings, const BonxaiStats& s) {
  JsonObject o = resultJson("bonxai", resolution, readings, s.insert_seconds);
  o.add("memory_bytes", s.memory_bytes).add("threads", 1).add("active_cells", s.active_cells);
  return o;
}

/// Each backend's name and its quality at one resolution (empty: not run).
std::array<std::pair<const char*, const std::optional<Quality>*>, 3> qualities(
    const ResolutionReport& r) {
  return {
      {{"mvog", &r.mvog_quality}, {"octomap", &r.octomap_quality}, {"bonxai", &r.bonxai_quality}}};
}

/// MVOG's speed and memory over Bonxai's: readings per second, bytes held.
std::pair<double, double> mvogOverBonxai(const MvogStats& mvog, const BonxaiStats& bonxai) {
  return {
      ratio(bonxai.insert_seconds, mvog.insert_seconds),
      ratio(static_cast<double>(mvog.memory.bytes_held), static_cast<double>(bonxai.memory_bytes))};
}

JsonObject agreementJson(const StateAgreement& a) {
  std::string matrix = "{";
  for (std::size_t m = 0; m < 3; ++m) {
    matrix += std::string(m == 0 ? "" : ", ") + "\"" + kStateNames[m] + "\": {";
    for (std::size_t o = 0; o < 3; ++o) {
      matrix += std::string(o == 0 ? "" : ", ") + "\"" + kStateNames[o] +
                "\": " + std::to_string(a.counts[m][o]);
    }
    matrix += "}";
  }
  JsonObject o;
  o.add("points", a.points())
      .add("agreeing", a.agreeing())
      .add("fraction", ratio(static_cast<double>(a.agreeing()), static_cast<double>(a.points())))
      .raw("mvog_vs_octomap", matrix + "}");
  return o;
}

std::string megabytes(double bytes) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.3f MB", bytes / 1e6);
  return text;
}

std::string optionalMegabytes(bool present, std::size_t bytes) {
  return present ? megabytes(static_cast<double>(bytes)) : "-";
}

std::string percent(const StateAgreement& a) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.1f %%",
                100.0 * ratio(static_cast<double>(a.agreeing()), static_cast<double>(a.points())));
  return text;
}

std::string rulesText(const mvog::ModelRules& rules) {
  return std::string("clip_free_space_at_hits ") + (rules.clip_free_space_at_hits ? "on" : "off") +
         ", mass_counting " +
         (rules.mass_counting == mvog::MassCounting::kPerScan ? "per-scan" : "per-reading") +
         ", split_free_space_at_obstacles " + (rules.split_free_space_at_obstacles ? "on" : "off") +
         ", out_of_range_free_length " +
         (std::isinf(rules.out_of_range_free_length)
              ? std::string("inf")
              : std::to_string(rules.out_of_range_free_length).substr(0, 5) + " m");
}

const char* hitMemoryScopeText(mvog::HitMemoryScope scope) {
  return scope == mvog::HitMemoryScope::kLineScans ? "line scans" : "every scan";
}

/// A map's scores at the labelled points: shares of the points in the state each label calls
/// right (and the two errors a planner pays for), and the F1 of "occupied".
JsonObject truthJson(double resolution, const TruthResult& result) {
  const TruthScores& t = result.scores;
  using mvog::OccupancyState;
  JsonObject o;
  o.add("backend", result.backend)
      .add("resolution", resolution)
      .add("surface_occupied", TruthScores::share(t.surface, OccupancyState::kOccupied))
      .add("surface_free", TruthScores::share(t.surface, OccupancyState::kFree))
      .add("thin_occupied", TruthScores::share(t.thin, OccupancyState::kOccupied))
      .add("free_near_surface_free", TruthScores::share(t.free_near_surface, OccupancyState::kFree))
      .add("free_near_surface_occupied",
           TruthScores::share(t.free_near_surface, OccupancyState::kOccupied))
      .add("free_far_free", TruthScores::share(t.free_far_from_surfaces, OccupancyState::kFree))
      .add("free_under_overhang_free",
           TruthScores::share(t.free_under_overhang, OccupancyState::kFree))
      .add("free_under_overhang_occupied",
           TruthScores::share(t.free_under_overhang, OccupancyState::kOccupied))
      .add("unobserved_unknown", TruthScores::share(t.unobserved, OccupancyState::kUnknown))
      .add("occupancy_f1", t.occupancyF1())
      .add("surface_points", t.surface.points())
      .add("thin_points", t.thin.points())
      .add("free_near_surface_points", t.free_near_surface.points())
      .add("free_far_points", t.free_far_from_surfaces.points())
      .add("free_under_overhang_points", t.free_under_overhang.points())
      .add("unobserved_points", t.unobserved.points());
  return o;
}

}  // namespace

void printReport(const BenchReport& report, const InputData& input, std::FILE* out) {
  const std::size_t readings = input.readings();
  std::fprintf(out, "input       %s (%s), loaded in %.2f s\n", report.input_path.c_str(),
               input.format.c_str(), report.load_seconds);
  std::fprintf(out,
               "readings    %zu obstacle readings in %zu scans (of %zu sensor messages); "
               "out-of-range: %zu (%s); disregarded: %zu invalid beams, %zu invalid pixels, "
               "%zu non-finite points; skipped messages: %zu without transform, %zu without "
               "camera info, %zu malformed\n",
               readings, input.scans.size(), input.sensor_messages, input.out_of_range_readings,
               report.out_of_range ? "given to MVOG only" : "disregarded by every backend",
               input.skipped_beams, input.skipped_pixels, input.non_finite_points,
               input.without_transform, input.without_camera_info, input.invalid_messages);
  if (std::isfinite(report.max_range)) {
    std::fprintf(out, "max range   %.2f m\n", report.max_range);
  } else {
    std::fprintf(out, "max range   none\n");
  }
  std::fprintf(out,
               "MVOG rules  %s%s; occupied where p > %.3f; evidence limit %g; hit memory %d "
               "scans (%s)\n",
               rulesText(report.rules).c_str(),
               report.rules == mvog::ModelRules::paper() ? " (the paper's model)" : "",
               report.occupancy_threshold, report.evidence_limit, report.hit_memory_scans,
               hitMemoryScopeText(report.hit_memory_scope));
  std::fprintf(out, "OctoMap     log-odds clamping %s\n\n",
               report.octomap_clamping ? "on (its default)" : "off");

  if (report.repeat > 1) {
    std::fprintf(out, "timings     the fastest of %d insertions per backend\n\n", report.repeat);
  }
  std::fprintf(out, "%-8s %7s %7s %10s %10s %12s %14s %14s %14s\n", "backend", "res (m)", "threads",
               "readings", "insert (s)", "readings/s", "memory (B)", "file (B)", ".ot file (B)");
  for (const ResolutionReport& r : report.resolutions) {
    if (r.mvog) {
      std::fprintf(out, "%-8s %7.3f %7d %10zu %10.3f %12.0f %14zu %14zu %14s\n", "mvog",
                   r.resolution, r.mvog->threads, readings, r.mvog->insert_seconds,
                   perSecond(readings, r.mvog->insert_seconds), r.mvog->memory.bytes_held,
                   r.mvog->file_bytes, "-");
    }
    if (r.every_reading) {
      std::fprintf(out, "%-8s %7.3f %7d %10zu %10.3f %12.0f %14zu %14zu %14s\n", "mvog-all",
                   r.resolution, r.every_reading->threads, readings,
                   r.every_reading->insert_seconds,
                   perSecond(readings, r.every_reading->insert_seconds),
                   r.every_reading->memory.bytes_held, r.every_reading->file_bytes, "-");
    }
    if (r.octomap) {
      std::fprintf(out, "%-8s %7.3f %7d %10zu %10.3f %12.0f %14zu %14zu %14zu\n", "octomap",
                   r.resolution, 1, readings, r.octomap->insert_seconds,
                   perSecond(readings, r.octomap->insert_seconds), r.octomap->memory_bytes,
                   r.octomap->binary_file_bytes, r.octomap->full_file_bytes);
    }
    if (r.bonxai) {
      std::fprintf(out, "%-8s %7.3f %7d %10zu %10.3f %12.0f %14zu %14s %14s\n", "bonxai",
                   r.resolution, 1, readings, r.bonxai->insert_seconds,
                   perSecond(readings, r.bonxai->insert_seconds), r.bonxai->memory_bytes, "-", "-");
    }
    if (r.walk) {
      std::fprintf(out, "%-8s %7.3f %7d %10zu %10.3f %12.0f %14s %14s %14s\n", "walk", r.resolution,
                   1, readings, r.walk->insert_seconds, perSecond(readings, r.walk->insert_seconds),
                   "-", "-", "-");
    }
  }

  bool quality_header = false;
  for (const ResolutionReport& r : report.resolutions) {
    for (const auto& [name, quality] : qualities(r)) {
      if (!*quality) continue;
      if (!quality_header) {
        std::fprintf(out,
                     "\nQuality (%% of the sample points): ray ends called occupied, points along "
                     "the rays called free, points far from every ray called unknown\n"
                     "%-8s %7s %12s %12s %12s %10s %10s\n",
                     "backend", "res (m)", "ends occ.", "along free", "far unknown", "rays",
                     "far points");
        quality_header = true;
      }
      const Quality& q = **quality;
      std::fprintf(out, "%-8s %7.3f %11.1f%% %11.1f%% %11.1f%% %10zu %10zu\n", name, r.resolution,
                   q.endpoints.percent(mvog::OccupancyState::kOccupied),
                   q.along_rays.percent(mvog::OccupancyState::kFree),
                   q.far_from_data.percent(mvog::OccupancyState::kUnknown), q.endpoints.points(),
                   q.far_from_data.points());
    }
  }

  bool truth_header = false;
  for (const ResolutionReport& r : report.resolutions) {
    for (const TruthResult& result : r.truth) {
      using mvog::OccupancyState;
      const TruthScores& t = result.scores;
      if (!truth_header) {
        std::fprintf(out,
                     "\nGround truth (shares of the labelled points; oracle and endpoints-only "
                     "check the labels): surface called occupied, called free; thin objects "
                     "occupied; free space called free near surfaces (occupied), far from them, "
                     "under overhangs (occupied); unobserved called unknown; F1 of occupied\n"
                     "%-13s %7s %8s %8s %8s %8s %8s %8s %8s %8s %8s %8s\n",
                     "backend", "res (m)", "surf occ", "surf fr", "thin occ", "near fr", "near occ",
                     "far fr", "under fr", "under oc", "unobs un", "F1");
        truth_header = true;
      }
      std::fprintf(out, "%-13s %7.3f %8.3f %8.3f %8.3f %8.3f %8.3f %8.3f %8.3f %8.3f %8.3f %8.3f\n",
                   result.backend.c_str(), r.resolution,
                   TruthScores::share(t.surface, OccupancyState::kOccupied),
                   TruthScores::share(t.surface, OccupancyState::kFree),
                   TruthScores::share(t.thin, OccupancyState::kOccupied),
                   TruthScores::share(t.free_near_surface, OccupancyState::kFree),
                   TruthScores::share(t.free_near_surface, OccupancyState::kOccupied),
                   TruthScores::share(t.free_far_from_surfaces, OccupancyState::kFree),
                   TruthScores::share(t.free_under_overhang, OccupancyState::kFree),
                   TruthScores::share(t.free_under_overhang, OccupancyState::kOccupied),
                   TruthScores::share(t.unobserved, OccupancyState::kUnknown), t.occupancyF1());
    }
    if (!r.truth.empty()) {
      const TruthScores& t = r.truth.front().scores;
      std::fprintf(out,
                   "%-13s %7.3f labelled points: %zu surface (%zu thin), %zu free near surfaces, "
                   "%zu far, %zu under overhangs, %zu unobserved\n",
                   "", r.resolution, t.surface.points(), t.thin.points(),
                   t.free_near_surface.points(), t.free_far_from_surfaces.points(),
                   t.free_under_overhang.points(), t.unobserved.points());
    }
  }

  std::fprintf(out, "\nTable I (single precision; out-of-range readings disregarded)\n");
  std::fprintf(out, "%7s %14s %14s %14s %14s\n", "res (m)", "point cloud", "voxel grid", "OctoMap",
               "MVOG");
  for (const ResolutionReport& r : report.resolutions) {
    std::fprintf(
        out, "%7.3f %14s %14s %14s %14s\n", r.resolution,
        megabytes(static_cast<double>(readings * kPointCloudBytesPerPoint)).c_str(),
        megabytes(static_cast<double>(r.voxel_grid_cells) * kVoxelBytes).c_str(),
        optionalMegabytes(r.octomap.has_value(), r.octomap ? r.octomap->memory_bytes : 0).c_str(),
        optionalMegabytes(r.mvog.has_value(), r.mvog ? r.mvog->memory.table_one_bytes : 0).c_str());
  }

  bool walk_header = false;
  for (const ResolutionReport& r : report.resolutions) {
    if (!r.mvog || !r.walk) continue;
    if (!walk_header) {
      std::fprintf(out, "\nMVOG / the bare walk\n%7s %12s %14s\n", "res (m)", "time",
                   "cell visits");
      walk_header = true;
    }
    std::fprintf(out, "%7.3f %11.2fx %14zu\n", r.resolution,
                 ratio(r.mvog->insert_seconds, r.walk->insert_seconds), r.walk->cell_visits);
  }

  bool every_reading_header = false;
  for (const ResolutionReport& r : report.resolutions) {
    if (!r.mvog || !r.every_reading_agreement) continue;
    if (!every_reading_header) {
      std::fprintf(
          out,
          "\nMVOG / mvog-all (every reading's ray walked): rays walked, time, memory held; "
          "agreement (%% of the points in the same state): endpoints, along rays, within "
          "%.0f cells of the ends\n%7s %12s %12s %12s   %s\n",
          kNearEndCells, "res (m)", "rays", "time", "memory", "agreement");
      every_reading_header = true;
    }
    const EveryReadingAgreement& a = *r.every_reading_agreement;
    std::fprintf(out, "%7.3f %11.3fx %11.3fx %11.3fx   %s, %s, %s\n", r.resolution,
                 ratio(static_cast<double>(r.mvog->insertion.rays_walked),
                       static_cast<double>(r.every_reading->insertion.rays_walked)),
                 ratio(r.mvog->insert_seconds, r.every_reading->insert_seconds),
                 ratio(static_cast<double>(r.mvog->memory.bytes_held),
                       static_cast<double>(r.every_reading->memory.bytes_held)),
                 percent(a.endpoints).c_str(), percent(a.along_rays).c_str(),
                 percent(a.near_ends).c_str());
  }

  bool header = false;
  for (const ResolutionReport& r : report.resolutions) {
    if (!r.mvog || !r.octomap) continue;
    if (!header) {
      std::fprintf(out, "\nMVOG / OctoMap\n%7s %12s %14s %14s %12s   %s\n", "res (m)", "readings/s",
                   "memory held", "Table I", "file",
                   "agreement: endpoints, along rays (sampled rays)");
      header = true;
    }
    std::fprintf(out, "%7.3f %11.2fx %13.3fx %13.3fx %11.3fx   %s, %s (%zu)\n", r.resolution,
                 ratio(r.octomap->insert_seconds, r.mvog->insert_seconds),
                 ratio(static_cast<double>(r.mvog->memory.bytes_held),
                       static_cast<double>(r.octomap->memory_bytes)),
                 ratio(static_cast<double>(r.mvog->memory.table_one_bytes),
                       static_cast<double>(r.octomap->memory_bytes)),
                 ratio(static_cast<double>(r.mvog->file_bytes),
                       static_cast<double>(r.octomap->binary_file_bytes)),
                 percent(r.agreement->endpoints).c_str(), percent(r.agreement->along_rays).c_str(),
                 r.agreement->sampled_rays);
  }

  bool bonxai_header = false;
  for (const ResolutionReport& r : report.resolutions) {
    if (!r.mvog || !r.bonxai) continue;
    if (!bonxai_header) {
      std::fprintf(out, "\nMVOG / Bonxai\n%7s %12s %14s\n", "res (m)", "readings/s", "memory held");
      bonxai_header = true;
    }
    const auto [speed, memory] = mvogOverBonxai(*r.mvog, *r.bonxai);
    std::fprintf(out, "%7.3f %11.2fx %13.3fx\n", r.resolution, speed, memory);
  }
}

void writeJson(const BenchReport& report, const InputData& input, const std::string& path) {
  const std::size_t readings = input.readings();
  std::vector<JsonObject> results, table_one, comparison, agreement, quality, bonxai_comparison,
      every_reading_agreement, truth;
  for (const ResolutionReport& r : report.resolutions) {
    if (r.mvog) results.push_back(mvogJson("mvog", r.resolution, readings, *r.mvog));
    if (r.octomap) results.push_back(octomapJson(r.resolution, readings, *r.octomap));
    if (r.bonxai) results.push_back(bonxaiJson(r.resolution, readings, *r.bonxai));
    if (r.every_reading) {
      results.push_back(mvogJson("mvog_every_reading", r.resolution, readings, *r.every_reading));
    }
    if (r.every_reading_agreement) {
      JsonObject sampled;
      sampled.add("resolution", r.resolution)
          .add("endpoints", agreementJson(r.every_reading_agreement->endpoints))
          .add("along_rays", agreementJson(r.every_reading_agreement->along_rays))
          .add("near_ends", agreementJson(r.every_reading_agreement->near_ends));
      every_reading_agreement.push_back(sampled);
    }
    if (r.walk) {
      JsonObject walk = resultJson("walk", r.resolution, readings, r.walk->insert_seconds);
      walk.add("cell_visits", r.walk->cell_visits);
      if (r.mvog)
        walk.add("mvog_time_ratio", ratio(r.mvog->insert_seconds, r.walk->insert_seconds));
      results.push_back(walk);
    }
    for (const auto& [name, q] : qualities(r)) {
      if (!*q) continue;
      JsonObject row;
      row.add("backend", name)
          .add("resolution", r.resolution)
          .add("endpoints_occupied_percent",
               (*q)->endpoints.percent(mvog::OccupancyState::kOccupied))
          .add("endpoints_free_percent", (*q)->endpoints.percent(mvog::OccupancyState::kFree))
          .add("along_rays_free_percent", (*q)->along_rays.percent(mvog::OccupancyState::kFree))
          .add("along_rays_occupied_percent",
               (*q)->along_rays.percent(mvog::OccupancyState::kOccupied))
          .add("far_unknown_percent", (*q)->far_from_data.percent(mvog::OccupancyState::kUnknown))
          .add("endpoints", (*q)->endpoints.points())
          .add("far_points", (*q)->far_from_data.points());
      quality.push_back(row);
    }
    for (const TruthResult& result : r.truth) truth.push_back(truthJson(r.resolution, result));
    JsonObject row;
    row.add("resolution", r.resolution)
        .add("point_cloud_bytes", readings * kPointCloudBytesPerPoint)
        .add("voxel_grid_cells", r.voxel_grid_cells)
        .add("voxel_grid_bytes", r.voxel_grid_cells * kVoxelBytes);
    if (r.octomap) row.add("octomap_bytes", r.octomap->memory_bytes);
    if (r.mvog) row.add("mvog_bytes", r.mvog->memory.table_one_bytes);
    table_one.push_back(row);
    if (r.mvog && r.bonxai) {
      const auto [speed, memory] = mvogOverBonxai(*r.mvog, *r.bonxai);
      JsonObject ratios;
      ratios.add("resolution", r.resolution)
          .add("readings_per_second_ratio", speed)
          .add("memory_ratio", memory);
      bonxai_comparison.push_back(ratios);
    }
    if (!r.mvog || !r.octomap) continue;
    JsonObject ratios;
    ratios.add("resolution", r.resolution)
        .add("readings_per_second_ratio", ratio(r.octomap->insert_seconds, r.mvog->insert_seconds))
        .add("memory_ratio", ratio(static_cast<double>(r.mvog->memory.bytes_held),
                                   static_cast<double>(r.octomap->memory_bytes)))
        .add("table_one_ratio", ratio(static_cast<double>(r.mvog->memory.table_one_bytes),
                                      static_cast<double>(r.octomap->memory_bytes)))
        .add("file_ratio", ratio(static_cast<double>(r.mvog->file_bytes),
                                 static_cast<double>(r.octomap->binary_file_bytes)));
    comparison.push_back(ratios);
    JsonObject sampled;
    sampled.add("resolution", r.resolution)
        .add("sampled_rays", r.agreement->sampled_rays)
        .add("endpoints", agreementJson(r.agreement->endpoints))
        .add("along_rays", agreementJson(r.agreement->along_rays));
    agreement.push_back(sampled);
  }
  JsonObject input_json;
  input_json.add("path", report.input_path)
      .add("format", input.format)
      .add("sensor_messages", input.sensor_messages)
      .add("scans", input.scans.size())
      .add("readings", readings)
      .add("out_of_range_disregarded", input.out_of_range_readings)
      .add("invalid_beams", input.skipped_beams)
      .add("invalid_pixels", input.skipped_pixels)
      .add("non_finite_points", input.non_finite_points)
      .add("messages_without_transform", input.without_transform)
      .add("messages_without_camera_info", input.without_camera_info)
      .add("malformed_messages", input.invalid_messages)
      .add("load_seconds", report.load_seconds);
  JsonObject document;
  document.add("results", results)
      .add("input", input_json)
      .add("max_range", report.max_range)
      .add("rules", rulesText(report.rules))
      .add("out_of_range_to_mvog", report.out_of_range)
      .add("occupancy_threshold", report.occupancy_threshold)
      .add("octomap_clamping", report.octomap_clamping)
      .add("evidence_limit", report.evidence_limit)
      .add("hit_memory_scans", report.hit_memory_scans)
      .add("hit_memory_scope", std::string(hitMemoryScopeText(report.hit_memory_scope)))
      .add("repeat", report.repeat)
      .add("table_one", table_one)
      .add("quality", quality)
      .add("comparison", comparison)
      .add("agreement", agreement)
      .add("bonxai_comparison", bonxai_comparison)
      .add("every_reading_agreement", every_reading_agreement)
      .add("truth", truth);

  const std::string temporary = path + ".tmp." + std::to_string(::getpid());
  {
    std::ofstream file(temporary, std::ios::trunc);
    file << document.pretty();
    file.close();
    if (!file) {
      std::remove(temporary.c_str());
      throw std::runtime_error(path + ": cannot write the JSON report");
    }
  }
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    std::remove(temporary.c_str());
    throw std::runtime_error(path + ": cannot rename the JSON report into place");
  }
}

}  // namespace mvog_bench
