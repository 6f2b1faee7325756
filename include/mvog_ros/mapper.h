#pragma once

#include <atomic>
#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <shared_mutex>
#include <string>
#include <thread>
#include <vector>

#include <ros/ros.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_srvs/Trigger.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>
#include <Eigen/Geometry>

#include "mvog/GetCrossSection.h"
#include "mvog/GetOccupancy.h"
#include "mvog/MapBinary.h"
#include "mvog/MapFile.h"
#include "mvog/map.h"
#include "mvog_ros/mapper_config.h"
#include "mvog_ros/visualization.h"
#include "mvog_ros/writer_preferring_mutex.h"

namespace mvog_ros {

/// The mapping server: subscribes to range sensors, feeds the MVOG core, publishes the map and
/// answers queries. Shared by the nodelet and the node. Callbacks may run on several threads:
/// the map is guarded by a readers-writer lock, and insertion runs on its own thread behind a
/// bounded queue that drops the oldest message when the sensors outpace it. A sensor message
/// whose transform to the map frame has not arrived yet waits for it (up to ~sensor_queue_size
/// messages per topic); tf2_ros::MessageFilter is not used: its version here loses a message
/// for good when the transform arrives while the message is being registered.
class Mapper {
 public:
  /// Throws mvog::ConfigError naming the parameter at fault (~map_file if it cannot be loaded).
  Mapper(ros::NodeHandle nh, ros::NodeHandle private_nh);
  ~Mapper();
  Mapper(const Mapper&) = delete;
  Mapper& operator=(const Mapper&) = delete;

 private:
  /// A sensor message: its header, and what inserts it given the sensor's pose.
  struct SensorMessage {
    std_msgs::Header header;
    std::function<void(const Eigen::Isometry3d& map_from_sensor)> insert;
  };
  /// One sensor topic and its messages waiting for their transform, oldest first.
  struct SensorInput {
    std::mutex mutex;
    std::deque<SensorMessage> waiting;
    ros::Subscriber subscriber;
  };
  struct PendingScan {
    mvog::Scan scan;
    std::string source;
  };
  struct Counters {
    std::atomic<std::uint64_t> readings_inserted{0};
    std::atomic<std::uint64_t> readings_rejected{0};
    std::atomic<std::uint64_t> messages_inserted{0};
    std::atomic<std::uint64_t> messages_dropped_tf{0};
    std::atomic<std::uint64_t> messages_dropped_queue{0};
    std::atomic<std::uint64_t> messages_dropped_invalid{0};
    std::atomic<std::uint64_t> insertion_nanoseconds{0};
    void reset();
  };

  template <class Message>
  void subscribe(const std::string& topic);
  /// Inserts the message if its transform is there, else keeps it waiting.
  void receive(SensorInput& input, SensorMessage&& message);
  /// Inserts the waiting messages of `input` whose transforms have arrived (under its mutex).
  void insertTransformable(SensorInput& input);
  /// Retries every waiting message (timer): transforms arrive on tf's own thread.
  void retryWaitingMessages(const ros::TimerEvent&);
  void dropForTransform(const std_msgs::Header& header, const std::string& why);
  void insertScan(const sensor_msgs::LaserScan& scan, const Eigen::Isometry3d& map_from_sensor);
  void insertCloud(const sensor_msgs::PointCloud2& cloud, const Eigen::Isometry3d& map_from_sensor);
  void rejectMessage(const std::string& topic_kind, const std::string& why);
  void enqueue(PendingScan&& pending);
  void insertionLoop();

  void publishChanges(const ros::TimerEvent&);
  void publishBinaryMap(const ros::TimerEvent&);
  void publishStatistics(const ros::TimerEvent&);
  void decay(const ros::TimerEvent&);
  /// Saves ~autosave_file if the map changed since the last autosave (a warning if it fails).
  void autosave();
  void sendAllMarkers(const ros::SingleSubscriberPublisher& subscriber, bool occupied_only);
  void sendGrid(const ros::SingleSubscriberPublisher& subscriber, std::size_t layer);
  /// Brings grid `layer` up to date (IncrementalGrid::update): the rectangle that changed, or
  /// nothing (with a warning) if the map has outgrown ~max_cross_section_cells.
  std::optional<mvog::CellRange> updateGrid(std::size_t layer,
                                            const std::vector<mvog::TileIndex>& changed,
                                            bool& relaid_out);
  void sendBinaryMap(const ros::SingleSubscriberPublisher& subscriber);
  /// The whole map as a ~map message; the caller holds the map lock (shared).
  mvog::MapBinary binaryMapMessage() const;
  /// Forgets every published tile and grid (clearing the markers and publishing the grids as
  /// unknown): the next publication starts from scratch.
  void restartPublication();

  bool getOccupancy(mvog::GetOccupancy::Request& request, mvog::GetOccupancy::Response& response);
  bool getCrossSection(mvog::GetCrossSection::Request& request,
                       mvog::GetCrossSection::Response& response);
  bool saveMap(mvog::MapFile::Request& request, mvog::MapFile::Response& response);
  bool loadMap(mvog::MapFile::Request& request, mvog::MapFile::Response& response);
  bool reset(std_srvs::Trigger::Request& request, std_srvs::Trigger::Response& response);
  /// Replaces the map (load): under the write lock, and publication restarts.
  void replaceMap(mvog::Map&& map);

  ros::NodeHandle nh_;
  ros::NodeHandle private_nh_;
  const MapperConfig config_;

  mutable WriterPreferringMutex map_mutex_;
  mvog::Map map_;
  std::uint64_t map_generation_ = 0;  // how many maps replaceMap put in place (under map_mutex_)

  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  /// Filled in the constructor only; callbacks hold pointers to the inputs.
  std::vector<std::unique_ptr<SensorInput>> inputs_;

  std::mutex queue_mutex_;
  std::condition_variable queue_changed_;
  std::deque<PendingScan> queue_;
  bool stopping_ = false;
  std::thread insertion_thread_;

  std::mutex publish_mutex_;  // the publication state below
  std::uint64_t published_revision_ = 0;
  std::uint64_t binary_revision_ = 0;
  std::mutex autosave_mutex_;           // one autosave at a time (timer, shutdown); guards saved_*
  std::uint64_t saved_generation_ = 0;  // the map last autosaved, and its revision then
  std::uint64_t saved_revision_ = 0;
  /// Layer 0 is the projected map, then one per ~cross_section_heights entry.
  std::vector<IncrementalGrid> grids_;

  Counters counters_;
  std::uint64_t readings_at_last_statistics_ = 0;
  ros::WallTime last_statistics_time_;

  ros::Publisher volumes_publisher_;
  ros::Publisher occupied_publisher_;
  std::vector<ros::Publisher> grid_publishers_;
  std::vector<ros::Publisher> grid_update_publishers_;
  ros::Publisher binary_map_publisher_;
  ros::Publisher statistics_publisher_;
  std::vector<ros::ServiceServer> services_;
  std::vector<ros::Timer> timers_;
};

}  // namespace mvog_ros
