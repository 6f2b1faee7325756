#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nav_msgs/OccupancyGrid.h>
#include <ros/time.h>
#include <sensor_msgs/PointCloud2.h>
#include <visualization_msgs/MarkerArray.h>

#include "mvog/frontiers.h"
#include "mvog/planning_config.h"
#include "mvog/surfaces.h"

namespace mvog_ros {

// What planners and explorers are published (PlanningPublication, GridPublication's
// traversable map), as messages.

/// Frontier voxels as an unorganized PointCloud2, one point per voxel at its centre: fields x, y,
/// z (float32) and cluster (uint32), the connected piece it belongs to.
sensor_msgs::PointCloud2 frontierCloud(const std::vector<mvog::FrontierPoint>& points,
                                       const std::string& frame_id, const ros::Time& stamp);

/// Frontier voxels for rviz: a DELETEALL, then one CUBE_LIST per cluster (namespace
/// "frontiers", id the cluster's number) of cubes one cell in size, each cluster in a colour of
/// its own (neighbouring numbers far apart on the height colour map).
visualization_msgs::MarkerArray frontierMarkers(const std::vector<mvog::FrontierPoint>& points,
                                                std::uint32_t num_clusters, double resolution,
                                                const std::string& frame_id,
                                                const ros::Time& stamp);

/// Surfaces as an unorganized PointCloud2, one point per surface: fields x, y (the cell's
/// centre), z (the top of occupied space), clearance (the known-free height above it) and
/// probability (eq. 9 just below the top), all float32.
sensor_msgs::PointCloud2 surfaceCloud(const std::vector<mvog::Surface>& surfaces,
                                      const std::string& frame_id, const ros::Time& stamp);

/// The traversable map (mvog::traversableMap) over `cells` as nav_msgs/OccupancyGrid values,
/// computed a row of tiles at a time: the core keeps a list of surfaces per cell while it
/// computes, too much for a whole large grid at once.
nav_msgs::OccupancyGrid::_data_type traversableGridData(const mvog::Map& map,
                                                        const mvog::CellRange& cells,
                                                        const mvog::PlanningConfig& planning);

}  // namespace mvog_ros
