#include "mvog_ros/publications/planning_publication.h"

#include <shared_mutex>

#include <sensor_msgs/PointCloud2.h>
#include <visualization_msgs/MarkerArray.h>

#include "mvog_ros/planning_messages.h"
#include "mvog_ros/visualization.h"

namespace mvog_ros {

PlanningPublication::PlanningPublication(ros::NodeHandle& private_nh,
                                         const PublicationsConfig& config,
                                         const mvog::PlanningConfig& planning,
                                         const std::string& frame_id, const SharedMap& shared_map)
    : ChangePublication(shared_map),
      frame_id_(frame_id),
      frontiers_(planning),
      surfaces_(planning) {
  auto advertise = [&](auto message_type, const std::string& topic, Output output) {
    return private_nh.advertise<decltype(message_type)>(
        topic, 1,
        [this, output](const ros::SingleSubscriberPublisher& subscriber) {
          send(subscriber, output);
        },
        ros::SubscriberStatusCallback(), ros::VoidConstPtr(), true);
  };
  frontiers_publisher_ = advertise(sensor_msgs::PointCloud2(), "frontiers", Output::kFrontiers);
  frontier_markers_publisher_ =
      advertise(visualization_msgs::MarkerArray(), "frontier_markers", Output::kFrontierMarkers);
  surfaces_publisher_ = advertise(sensor_msgs::PointCloud2(), "surfaces", Output::kSurfaces);
  start(private_nh, config.publish_period);
}

PlanningPublication::~PlanningPublication() { stop(); }

void PlanningPublication::reconfigure(double publish_period, const mvog::PlanningConfig& planning) {
  ChangePublication::reconfigure(publish_period, [&] {
    frontiers_ = mvog::Frontiers(planning);
    surfaces_ = mvog::Surfaces(planning);
  });
}

void PlanningPublication::clearPublished() {
  frontiers_.clear();
  surfaces_.clear();
  const ros::Time stamp = ros::Time::now();
  frontiers_publisher_.publish(frontierCloud({}, frame_id_, stamp));
  visualization_msgs::MarkerArray clear;
  clear.markers.push_back(deleteAllMarker(frame_id_, stamp));
  frontier_markers_publisher_.publish(clear);
  surfaces_publisher_.publish(surfaceCloud({}, frame_id_, stamp));
}

void PlanningPublication::publishTiles(const std::vector<mvog::TileIndex>&) {
  const ros::Time stamp = ros::Time::now();
  if (frontiers_publisher_.getNumSubscribers() + frontier_markers_publisher_.getNumSubscribers() >
      0) {
    bringUpToDate(frontiers_, frontiers_unpublished_);
    if (frontiers_unpublished_) publishFrontiers(stamp);
    frontiers_unpublished_ = false;
  }
  if (surfaces_publisher_.getNumSubscribers() > 0) {
    bringUpToDate(surfaces_, surfaces_unpublished_);
    if (surfaces_unpublished_) {
      surfaces_publisher_.publish(surfaceCloud(surfaces_.surfaces(), frame_id_, stamp));
    }
    surfaces_unpublished_ = false;
  }
}

template <class Results>
void PlanningPublication::bringUpToDate(Results& results, bool& unpublished) {
  results.update(map_.map);
  if (results.tilesRecomputed() > 0) unpublished = true;
}

void PlanningPublication::publishFrontiers(const ros::Time& stamp) {
  if (frontiers_publisher_.getNumSubscribers() > 0) {
    frontiers_publisher_.publish(frontierCloud(frontiers_.points(), frame_id_, stamp));
  }
  if (frontier_markers_publisher_.getNumSubscribers() > 0) {
    frontier_markers_publisher_.publish(frontierMarkers(
        frontiers_.points(), frontiers_.numClusters(), map_.map.resolution(), frame_id_, stamp));
  }
}

void PlanningPublication::send(const ros::SingleSubscriberPublisher& subscriber, Output output) {
  std::lock_guard<std::mutex> publication_lock(mutex_);
  std::shared_lock<WriterPreferringMutex> lock(map_.mutex);
  restartIfReplacedLocked();
  const ros::Time stamp = ros::Time::now();
  switch (output) {
    case Output::kFrontiers:
      bringUpToDate(frontiers_, frontiers_unpublished_);
      subscriber.publish(frontierCloud(frontiers_.points(), frame_id_, stamp));
      break;
    case Output::kFrontierMarkers:
      bringUpToDate(frontiers_, frontiers_unpublished_);
      subscriber.publish(frontierMarkers(frontiers_.points(), frontiers_.numClusters(),
                                         map_.map.resolution(), frame_id_, stamp));
      break;
    case Output::kSurfaces:
      bringUpToDate(surfaces_, surfaces_unpublished_);
      subscriber.publish(surfaceCloud(surfaces_.surfaces(), frame_id_, stamp));
      break;
  }
}

}  // namespace mvog_ros
