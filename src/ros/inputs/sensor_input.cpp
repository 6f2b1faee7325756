#include "mvog_ros/inputs/sensor_input.h"

#include <utility>

#include <tf2_eigen/tf2_eigen.h>

#include "mvog_ros/frames.h"

namespace mvog_ros {
namespace {

constexpr double kTransformRetryPeriod = 0.01;  // s between checks for awaited transforms

}  // namespace

InputStatistics InputCounters::statistics() const {
  return {messages_dropped_tf.load(), messages_dropped_invalid.load(),
          messages_dropped_camera_info.load(), readings_rejected.load()};
}

void InputCounters::reset() {
  for (std::atomic<std::uint64_t>* counter : {&messages_dropped_tf, &messages_dropped_invalid,
                                              &messages_dropped_camera_info, &readings_rejected}) {
    counter->store(0);
  }
}

SensorInput::SensorInput(ros::NodeHandle& nh, const SensorInputContext& context)
    : context_(context),
      retry_timer_(nh.createTimer(ros::Duration(kTransformRetryPeriod),
                                  &SensorInput::retryWaitingMessages, this)) {}

SensorInput::~SensorInput() { stop(); }

void SensorInput::stop() {
  subscriber_.shutdown();
  retry_timer_.stop();
}

void SensorInput::receive(std_msgs::Header header, ConvertAndEnqueue convert_and_enqueue) {
  header.frame_id = tf2FrameId(header.frame_id);
  if (header.frame_id.empty()) {
    dropForTransform(header, "its frame_id is empty");
    return;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  waiting_.push_back({std::move(header), std::move(convert_and_enqueue)});
  convertTransformable();
  if (waiting_.size() > static_cast<std::size_t>(context_.config.sensor_queue_size)) {
    dropForTransform(waiting_.front().header,
                     "no transform to the map frame before ~sensor_queue_size newer messages");
    waiting_.pop_front();
  }
}

void SensorInput::convertTransformable() {
  for (auto message = waiting_.begin(); message != waiting_.end();) {
    if (!context_.tf_buffer.canTransform(context_.frame_id, message->header.frame_id,
                                         message->header.stamp)) {
      ++message;
      continue;
    }
    try {
      message->convert_and_enqueue(tf2::transformToEigen(context_.tf_buffer.lookupTransform(
          context_.frame_id, message->header.frame_id, message->header.stamp)));
    } catch (const tf2::TransformException& e) {  // gone from the cache since canTransform
      dropForTransform(message->header, e.what());
    }
    message = waiting_.erase(message);
  }
}

void SensorInput::retryWaitingMessages(const ros::TimerEvent&) {
  std::lock_guard<std::mutex> lock(mutex_);
  convertTransformable();
}

void SensorInput::dropForTransform(const std_msgs::Header& header, const std::string& why) {
  ++context_.counters.messages_dropped_tf;
  ROS_WARN_THROTTLE(kWarningPeriod,
                    "mvog: dropped a message from frame '%s' at %.3f: %s (%llu so far)",
                    header.frame_id.c_str(), header.stamp.toSec(), why.c_str(),
                    static_cast<unsigned long long>(context_.counters.messages_dropped_tf.load()));
}

void SensorInput::rejectMessage(const std::string& message_type, const std::string& why) {
  ++context_.counters.messages_dropped_invalid;
  const double now = ros::WallTime::now().toSec();
  double last = last_invalid_warning_.load();
  if (now - last < kWarningPeriod || !last_invalid_warning_.compare_exchange_strong(last, now)) {
    return;  // warned within the period (or another thread warns now)
  }
  ROS_WARN("mvog: dropped an invalid %s: %s (%llu invalid so far)", message_type.c_str(),
           why.c_str(),
           static_cast<unsigned long long>(context_.counters.messages_dropped_invalid.load()));
}

}  // namespace mvog_ros
