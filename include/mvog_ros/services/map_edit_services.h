#pragma once

#include <string>

#include <ros/ros.h>
#include <tf2_ros/buffer.h>

#include "mvog/ClearBox.h"
#include "mvog/MergeMap.h"
#include "mvog/map.h"
#include "mvog_ros/mapper_config.h"
#include "mvog_ros/shared_map.h"

namespace mvog_ros {

/// ~clear_box (mvog/ClearBox: a box becomes unknown) and ~merge_map (mvog/MergeMap: another map
/// added into this one, from a file in ~map_directory or a MapBinary). Both write the map under
/// its lock; a refused request leaves it untouched and says why. The outputs follow by
/// themselves (the tiles modified or removed are published: ChangePublication).
class MapEditServices {
 public:
  /// `tf_timeout`: s to wait for the transform of a box's frame.
  MapEditServices(ros::NodeHandle& private_nh, const std::string& frame_id, double tf_timeout,
                  const std::string& map_directory, SharedMap& shared_map,
                  const tf2_ros::Buffer& tf_buffer);

 private:
  bool clearBox(mvog::ClearBox::Request& request, mvog::ClearBox::Response& response);
  bool mergeMap(mvog::MergeMap::Request& request, mvog::MergeMap::Response& response);
  /// The map a MergeMap request gives (its file or its bytes). Throws PathRefused,
  /// mvog::MapFileError or mvog::ConfigError.
  mvog::Map otherMap(const mvog::MergeMap::Request& request) const;

  const std::string frame_id_;
  const double tf_timeout_;
  const std::string map_directory_;
  SharedMap& map_;
  const tf2_ros::Buffer& tf_buffer_;
  ros::ServiceServer clear_box_;
  ros::ServiceServer merge_map_;
};

}  // namespace mvog_ros
