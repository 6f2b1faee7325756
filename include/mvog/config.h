#pragma once

#include <limits>
#include <stdexcept>
#include <string>

namespace mvog {

/// Thrown by a config's validate() and by Map for invalid arguments; the message names the field.
class ConfigError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// The map itself.
struct MapConfig {
  /// Edge of a square cell in metres; s = 1 / resolution (Sec. III-A).
  double resolution = 0.1;
  /// Readings whose origin or end lies further than this from the map origin along any axis (m)
  /// are rejected, so that a wild point cannot make the map grow without bound (Sec. V.A).
  double max_coordinate = 10000.0;

  /// Throws ConfigError naming the first invalid field.
  void validate() const;
};

/// How readings are turned into volumes (Sec. III-B).
struct InsertionConfig {
  /// Obstacle readings closer than this to the sensor (m) are dropped.
  double min_range = 0.0;
  /// Obstacle readings further than this (m) become out-of-range readings truncated to it, and
  /// out-of-range readings are truncated to it too.
  double max_range = std::numeric_limits<double>::infinity();
  /// Whether out-of-range readings add free space (Sec. III-B.1); if false they are ignored.
  bool insert_out_of_range = true;
  /// Whether negative (free-space) volumes are created at all.
  bool model_negative_space = true;
  /// Sec. V.B remedy: within one scan, a negative volume that overlaps a positive volume created
  /// by the same scan in the same cell is not inserted.
  bool clear_conflicting_free_space = false;
  /// Threads used by Map::insertScan; the resulting map is identical for any count.
  int insertion_threads = 1;

  /// Throws ConfigError naming the first invalid field.
  void validate() const;
};

}  // namespace mvog
