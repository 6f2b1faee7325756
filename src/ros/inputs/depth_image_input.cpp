#include "mvog_ros/inputs/depth_image_input.h"

#include <utility>
#include <vector>

#include <image_transport/camera_common.h>

#include "mvog_ros/conversions.h"

namespace mvog_ros {

DepthImageInput::DepthImageInput(ros::NodeHandle& nh, const std::string& topic,
                                 const SensorInputContext& context, double no_return_length)
    : SensorInput(nh, context),
      stride_(context.config.depth_stride),
      no_return_length_(no_return_length),
      image_transport_(nh) {
  const auto queue_size = static_cast<std::uint32_t>(context.config.sensor_queue_size);
  image_subscriber_ =
      image_transport_.subscribe(topic, queue_size, &DepthImageInput::receiveImage, this);
  camera_info_subscriber_ = nh.subscribe(image_transport::getCameraInfoTopic(nh.resolveName(topic)),
                                         queue_size, &DepthImageInput::receiveCameraInfo, this);
}

DepthImageInput::~DepthImageInput() { stop(); }

void DepthImageInput::stop() {
  image_subscriber_.shutdown();
  camera_info_subscriber_.shutdown();
  SensorInput::stop();
}

void DepthImageInput::receiveImage(const sensor_msgs::ImageConstPtr& image) {
  sensor_msgs::CameraInfoConstPtr camera_info;
  {
    std::lock_guard<std::mutex> lock(pairing_mutex_);
    for (auto info = camera_infos_.rbegin(); info != camera_infos_.rend(); ++info) {
      if ((*info)->header.stamp == image->header.stamp) {
        camera_info = *info;
        break;
      }
    }
    if (camera_info == nullptr) {
      unpaired_images_.push_back(image);
      if (unpaired_images_.size() > static_cast<std::size_t>(context_.config.sensor_queue_size)) {
        const std_msgs::Header& dropped = unpaired_images_.front()->header;
        ++context_.counters.messages_dropped_camera_info;
        ROS_WARN_THROTTLE(
            kWarningPeriod,
            "mvog: dropped a depth image from frame '%s' at %.3f: no camera info of its stamp on "
            "'%s' before ~sensor_queue_size newer images (%llu so far)",
            dropped.frame_id.c_str(), dropped.stamp.toSec(),
            camera_info_subscriber_.getTopic().c_str(),
            static_cast<unsigned long long>(context_.counters.messages_dropped_camera_info.load()));
        unpaired_images_.pop_front();
      }
      return;
    }
  }
  receivePair(image, camera_info);
}

void DepthImageInput::receiveCameraInfo(const sensor_msgs::CameraInfoConstPtr& camera_info) {
  std::vector<sensor_msgs::ImageConstPtr> paired;
  {
    std::lock_guard<std::mutex> lock(pairing_mutex_);
    camera_infos_.push_back(camera_info);
    if (camera_infos_.size() > static_cast<std::size_t>(context_.config.sensor_queue_size)) {
      camera_infos_.pop_front();
    }
    for (auto image = unpaired_images_.begin(); image != unpaired_images_.end();) {
      if ((*image)->header.stamp == camera_info->header.stamp) {
        paired.push_back(*image);
        image = unpaired_images_.erase(image);
      } else {
        ++image;
      }
    }
  }
  for (const sensor_msgs::ImageConstPtr& image : paired) receivePair(image, camera_info);
}

void DepthImageInput::receivePair(const sensor_msgs::ImageConstPtr& image,
                                  const sensor_msgs::CameraInfoConstPtr& camera_info) {
  receive(image->header, [this, image, camera_info](const Eigen::Isometry3d& map_from_camera) {
    convertAndEnqueue(image, *camera_info, map_from_camera);
  });
}

void DepthImageInput::convertAndEnqueue(const sensor_msgs::ImageConstPtr& image,
                                        const sensor_msgs::CameraInfo& camera_info,
                                        const Eigen::Isometry3d& map_from_camera) {
  // Checked here and inserted straight from its pixels (mvog::Map::insertDepthImage), which the
  // insertion counts: no cloud of every pixel in between.
  enqueueConverted("depth image", [&](std::size_t&) {
    const mvog::DepthImageConfig config{stride_, no_return_length_.load()};
    return DepthImageReadings{
        image, depthFrameOf(*image, camera_info, map_from_camera, config,
                            static_cast<std::size_t>(context_.config.max_points_per_message))};
  });
}

}  // namespace mvog_ros
