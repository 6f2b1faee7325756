#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "mvog/map.h"

namespace mvog_bench {

/// An input file that cannot be used; the message says what is wrong.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Every scan of an input file, read into memory before anything is timed.
///
/// Both backends see exactly these rays: each scan's origin and its obstacle readings (hits) in
/// the map frame, single precision. Out-of-range readings are kept aside: disregarded by
/// default, as in the paper's Table I ("Out-of-range sensor readings present in the experiments
/// are disregarded in all four representations"), so `Scan::out_of_range` is always empty;
/// given to MVOG alone with mvog_bench --out-of-range-free-length.
struct InputData {
  std::string format;  ///< "bag", "graph", "synthetic" or "truth"
  std::vector<mvog::Scan> scans;
  /// The out-of-range readings of each scan (at the sensor's range_max).
  std::vector<std::vector<Eigen::Vector3f>> out_of_range;
  /// LaserScan, PointCloud2 and depth Image messages, graph nodes, or synthetic scans
  std::size_t sensor_messages = 0;
  std::size_t without_transform = 0;      ///< messages skipped: no transform to the fixed frame
  std::size_t without_camera_info = 0;    ///< depth images skipped: no camera info of their stamp
  std::size_t invalid_messages = 0;       ///< messages skipped: malformed
  std::size_t out_of_range_readings = 0;  ///< +Inf / beyond range_max (in out_of_range)
  std::size_t skipped_beams = 0;          ///< NaN, -Inf or below range_min: no information
  std::size_t skipped_pixels = 0;         ///< depth pixels 0, NaN, -Inf: no information
  std::size_t non_finite_points = 0;      ///< cloud points with a NaN or infinite coordinate

  /// Obstacle readings over all scans.
  std::size_t readings() const;
};

/// What names a synthetic input instead of a file: "synthetic:NAME" (loadSynthetic).
constexpr std::string_view kSyntheticPrefix = "synthetic:";

/// Reads a ROS bag (by its "#ROSBAG V2.0" header) or an OctoMap ScanGraph (.graph), or makes the
/// synthetic input "synthetic:NAME" or the ground-truth scene's "truth:NAME" (truth.h).
/// `depth_no_return_length`: where the out-of-range readings of a bag's depth images end (m;
/// infinite: their +Inf pixels are skipped). Throws InputError for a missing, unreadable,
/// truncated or unusable file.
InputData loadInput(const std::string& path, const std::string& fixed_frame,
                    double depth_no_return_length);

/// Every LaserScan, PointCloud2 and depth image (Image of encoding 16UC1 or 32FC1, with the
/// CameraInfo of its stamp on the sibling `camera_info` topic) of the bag, with each message's
/// pose looked up in a tf2 buffer holding every /tf and /tf_static message of the bag. Images of
/// other encodings (colour, mono) are not range data and are not read.
InputData loadBag(const std::string& path, const std::string& fixed_frame,
                  double depth_no_return_length);

/// The scans of a sensor that none of the shared recordings has, cast into a scene built in code
/// (mvog_scene), by `name`: "rotating-lidar-16" (a Velodyne VLP-16, 16 beams from -15 to +15
/// degrees, 0.2 degrees apart in azimuth) and "rotating-lidar-32" (an HDL-32E, 32 beams from
/// -30.67 to +10.67 degrees), each 1.8 m up on 10 turns 2 m apart along a street (100 m range);
/// "tilting-laser" (181 beams over 180 degrees, nodding from -45 to +45 degrees a degree at a
/// time), 0.5 m up on 10 poses across an office (30 m range). Beams that meet nothing within
/// range are out-of-range readings. Throws InputError for an unknown name.
InputData loadSynthetic(const std::string& name);

/// The scans of a sensor cast into a scene (`format` "synthetic" or "truth"), their
/// out-of-range readings put aside.
InputData inputOfScans(const std::string& format, std::vector<mvog::Scan> scans);

/// Every node of an OctoMap ScanGraph binary file, parsed with every count checked against the
/// file size first (a truncated or corrupt file is an error, never a partial graph).
InputData loadScanGraph(const std::string& path);

}  // namespace mvog_bench
