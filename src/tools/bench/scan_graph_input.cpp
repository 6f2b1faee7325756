// OctoMap ScanGraph binary files (octomap::ScanGraph::writeBinary), little-endian, no padding:
//   uint32 n_nodes
//   n_nodes x { uint32 n_points, n_points x (int32 3, float64 x, y, z),
//               pose: (int32 3, float64 tx, ty, tz), (int32 4, float64 qw, qx, qy, qz),
//               uint32 id }
//   uint32 n_edges
//   n_edges x { uint32 first_id, uint32 second_id, pose as above, float64 weight }
// Points are in the node's sensor frame; p_world = R(q) p + t, and the sensor origin is t.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>

#include <Eigen/Geometry>

#include "input.h"

namespace mvog_bench {
namespace {

constexpr std::size_t kPointBytes = 4 + 3 * 8;
constexpr std::size_t kPoseBytes = (4 + 3 * 8) + (4 + 4 * 8);
constexpr std::size_t kNodeBytesWithoutPoints = 4 + kPoseBytes + 4;
constexpr std::size_t kEdgeBytes = 4 + 4 + kPoseBytes + 8;

/// Reads little-endian values from a buffer, throwing InputError past its end.
class Reader {
 public:
  Reader(const std::vector<char>& data, const std::string& path) : data_(data), path_(path) {}

  std::size_t remaining() const { return data_.size() - offset_; }
  void require(std::size_t bytes, const char* what) const {
    if (bytes > remaining()) {
      throw InputError(path_ + ": truncated ScanGraph file: " + what + " needs " +
                       std::to_string(bytes) + " bytes at offset " + std::to_string(offset_) +
                       ", only " + std::to_string(remaining()) + " left");
    }
  }
  std::uint32_t u32(const char* what) {
    require(4, what);
    std::uint32_t value = 0;
    for (int k = 0; k < 4; ++k) {
      value |= std::uint32_t{static_cast<std::uint8_t>(data_[offset_ + k])} << (8 * k);
    }
    offset_ += 4;
    return value;
  }
  double f64(const char* what) {
    require(8, what);
    std::uint64_t bits = 0;
    for (int k = 0; k < 8; ++k) {
      bits |= std::uint64_t{static_cast<std::uint8_t>(data_[offset_ + k])} << (8 * k);
    }
    offset_ += 8;
    double value;
    std::memcpy(&value, &bits, 8);
    return value;
  }
  /// A vector of `size` float64 values preceded by its int32 length, which must be `size`.
  void vector(double* values, std::uint32_t size, const char* what) {
    const std::uint32_t stored = u32(what);
    if (stored != size) {
      throw InputError(path_ + ": corrupt ScanGraph file: " + what + " has length " +
                       std::to_string(stored) + " at offset " + std::to_string(offset_ - 4) +
                       ", expected " + std::to_string(size));
    }
    for (std::uint32_t k = 0; k < size; ++k) values[k] = f64(what);
  }

 private:
  const std::vector<char>& data_;
  const std::string& path_;
  std::size_t offset_ = 0;
};

std::vector<char> readFile(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError(path + ": cannot open the file");
  std::vector<char> data((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  if (file.bad()) throw InputError(path + ": read error");
  return data;
}

}  // namespace

InputData loadScanGraph(const std::string& path) {
  const std::vector<char> data = readFile(path);
  Reader reader(data, path);
  InputData input;
  input.format = "graph";
  const std::uint32_t num_nodes = reader.u32("the node count");
  reader.require(std::size_t{num_nodes} * kNodeBytesWithoutPoints, "the nodes");
  input.scans.reserve(num_nodes);
  for (std::uint32_t node = 0; node < num_nodes; ++node) {
    const std::uint32_t num_points = reader.u32("a node's point count");
    reader.require(std::size_t{num_points} * kPointBytes, "a node's points");
    std::vector<Eigen::Vector3d> points(num_points);
    for (Eigen::Vector3d& point : points) reader.vector(point.data(), 3, "a point");
    double translation[3];
    double rotation[4];  // w, x, y, z
    reader.vector(translation, 3, "a pose's translation");
    reader.vector(rotation, 4, "a pose's rotation");
    reader.u32("a node's id");
    const Eigen::Quaterniond q(rotation[0], rotation[1], rotation[2], rotation[3]);
    if (!(q.norm() > 0.0) || !std::isfinite(q.norm()) ||
        !Eigen::Vector3d(translation[0], translation[1], translation[2]).allFinite()) {
      throw InputError(path + ": corrupt ScanGraph file: node " + std::to_string(node) +
                       " has a non-finite pose or a zero rotation quaternion");
    }
    const Eigen::Isometry3d world_from_sensor =
        Eigen::Translation3d(translation[0], translation[1], translation[2]) * q.normalized();
    mvog::Scan scan;
    // Both backends take single-precision points; the origin is rounded the same way.
    scan.origin = world_from_sensor.translation().cast<float>().cast<double>();
    scan.hits.reserve(points.size());
    for (const Eigen::Vector3d& point : points) {
      if (!point.allFinite()) {
        ++input.non_finite_points;
        continue;
      }
      scan.hits.push_back((world_from_sensor * point).cast<float>());
    }
    input.scans.push_back(std::move(scan));
    input.out_of_range.emplace_back();  // a scan graph holds hits only
    ++input.sensor_messages;
  }
  const std::uint32_t num_edges = reader.u32("the edge count");
  if (reader.remaining() != std::size_t{num_edges} * kEdgeBytes) {
    throw InputError(path + ": corrupt ScanGraph file: " + std::to_string(num_edges) +
                     " edges need " + std::to_string(std::size_t{num_edges} * kEdgeBytes) +
                     " bytes, " + std::to_string(reader.remaining()) + " left");
  }
  if (input.scans.empty()) throw InputError(path + ": the ScanGraph has no nodes");
  return input;
}

}  // namespace mvog_bench
