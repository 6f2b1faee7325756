#include "mvog_ros/visualization.h"

#include <algorithm>
#include <cmath>

#include "mvog/column.h"
#include "mvog/height_colour.h"

namespace mvog_ros {
namespace {

constexpr int kMarginTiles = 4;
constexpr double kColourMapTop = 3.0;  // m: occupied space is red at this height and above

std_msgs::ColorRGBA colour(float r, float g, float b, float a) {
  std_msgs::ColorRGBA c;
  c.r = r;
  c.g = g;
  c.b = b;
  c.a = a;
  return c;
}

visualization_msgs::Marker tileMarker(const mvog::TileIndex& tile, const std::string& ns,
                                      const std::string& frame_id, const ros::Time& stamp) {
  visualization_msgs::Marker marker;
  marker.header.frame_id = frame_id;
  marker.header.stamp = stamp;
  marker.ns = ns;
  marker.id = tileMarkerId(tile);
  marker.type = visualization_msgs::Marker::TRIANGLE_LIST;
  marker.pose.orientation.w = 1.0;
  marker.scale.x = marker.scale.y = marker.scale.z = 1.0;
  return marker;
}

/// Appends the 12 triangles of an axis-aligned box.
void appendBox(visualization_msgs::Marker& marker, const Eigen::Vector3d& min,
               const Eigen::Vector3d& max, const std_msgs::ColorRGBA* vertex_colour) {
  auto corner = [&](int k) {
    geometry_msgs::Point p;
    p.x = (k & 1) ? max.x() : min.x();
    p.y = (k & 2) ? max.y() : min.y();
    p.z = (k & 4) ? max.z() : min.z();
    return p;
  };
  // Two triangles per face, corners numbered by their (x, y, z) bits.
  static constexpr int kFaces[6][4] = {{0, 1, 3, 2}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                       {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 3, 7, 5}};
  for (const auto& face : kFaces) {
    for (int k : {face[0], face[1], face[2], face[0], face[2], face[3]}) {
      marker.points.push_back(corner(k));
      if (vertex_colour != nullptr) marker.colors.push_back(*vertex_colour);
    }
  }
}

/// A finished tile marker: ADD with its triangles, or DELETE if it has none.
void appendTileMarker(visualization_msgs::Marker&& marker,
                      visualization_msgs::MarkerArray& markers) {
  marker.action =
      marker.points.empty() ? visualization_msgs::Marker::DELETE : visualization_msgs::Marker::ADD;
  markers.markers.push_back(std::move(marker));
}

}  // namespace

int tileMarkerId(const mvog::TileIndex& tile) {
  // Tiles within +-32767 of the origin map to distinct ids (2^16 tiles of 16 cells per side).
  return static_cast<int>((static_cast<std::uint32_t>(tile.x & 0xffff) << 16) |
                          static_cast<std::uint32_t>(tile.y & 0xffff));
}

void appendVolumeMarkers(const mvog::Map& map, const mvog::TileIndex& tile,
                         const std::string& frame_id, const ros::Time& stamp,
                         visualization_msgs::MarkerArray& markers) {
  visualization_msgs::Marker positive = tileMarker(tile, "positive", frame_id, stamp);
  visualization_msgs::Marker negative = tileMarker(tile, "negative", frame_id, stamp);
  positive.color = colour(0.9f, 0.1f, 0.1f, 0.9f);
  negative.color = colour(0.1f, 0.3f, 0.9f, 0.25f);
  const double r = map.resolution();
  map.forEachVolumeIn(
      mvog::Map::tileCells(tile),
      [&](const mvog::CellIndex& cell, mvog::VolumeSign sign, const mvog::Volume& volume) {
        appendBox(sign == mvog::VolumeSign::kPositive ? positive : negative,
                  {cell.x * r, cell.y * r, volume.bottom * r},
                  {(cell.x + 1) * r, (cell.y + 1) * r, volume.top * r}, nullptr);
      });
  appendTileMarker(std::move(positive), markers);
  appendTileMarker(std::move(negative), markers);
}

void appendOccupiedMarkers(const mvog::Map& map, const mvog::TileIndex& tile,
                           double occupancy_threshold, const std::string& frame_id,
                           const ros::Time& stamp, visualization_msgs::MarkerArray& markers) {
  visualization_msgs::Marker occupied = tileMarker(tile, "occupied", frame_id, stamp);
  occupied.color = colour(1, 1, 1, 1);
  const double r = map.resolution();
  const mvog::CellRange cells = mvog::Map::tileCells(tile);
  for (std::int32_t y = cells.min.y; y <= cells.max.y; ++y) {
    for (std::int32_t x = cells.min.x; x <= cells.max.x; ++x) {
      for (const mvog::ColumnSegment& segment : mvog::columnProfile(map.cellVolumes({x, y}))) {
        if (segment.probability <= occupancy_threshold) continue;
        const mvog::Rgb rgb =
            mvog::heightColour(0.5 * (segment.bottom + segment.top) * r / kColourMapTop);
        const std_msgs::ColorRGBA c = colour(rgb.r, rgb.g, rgb.b, 1);
        appendBox(occupied, {x * r, y * r, segment.bottom * r},
                  {(x + 1) * r, (y + 1) * r, segment.top * r}, &c);
      }
    }
  }
  appendTileMarker(std::move(occupied), markers);
}

visualization_msgs::Marker deleteAllMarker(const std::string& frame_id, const ros::Time& stamp) {
  visualization_msgs::Marker marker;
  marker.header.frame_id = frame_id;
  marker.header.stamp = stamp;
  marker.action = visualization_msgs::Marker::DELETEALL;
  marker.pose.orientation.w = 1.0;
  return marker;
}

std::int8_t gridValue(float probability) {
  if (std::isnan(probability)) return -1;
  return static_cast<std::int8_t>(std::lround(std::clamp(probability, 0.0f, 1.0f) * 100.0f));
}

std::int8_t gridValue(mvog::OccupancyState state) {
  switch (state) {
    case mvog::OccupancyState::kOccupied:
      return 100;
    case mvog::OccupancyState::kFree:
      return 0;
    case mvog::OccupancyState::kUnknown:
      break;
  }
  return -1;
}

std::int8_t gridValue(mvog::Traversability traversability) {
  return static_cast<std::int8_t>(traversability);  // its values are those of OccupancyGrid
}

template <class T>
nav_msgs::OccupancyGrid toOccupancyGrid(const mvog::Grid2D<T>& grid, double z,
                                        const std::string& frame_id, const ros::Time& stamp) {
  nav_msgs::OccupancyGrid message;
  message.header.frame_id = frame_id;
  message.header.stamp = stamp;
  message.info.map_load_time = stamp;
  message.info.resolution = static_cast<float>(grid.resolution);
  message.info.width = static_cast<std::uint32_t>(grid.width());
  message.info.height = static_cast<std::uint32_t>(grid.height());
  message.info.origin.position.x = grid.originX();
  message.info.origin.position.y = grid.originY();
  message.info.origin.position.z = z;
  message.info.origin.orientation.w = 1.0;
  message.data.resize(grid.values.size());
  std::transform(grid.values.begin(), grid.values.end(), message.data.begin(),
                 [](const T& value) { return gridValue(value); });
  return message;
}
template nav_msgs::OccupancyGrid toOccupancyGrid(const mvog::CrossSection&, double,
                                                 const std::string&, const ros::Time&);
template nav_msgs::OccupancyGrid toOccupancyGrid(const mvog::Projection&, double,
                                                 const std::string&, const ros::Time&);
template nav_msgs::OccupancyGrid toOccupancyGrid(const mvog::TraversableMap&, double,
                                                 const std::string&, const ros::Time&);

mvog::CellRange IncrementalGrid::update(const mvog::Map& map,
                                        const std::vector<mvog::TileIndex>& changed,
                                        bool& relaid_out) {
  relaid_out = false;
  const mvog::CellRange bounds = map.bounds();
  if (bounds.empty() && cells_.empty()) return kNoCells;
  // A map emptied (forgetting, ~clear_box) keeps its layout: its removed tiles become unknown.
  if (cells_.empty() ||
      (!bounds.empty() && (!cells_.contains(bounds.min) || !cells_.contains(bounds.max)))) {
    // Re-lay out over whole tiles around the bounds plus a margin, and evaluate it all.
    const mvog::TileIndex low = mvog::Map::tileOf(bounds.min);
    const mvog::TileIndex high = mvog::Map::tileOf(bounds.max);
    const mvog::CellRange layout{
        mvog::Map::tileCells({low.x - kMarginTiles, low.y - kMarginTiles}).min,
        mvog::Map::tileCells({high.x + kMarginTiles, high.y + kMarginTiles}).max};
    if (layout.width() * layout.height() > max_cells_) {
      clear();
      throw GridTooLarge("the map's extent needs " + std::to_string(layout.width()) + " x " +
                         std::to_string(layout.height()) + " cells");
    }
    cells_ = layout;
    grid_.info.resolution = static_cast<float>(map.resolution());
    grid_.info.width = static_cast<std::uint32_t>(cells_.width());
    grid_.info.height = static_cast<std::uint32_t>(cells_.height());
    grid_.info.origin.position.x = cells_.min.x * map.resolution();
    grid_.info.origin.position.y = cells_.min.y * map.resolution();
    grid_.info.origin.position.z = z_;
    grid_.info.origin.orientation.w = 1.0;
    grid_.data.assign(static_cast<std::size_t>(cells_.width() * cells_.height()), -1);
    write(cells_, compute_(map, cells_));
    relaid_out = true;
    return cells_;
  }
  mvog::CellRange touched = kNoCells;
  for (const mvog::TileIndex& tile : changed) {
    const mvog::CellRange cells = mvog::Map::tileCells(tile);
    // The grid covers whole tiles: one that begins outside it (a tile the map removed, beyond a
    // layout that moved with the map's bounds) lies wholly outside.
    if (!cells_.contains(cells.min)) continue;
    write(cells, compute_(map, cells));
    touched =
        touched.empty()
            ? cells
            : mvog::CellRange{
                  {std::min(touched.min.x, cells.min.x), std::min(touched.min.y, cells.min.y)},
                  {std::max(touched.max.x, cells.max.x), std::max(touched.max.y, cells.max.y)}};
  }
  return touched;
}

void IncrementalGrid::write(const mvog::CellRange& cells,
                            const nav_msgs::OccupancyGrid::_data_type& values) {
  for (std::int64_t row = 0; row < cells.height(); ++row) {
    std::copy_n(values.begin() + row * cells.width(), cells.width(),
                grid_.data.begin() + indexOf(cells.min.x, cells.min.y + row));
  }
}

std::ptrdiff_t IncrementalGrid::indexOf(std::int64_t x, std::int64_t y) const {
  return (y - cells_.min.y) * cells_.width() + (x - cells_.min.x);
}

map_msgs::OccupancyGridUpdate IncrementalGrid::updateOf(const mvog::CellRange& cells) const {
  map_msgs::OccupancyGridUpdate update;
  update.header = grid_.header;
  update.x = static_cast<std::int32_t>(cells.min.x - cells_.min.x);
  update.y = static_cast<std::int32_t>(cells.min.y - cells_.min.y);
  update.width = static_cast<std::uint32_t>(cells.width());
  update.height = static_cast<std::uint32_t>(cells.height());
  update.data.reserve(static_cast<std::size_t>(cells.width() * cells.height()));
  for (std::int64_t row = 0; row < cells.height(); ++row) {
    const auto start = grid_.data.begin() + indexOf(cells.min.x, cells.min.y + row);
    update.data.insert(update.data.end(), start, start + cells.width());
  }
  return update;
}

}  // namespace mvog_ros
