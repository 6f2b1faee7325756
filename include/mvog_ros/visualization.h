#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include <map_msgs/OccupancyGridUpdate.h>
#include <nav_msgs/OccupancyGrid.h>
#include <visualization_msgs/MarkerArray.h>

#include "mvog/map.h"
#include "mvog/surfaces.h"

namespace mvog_ros {

/// Marker ids are per tile, so that a tile's markers are replaced when it changes (and only
/// then): publication costs what changed, not the whole map.
int tileMarkerId(const mvog::TileIndex& tile);

/// The volumes of one tile as two TRIANGLE_LIST boxes markers: namespace "positive" (red) and
/// "negative" (blue) (Fig. 4, middle). An empty list becomes a DELETE of that tile's marker.
void appendVolumeMarkers(const mvog::Map& map, const mvog::TileIndex& tile,
                         const std::string& frame_id, const ros::Time& stamp,
                         visualization_msgs::MarkerArray& markers);

/// The space of one tile with p > occupancy_threshold as boxes coloured by height (Fig. 4,
/// right), namespace "occupied".
void appendOccupiedMarkers(const mvog::Map& map, const mvog::TileIndex& tile,
                           double occupancy_threshold, const std::string& frame_id,
                           const ros::Time& stamp, visualization_msgs::MarkerArray& markers);

/// A marker that clears every marker of the topic (after a reset or a load).
visualization_msgs::Marker deleteAllMarker(const std::string& frame_id, const ros::Time& stamp);

/// The occupancy grid value of a probability (0..100) or of unknown (-1).
std::int8_t gridValue(float probability);
std::int8_t gridValue(mvog::OccupancyState state);
std::int8_t gridValue(mvog::Traversability traversability);

/// A nav_msgs/OccupancyGrid of a core grid, at height `z` (the grid's origin height).
template <class T>
nav_msgs::OccupancyGrid toOccupancyGrid(const mvog::Grid2D<T>& grid, double z,
                                        const std::string& frame_id, const ros::Time& stamp);

/// Thrown by IncrementalGrid::update when the map has outgrown the largest grid allowed.
class GridTooLarge : public std::length_error {
 public:
  using std::length_error::length_error;
};

/// A 2D layer of the map (the projected map or one cross-section) kept up to date tile by tile.
/// It covers whole tiles around the map's bounds, with a margin so that a growing map seldom
/// makes it re-lay itself out.
class IncrementalGrid {
 public:
  /// compute(map, cells) evaluates the layer over a range of cells.
  using Compute =
      std::function<nav_msgs::OccupancyGrid::_data_type(const mvog::Map&, const mvog::CellRange&)>;
  /// A grid of at most max_cells cells.
  IncrementalGrid(double z, std::int64_t max_cells, Compute compute)
      : z_(z), max_cells_(max_cells), compute_(std::move(compute)) {}

  /// Brings the grid up to date with the tiles changed since the last update (those outside the
  /// grid are passed over). Returns the rectangle that changed (for an OccupancyGridUpdate), or
  /// the whole grid after a re-layout.
  /// Throws GridTooLarge (and forgets the grid) if the map's bounds need more than max_cells.
  mvog::CellRange update(const mvog::Map& map, const std::vector<mvog::TileIndex>& changed,
                         bool& relaid_out);
  /// Forgets the grid and its layout: the next update lays it out afresh.
  void clear() {
    grid_ = nav_msgs::OccupancyGrid();
    cells_ = kNoCells;
  }
  const nav_msgs::OccupancyGrid& grid() const { return grid_; }
  /// The part of the grid over `cells` as an update message.
  map_msgs::OccupancyGridUpdate updateOf(const mvog::CellRange& cells) const;
  mvog::CellRange cells() const { return cells_; }

 private:
  void write(const mvog::CellRange& cells, const nav_msgs::OccupancyGrid::_data_type& values);
  /// Index in the grid's data of cell (x, y).
  std::ptrdiff_t indexOf(std::int64_t x, std::int64_t y) const;

  double z_;
  std::int64_t max_cells_;
  Compute compute_;
  nav_msgs::OccupancyGrid grid_;
  static constexpr mvog::CellRange kNoCells{{0, 0}, {-1, -1}};

  mvog::CellRange cells_ = kNoCells;
};

}  // namespace mvog_ros
