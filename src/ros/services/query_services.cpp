#include "mvog_ros/services/query_services.h"

#include <cmath>
#include <shared_mutex>

#include "mvog_ros/services/query_requests.h"
#include "mvog_ros/visualization.h"

namespace mvog_ros {

QueryServices::QueryServices(ros::NodeHandle& private_nh, const QueryServicesConfig& config,
                             const std::string& frame_id, double occupancy_threshold,
                             int max_cross_section_cells, double max_coordinate,
                             const SharedMap& shared_map, const tf2_ros::Buffer& tf_buffer)
    : config_(config),
      frame_id_(frame_id),
      occupancy_threshold_(occupancy_threshold),
      max_cross_section_cells_(max_cross_section_cells),
      max_coordinate_(max_coordinate),
      map_(shared_map),
      tf_buffer_(tf_buffer),
      get_occupancy_(
          private_nh.advertiseService("get_occupancy", &QueryServices::getOccupancy, this)),
      get_cross_section_(private_nh.advertiseService("get_cross_section",
                                                     &QueryServices::getCrossSection, this)) {}

void QueryServices::setOccupancyThreshold(double occupancy_threshold) {
  occupancy_threshold_ = occupancy_threshold;
}

bool QueryServices::getOccupancy(mvog::GetOccupancy::Request& request,
                                 mvog::GetOccupancy::Response& response) {
  if (!withinMaxQueryPoints(request.points.size(), "points", config_.max_query_points,
                            response.message)) {
    return true;
  }
  const std::optional<Eigen::Isometry3d> map_from_frame = mapFromQueryFrame(
      tf_buffer_, frame_id_, request.frame_id, config_.tf_timeout, response.message);
  if (!map_from_frame) return true;
  response.probability.resize(request.points.size());
  response.state.resize(request.points.size());
  const double occupancy_threshold = occupancy_threshold_;
  std::shared_lock<WriterPreferringMutex> lock(map_.mutex);
  for (std::size_t k = 0; k < request.points.size(); ++k) {
    const mvog::PointOccupancy occupancy =
        map_.map.occupancy(*map_from_frame * toEigen(request.points[k]));
    response.probability[k] = occupancy.probability.value_or(std::nanf(""));
    response.state[k] = static_cast<std::uint8_t>(occupancy.state(occupancy_threshold));
  }
  response.success = true;
  return true;
}

bool QueryServices::getCrossSection(mvog::GetCrossSection::Request& request,
                                    mvog::GetCrossSection::Response& response) {
  if (!std::isfinite(request.height)) {
    response.message = "height must be finite";
    return true;
  }
  std::shared_lock<WriterPreferringMutex> lock(map_.mutex);
  const mvog::Map& map = map_.map;
  mvog::CellRange cells = map.bounds();
  if (request.use_bounds) {
    if (!std::isfinite(request.min_x) || !std::isfinite(request.min_y) ||
        !std::isfinite(request.max_x) || !std::isfinite(request.max_y) ||
        request.min_x > request.max_x || request.min_y > request.max_y ||
        std::fmax(std::fabs(request.min_x), std::fabs(request.max_x)) > max_coordinate_ ||
        std::fmax(std::fabs(request.min_y), std::fabs(request.max_y)) > max_coordinate_) {
      response.message = "bounds must be finite, ordered and within ~max_coordinate";
      return true;
    }
    cells = map.cellsInRectangle(request.min_x, request.min_y, request.max_x, request.max_y);
  }
  if (cells.empty()) {
    response.message = "the map is empty";
    return true;
  }
  if (cells.width() * cells.height() > max_cross_section_cells_) {
    response.message = "refused: the cross-section would have " +
                       std::to_string(cells.width() * cells.height()) +
                       " cells, more than ~max_cross_section_cells";
    return true;
  }
  response.map = toOccupancyGrid(map.crossSection(request.height, cells), request.height, frame_id_,
                                 ros::Time::now());
  response.success = true;
  return true;
}

}  // namespace mvog_ros
