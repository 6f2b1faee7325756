#include "mvog_ros/inputs/sensor_inputs.h"

#include <utility>

#include "mvog_ros/inputs/depth_image_input.h"
#include "mvog_ros/inputs/laser_scan_input.h"
#include "mvog_ros/inputs/point_cloud_input.h"

namespace mvog_ros {

SensorInputs::SensorInputs(ros::NodeHandle nh, const SensorInputsConfig& config,
                           const std::string& frame_id, double max_range,
                           double depth_no_return_length, const tf2_ros::Buffer& tf_buffer,
                           EnqueueReadings enqueue) {
  const SensorInputContext context{config, frame_id, tf_buffer, counters_, std::move(enqueue)};
  std::vector<std::string> scan_topics{"scan"};
  scan_topics.insert(scan_topics.end(), config.scan_topics.begin(), config.scan_topics.end());
  for (const std::string& topic : scan_topics) {
    auto input = std::make_unique<LaserScanInput>(nh, topic, context, max_range);
    scan_inputs_.push_back(input.get());
    inputs_.push_back(std::move(input));
  }
  inputs_.push_back(std::make_unique<PointCloudInput>(nh, "cloud_in", context));
  for (const std::string& topic : config.cloud_topics) {
    inputs_.push_back(std::make_unique<PointCloudInput>(nh, topic, context));
  }
  for (const std::string& topic : config.depth_topics) {
    auto input = std::make_unique<DepthImageInput>(nh, topic, context, depth_no_return_length);
    depth_inputs_.push_back(input.get());
    inputs_.push_back(std::move(input));
  }
}

void SensorInputs::setMaxRange(double max_range, double depth_no_return_length) {
  for (LaserScanInput* input : scan_inputs_) input->setMaxRange(max_range);
  for (DepthImageInput* input : depth_inputs_) input->setNoReturnLength(depth_no_return_length);
}

void SensorInputs::stop() {
  for (const std::unique_ptr<SensorInput>& input : inputs_) input->stop();
}

}  // namespace mvog_ros
