#include "mvog_ros/inputs/sensor_inputs.h"

#include <utility>

#include "mvog_ros/inputs/depth_image_input.h"
#include "mvog_ros/inputs/laser_scan_input.h"
#include "mvog_ros/inputs/point_cloud_input.h"

namespace mvog_ros {

SensorInputs::SensorInputs(ros::NodeHandle nh, const SensorInputsConfig& config,
                           const std::string& frame_id, double max_range,
                           double depth_no_return_length, const tf2_ros::Buffer& tf_buffer,
                           EnqueueScan enqueue) {
  const SensorInputContext context{config, frame_id, tf_buffer, counters_, std::move(enqueue)};
  inputs_.push_back(std::make_unique<LaserScanInput>(nh, "scan", context, max_range));
  for (const std::string& topic : config.scan_topics) {
    inputs_.push_back(std::make_unique<LaserScanInput>(nh, topic, context, max_range));
  }
  inputs_.push_back(std::make_unique<PointCloudInput>(nh, "cloud_in", context));
  for (const std::string& topic : config.cloud_topics) {
    inputs_.push_back(std::make_unique<PointCloudInput>(nh, topic, context));
  }
  for (const std::string& topic : config.depth_topics) {
    inputs_.push_back(
        std::make_unique<DepthImageInput>(nh, topic, context, depth_no_return_length));
  }
}

void SensorInputs::stop() {
  for (const std::unique_ptr<SensorInput>& input : inputs_) input->stop();
}

}  // namespace mvog_ros
