#include "mvog_ros/services/map_edit_services.h"

#include <cmath>
#include <cstdio>
#include <mutex>
#include <utility>

#include <tf2_eigen/tf2_eigen.h>
#include <Eigen/Geometry>

#include "mvog/map_io.h"
#include "mvog_ros/frames.h"
#include "mvog_ros/map_paths.h"
#include "mvog_ros/services/query_requests.h"

namespace mvog_ros {
namespace {

/// How far from 1 the norm of map_from_other's quaternion may be (typed in with 4 decimals, 90
/// degrees is (0, 0, 0.7071, 0.7071)): it is normalised, and the grid check that follows is exact.
constexpr double kQuaternionNormTolerance = 1e-3;

/// The axis-aligned box of the map frame that holds the 8 corners of the box [min, max] of a frame
/// at `map_from_frame`. Throws mvog::ConfigError for a box that is not finite or not ordered: an
/// infinite corner turned would make NaNs, and an inverted box would hold its corners all the same.
std::pair<Eigen::Vector3d, Eigen::Vector3d> boxInMapFrame(const Eigen::Vector3d& min,
                                                          const Eigen::Vector3d& max,
                                                          const Eigen::Isometry3d& map_from_frame) {
  if (!(min.allFinite() && max.allFinite() && (min.array() < max.array()).all())) {
    throw mvog::ConfigError(
        "box: in another frame than the map's, the corners must be finite and min_corner below "
        "max_corner on every axis");
  }
  Eigen::AlignedBox3d map_box;
  for (int corner = 0; corner < 8; ++corner) {
    map_box.extend(map_from_frame * Eigen::Vector3d(corner & 1 ? max.x() : min.x(),
                                                    corner & 2 ? max.y() : min.y(),
                                                    corner & 4 ? max.z() : min.z()));
  }
  return {map_box.min(), map_box.max()};
}

/// map_from_other as a transform that keeps the grid (mvog::GridTransform::fromMatrix), for maps
/// of `resolution`. Throws mvog::ConfigError saying why it is refused.
mvog::GridTransform gridTransform(geometry_msgs::Transform map_from_other, double resolution) {
  geometry_msgs::Quaternion& q = map_from_other.rotation;
  const double norm = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
  if (!(std::fabs(norm - 1.0) <= kQuaternionNormTolerance)) {
    char norm_text[32];
    std::snprintf(norm_text, sizeof(norm_text), "%g", norm);
    throw mvog::ConfigError("map_from_other: the rotation is not a unit quaternion (norm " +
                            std::string(norm_text) + "; no rotation is x: 0, y: 0, z: 0, w: 1)");
  }
  q.x /= norm;
  q.y /= norm;
  q.z /= norm;
  q.w /= norm;
  try {
    return mvog::GridTransform::fromMatrix(tf2::transformToEigen(map_from_other).matrix(),
                                           resolution);
  } catch (const mvog::ConfigError& e) {  // "transform: why"
    std::string why = e.what();
    const std::string core_prefix = "transform: ";
    if (why.rfind(core_prefix, 0) == 0) why.erase(0, core_prefix.size());
    throw mvog::ConfigError("map_from_other: " + why);
  }
}

}  // namespace

MapEditServices::MapEditServices(ros::NodeHandle& private_nh, const std::string& frame_id,
                                 double tf_timeout, const std::string& map_directory,
                                 SharedMap& shared_map, const tf2_ros::Buffer& tf_buffer)
    : frame_id_(frame_id),
      tf_timeout_(tf_timeout),
      map_directory_(map_directory),
      map_(shared_map),
      tf_buffer_(tf_buffer),
      clear_box_(private_nh.advertiseService("clear_box", &MapEditServices::clearBox, this)),
      merge_map_(private_nh.advertiseService("merge_map", &MapEditServices::mergeMap, this)) {}

bool MapEditServices::clearBox(mvog::ClearBox::Request& request,
                               mvog::ClearBox::Response& response) {
  try {
    Eigen::Vector3d min = toEigen(request.min_corner);
    Eigen::Vector3d max = toEigen(request.max_corner);
    if (!request.frame_id.empty() && request.frame_id != frame_id_) {
      std::tie(min, max) = boxInMapFrame(
          min, max, latestTransform(tf_buffer_, frame_id_, request.frame_id, tf_timeout_));
    }
    {
      std::unique_lock<WriterPreferringMutex> lock(map_.mutex);
      response.cells_changed = map_.map.clearBox(min, max);
    }
    response.message = "cleared " + std::to_string(response.cells_changed) + " cells";
    response.success = true;
  } catch (const std::exception& e) {  // mvog::ConfigError, TransformUnavailable
    response.message = e.what();
  }
  return true;
}

mvog::Map MapEditServices::otherMap(const mvog::MergeMap::Request& request) const {
  if (request.path.empty())
    return mvog::deserializeMap(request.map.data.data(), request.map.data.size());
  if (!request.map.data.empty()) {
    throw mvog::ConfigError("give a path or a map, not both");
  }
  return mvog::loadMap(resolveMapPath(map_directory_, request.path, false));
}

bool MapEditServices::mergeMap(mvog::MergeMap::Request& request,
                               mvog::MergeMap::Response& response) {
  try {
    // Read and checked whole before the map is touched.
    const mvog::Map other = otherMap(request);
    {
      std::unique_lock<WriterPreferringMutex> lock(map_.mutex);
      map_.map.merge(other, gridTransform(request.map_from_other, map_.map.resolution()));
    }
    response.message = "merged " + std::to_string(other.memoryUsage().cells_with_volumes) +
                       " cells" + (request.path.empty() ? "" : " of '" + request.path + "'");
    response.success = true;
  } catch (const std::exception& e) {  // PathRefused, mvog::MapFileError, mvog::ConfigError
    response.message = e.what();
  }
  return true;
}

}  // namespace mvog_ros
