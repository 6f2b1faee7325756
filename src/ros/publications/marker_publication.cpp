#include "mvog_ros/publications/marker_publication.h"

#include <shared_mutex>

#include <visualization_msgs/MarkerArray.h>

#include "mvog_ros/visualization.h"

namespace mvog_ros {

MarkerPublication::MarkerPublication(ros::NodeHandle& private_nh, const PublicationsConfig& config,
                                     const std::string& frame_id, double occupancy_threshold,
                                     const SharedMap& shared_map)
    : ChangePublication(shared_map),
      frame_id_(frame_id),
      occupancy_threshold_(occupancy_threshold) {
  auto advertise = [&](const std::string& topic, bool occupied_only) {
    return private_nh.advertise<visualization_msgs::MarkerArray>(
        topic, 1,
        [this, occupied_only](const ros::SingleSubscriberPublisher& subscriber) {
          sendAll(subscriber, occupied_only);
        },
        ros::SubscriberStatusCallback(), ros::VoidConstPtr(), true);
  };
  volumes_publisher_ = advertise("volumes", false);
  occupied_publisher_ = advertise("occupied", true);
  start(private_nh, config.publish_period);
}

MarkerPublication::~MarkerPublication() { stop(); }

void MarkerPublication::reconfigure(double publish_period, double occupancy_threshold) {
  ChangePublication::reconfigure(publish_period,
                                 [&] { occupancy_threshold_ = occupancy_threshold; });
}

void MarkerPublication::clearPublished() {
  visualization_msgs::MarkerArray clear;
  clear.markers.push_back(deleteAllMarker(frame_id_, ros::Time::now()));
  volumes_publisher_.publish(clear);
  occupied_publisher_.publish(clear);
}

void MarkerPublication::publishTiles(const std::vector<mvog::TileIndex>& changed) {
  const bool volumes_wanted = volumes_publisher_.getNumSubscribers() > 0;
  const bool occupied_wanted = occupied_publisher_.getNumSubscribers() > 0;
  if (!volumes_wanted && !occupied_wanted) return;
  const ros::Time stamp = ros::Time::now();
  visualization_msgs::MarkerArray volumes;
  visualization_msgs::MarkerArray occupied;
  for (const mvog::TileIndex& tile : changed) {
    if (volumes_wanted) appendVolumeMarkers(map_.map, tile, frame_id_, stamp, volumes);
    if (occupied_wanted) {
      appendOccupiedMarkers(map_.map, tile, occupancy_threshold_, frame_id_, stamp, occupied);
    }
  }
  if (!volumes.markers.empty()) volumes_publisher_.publish(volumes);
  if (!occupied.markers.empty()) occupied_publisher_.publish(occupied);
}

void MarkerPublication::sendAll(const ros::SingleSubscriberPublisher& subscriber,
                                bool occupied_only) {
  std::lock_guard<std::mutex> publication_lock(mutex_);
  std::shared_lock<WriterPreferringMutex> lock(map_.mutex);
  const ros::Time stamp = ros::Time::now();
  visualization_msgs::MarkerArray markers;
  markers.markers.push_back(deleteAllMarker(frame_id_, stamp));
  for (const mvog::TileIndex& tile : map_.map.tilesModifiedSince(0)) {
    if (occupied_only) {
      appendOccupiedMarkers(map_.map, tile, occupancy_threshold_, frame_id_, stamp, markers);
    } else {
      appendVolumeMarkers(map_.map, tile, frame_id_, stamp, markers);
    }
  }
  subscriber.publish(markers);
}

}  // namespace mvog_ros
