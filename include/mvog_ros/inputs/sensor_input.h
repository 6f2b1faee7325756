#pragma once

#include <atomic>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <string>

#include <ros/ros.h>
#include <std_msgs/Header.h>
#include <tf2_ros/buffer.h>
#include <Eigen/Geometry>

#include "mvog/map.h"
#include "mvog_ros/conversions.h"
#include "mvog_ros/mapper_config.h"

namespace mvog_ros {

/// What the sensor inputs dropped or skipped since the start or the last reset.
struct InputStatistics {
  std::uint64_t messages_dropped_tf = 0;           // no transform into the map frame
  std::uint64_t messages_dropped_invalid = 0;      // malformed
  std::uint64_t messages_dropped_camera_info = 0;  // depth images without their camera info
  // LaserScan beams and depth pixels that say nothing, points filtered out
  std::uint64_t readings_rejected = 0;
};

/// The counts of InputStatistics, kept by every input of a server together (from any thread).
struct InputCounters {
  std::atomic<std::uint64_t> messages_dropped_tf{0};
  std::atomic<std::uint64_t> messages_dropped_invalid{0};
  std::atomic<std::uint64_t> messages_dropped_camera_info{0};
  std::atomic<std::uint64_t> readings_rejected{0};

  InputStatistics statistics() const;
  void reset();
};

/// Where a converted message goes (InsertionWorker::enqueue); `source` is its message type.
using EnqueueReadings = std::function<void(SensorReadings&& readings, const std::string& source)>;

/// What every sensor input is given: its parameters, the map frame, the tf buffer to wait on,
/// the counters of what it drops, and where converted messages go.
struct SensorInputContext {
  SensorInputsConfig config;
  std::string frame_id;
  const tf2_ros::Buffer& tf_buffer;
  InputCounters& counters;
  EnqueueReadings enqueue;
};

/// One sensor topic: its subscription, and its messages waiting for the transform into the map
/// frame at their stamp (up to ~sensor_queue_size). Once a message's transform is there, the
/// input kind (LaserScanInput, PointCloudInput, DepthImageInput) converts it with the sensor's
/// pose and enqueues it. tf2_ros::MessageFilter is not used: its version in Debian loses a message
/// for good when the transform arrives while the message is being registered.
class SensorInput {
 public:
  virtual ~SensorInput();
  SensorInput(const SensorInput&) = delete;
  SensorInput& operator=(const SensorInput&) = delete;

  /// Takes no more messages: the subscription and the retries end, and the messages still
  /// waiting for their transform are dropped. The input kinds stop in their destructors (their
  /// callbacks use them); an input kind with subscriptions of its own ends them too.
  virtual void stop();

 protected:
  SensorInput(ros::NodeHandle& nh, const SensorInputContext& context);

  /// Subscribes to `topic`; every message waits for its transform, then goes to
  /// input->convertAndEnqueue(message, map_from_sensor).
  template <class Message, class Input>
  void subscribe(ros::NodeHandle& nh, const std::string& topic, Input* input) {
    subscriber_ = nh.subscribe<Message>(
        topic, static_cast<std::uint32_t>(context_.config.sensor_queue_size),
        [this, input](const boost::shared_ptr<const Message>& message) {
          receive(message->header, [input, message](const Eigen::Isometry3d& map_from_sensor) {
            input->convertAndEnqueue(*message, map_from_sensor);
          });
        });
  }
  /// Enqueues the readings `convert(skipped)` returns (a Scan, or a depth image inserted straight
  /// from its pixels, whose pixels without a measurement the insertion counts), the readings it
  /// skipped counted as rejected;
  /// a message it throws InvalidMessage for is dropped, counted, with a throttled warning.
  template <class Convert>
  void enqueueConverted(const std::string& message_type, Convert&& convert) {
    try {
      std::size_t skipped = 0;
      SensorReadings readings(convert(skipped));
      context_.counters.readings_rejected += skipped;
      context_.enqueue(std::move(readings), message_type);
    } catch (const InvalidMessage& e) {
      rejectMessage(message_type, e.what());
    }
  }

  using ConvertAndEnqueue = std::function<void(const Eigen::Isometry3d& map_from_sensor)>;
  /// Converts the message if its transform is there, else keeps it waiting.
  void receive(std_msgs::Header header, ConvertAndEnqueue convert_and_enqueue);

  const SensorInputContext context_;

 private:
  struct WaitingMessage {
    std_msgs::Header header;
    ConvertAndEnqueue convert_and_enqueue;
  };

  /// Converts the waiting messages whose transforms have arrived (under mutex_).
  void convertTransformable();
  /// Retries the waiting messages (timer): transforms arrive on tf's own thread.
  void retryWaitingMessages(const ros::TimerEvent&);
  void dropForTransform(const std_msgs::Header& header, const std::string& why);
  /// Drops a message that cannot be converted, counted, with a warning throttled per input (one
  /// input's bad messages do not hide another's).
  void rejectMessage(const std::string& message_type, const std::string& why);

  /// Wall time (s) of this input's last warning of an invalid message.
  std::atomic<double> last_invalid_warning_{-kWarningPeriod};
  std::mutex mutex_;
  std::deque<WaitingMessage> waiting_;  // oldest first
  ros::Subscriber subscriber_;
  ros::Timer retry_timer_;
};

}  // namespace mvog_ros
