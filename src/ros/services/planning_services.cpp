#include "mvog_ros/services/planning_services.h"

#include <shared_mutex>
#include <vector>

#include "mvog_ros/services/query_requests.h"

namespace mvog_ros {
namespace {

/// A refusal of the core (mvog::ConfigError) as a message; the core names max_query_cells as
/// the field, which is the parameter ~max_query_cells.
std::string refusalOf(const mvog::ConfigError& e) {
  const std::string what = e.what();
  return std::string("refused: ") + (what.rfind("max_query_cells", 0) == 0 ? "~" : "") + what;
}

}  // namespace

PlanningServices::PlanningServices(ros::NodeHandle& private_nh, const QueryServicesConfig& config,
                                   const mvog::PlanningConfig& planning,
                                   const std::string& frame_id, const SharedMap& shared_map,
                                   const tf2_ros::Buffer& tf_buffer)
    : config_(config),
      planning_(planning),
      frame_id_(frame_id),
      map_(shared_map),
      tf_buffer_(tf_buffer),
      checker_(planning),
      check_segments_(
          private_nh.advertiseService("check_segments", &PlanningServices::checkSegments, this)),
      check_boxes_(
          private_nh.advertiseService("check_boxes", &PlanningServices::checkBoxes, this)) {}

void PlanningServices::setPlanning(const mvog::PlanningConfig& planning) {
  std::lock_guard<std::mutex> checker_lock(checker_mutex_);
  planning_ = planning;
  // What the checker found of open space followed the old threshold.
  checker_ = mvog::SegmentChecker(planning);
}

std::optional<Eigen::Isometry3d> PlanningServices::acceptRequest(
    const std::string& frame_id, std::size_t count, std::size_t other_count, const char* what,
    const char* lists, std::string& refusal) const {
  if (!withinMaxQueryPoints(count, what, config_.max_query_points, refusal)) return std::nullopt;
  if (count != other_count) {
    refusal = std::string("refused: ") + lists + " differ in length (" + std::to_string(count) +
              " and " + std::to_string(other_count) + ")";
    return std::nullopt;
  }
  return mapFromQueryFrame(tf_buffer_, frame_id_, frame_id, config_.tf_timeout, refusal);
}

bool PlanningServices::checkSegments(mvog::CheckSegments::Request& request,
                                     mvog::CheckSegments::Response& response) {
  const std::optional<Eigen::Isometry3d> map_from_frame =
      acceptRequest(request.frame_id, request.starts.size(), request.ends.size(), "segments",
                    "starts and ends", response.message);
  if (!map_from_frame) return true;
  std::vector<mvog::Segment> segments;
  segments.reserve(request.starts.size());
  for (std::size_t k = 0; k < request.starts.size(); ++k) {
    segments.push_back(
        {*map_from_frame * toEigen(request.starts[k]), *map_from_frame * toEigen(request.ends[k])});
  }
  std::vector<mvog::SegmentCheck> checks;
  try {
    std::lock_guard<std::mutex> checker_lock(checker_mutex_);
    std::shared_lock<WriterPreferringMutex> lock(map_.mutex);
    if (map_.generation != checker_generation_) {
      checker_.clear();
      checker_generation_ = map_.generation;
    }
    checks = checker_.check(map_.map, segments, request.radius);
  } catch (const mvog::ConfigError& e) {
    response.message = refusalOf(e);
    return true;
  }
  response.state.reserve(checks.size());
  response.blocked_at.reserve(checks.size());
  for (const mvog::SegmentCheck& check : checks) {
    response.state.push_back(static_cast<std::uint8_t>(check.state));
    response.blocked_at.push_back(check.blocked_at);
  }
  response.success = true;
  return true;
}

bool PlanningServices::checkBoxes(mvog::CheckBoxes::Request& request,
                                  mvog::CheckBoxes::Response& response) {
  const std::optional<Eigen::Isometry3d> map_from_frame =
      acceptRequest(request.frame_id, request.min_corners.size(), request.max_corners.size(),
                    "boxes", "min_corners and max_corners", response.message);
  if (!map_from_frame) return true;
  std::vector<mvog::Box> boxes;
  boxes.reserve(request.min_corners.size());
  for (std::size_t k = 0; k < request.min_corners.size(); ++k) {
    const Eigen::AlignedBox3d box(toEigen(request.min_corners[k]), toEigen(request.max_corners[k]));
    if ((box.min().array() > box.max().array()).any()) {
      response.message = "refused: box " + std::to_string(k) +
                         ": its min corner lies above its max corner along an axis";
      return true;
    }
    // In another frame: the smallest box axis-aligned in the map frame that holds the box (the
    // box itself where the frames differ by a translation and quarter turns about z). Eigen's
    // transformed() keeps a NaN corner NaN, for the core to refuse.
    const Eigen::AlignedBox3d in_map = map_from_frame->matrix() == Eigen::Matrix4d::Identity()
                                           ? box
                                           : box.transformed(*map_from_frame);
    boxes.push_back({in_map.min(), in_map.max()});
  }
  std::vector<mvog::BoxCheck> checks;
  try {
    mvog::PlanningConfig planning;
    {
      std::lock_guard<std::mutex> checker_lock(checker_mutex_);
      planning = planning_;
    }
    std::shared_lock<WriterPreferringMutex> lock(map_.mutex);
    checks = mvog::checkBoxes(map_.map, boxes, planning);
  } catch (const mvog::ConfigError& e) {
    response.message = refusalOf(e);
    return true;
  }
  for (const mvog::BoxCheck& check : checks) {
    response.state.push_back(static_cast<std::uint8_t>(check.state));
    response.known_fraction.push_back(check.known_fraction);
    response.max_probability.push_back(check.max_probability);
  }
  response.success = true;
  return true;
}

}  // namespace mvog_ros
