#include "mvog_ros/services/query_requests.h"

#include "mvog_ros/frames.h"

namespace mvog_ros {

bool withinMaxQueryPoints(std::size_t count, const char* what, int max_query_points,
                          std::string& refusal) {
  if (count <= static_cast<std::size_t>(max_query_points)) return true;
  refusal = "refused: " + std::to_string(count) + " " + what + " exceed ~max_query_points (" +
            std::to_string(max_query_points) + ")";
  return false;
}

std::optional<Eigen::Isometry3d> mapFromQueryFrame(const tf2_ros::Buffer& tf_buffer,
                                                   const std::string& map_frame,
                                                   const std::string& frame_id, double timeout,
                                                   std::string& refusal) {
  if (frame_id.empty() || frame_id == map_frame) return Eigen::Isometry3d::Identity();
  try {
    return latestTransform(tf_buffer, map_frame, frame_id, timeout);
  } catch (const TransformUnavailable& e) {
    refusal = e.what();
    return std::nullopt;
  }
}

}  // namespace mvog_ros
