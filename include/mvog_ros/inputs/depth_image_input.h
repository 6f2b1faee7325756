#pragma once

#include <atomic>
#include <deque>
#include <mutex>
#include <string>

#include <image_transport/image_transport.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include "mvog/depth_image.h"
#include "mvog_ros/inputs/sensor_input.h"

namespace mvog_ros {

/// A depth image topic (sensor_msgs/Image through image_transport, REP-118) with its camera info
/// on the sibling topic `camera_info` (image_transport's CameraSubscriber convention), paired by
/// exact stamp as CameraSubscriber pairs them, converted by depthImageToScan. CameraSubscriber
/// itself is not used: its synchroniser drops an image whose camera info never comes without
/// telling, and the server counts such images (messages_dropped_camera_info).
class DepthImageInput : public SensorInput {
 public:
  /// `no_return_length`: where the rays of +Inf pixels end (DepthImageConfig).
  DepthImageInput(ros::NodeHandle& nh, const std::string& topic, const SensorInputContext& context,
                  double no_return_length);
  ~DepthImageInput() override;

  void stop() override;
  /// ~max_range changed (RuntimeReconfigure): the next image converted uses `no_return_length`.
  void setNoReturnLength(double no_return_length) { no_return_length_ = no_return_length; }

  /// Converts `image` with its camera info and the camera's pose and enqueues it; an invalid
  /// pair is dropped, counted.
  void convertAndEnqueue(const sensor_msgs::ImageConstPtr& image,
                         const sensor_msgs::CameraInfo& camera_info,
                         const Eigen::Isometry3d& map_from_camera);

 private:
  void receiveImage(const sensor_msgs::ImageConstPtr& image);
  void receiveCameraInfo(const sensor_msgs::CameraInfoConstPtr& camera_info);
  /// A paired image waits for its transform like any message (SensorInput::receive).
  void receivePair(const sensor_msgs::ImageConstPtr& image,
                   const sensor_msgs::CameraInfoConstPtr& camera_info);

  const int stride_;                      // ~depth_stride
  std::atomic<double> no_return_length_;  // DepthImageConfig's, read once per image
  std::mutex pairing_mutex_;
  // Up to ~sensor_queue_size each, oldest first: images waiting for the camera info of their
  // stamp (the oldest is dropped and counted beyond), and the latest camera infos.
  std::deque<sensor_msgs::ImageConstPtr> unpaired_images_;
  std::deque<sensor_msgs::CameraInfoConstPtr> camera_infos_;
  image_transport::ImageTransport image_transport_;
  image_transport::Subscriber image_subscriber_;
  ros::Subscriber camera_info_subscriber_;
};

}  // namespace mvog_ros
