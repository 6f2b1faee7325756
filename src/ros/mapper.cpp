#include "mvog_ros/mapper.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <tf2_eigen/tf2_eigen.h>

#include "mvog/MapBinary.h"
#include "mvog/MapStatistics.h"
#include "mvog/map_io.h"
#include "mvog_ros/conversions.h"
#include "mvog_ros/map_paths.h"

namespace mvog_ros {
namespace {

constexpr double kWarningPeriod = 5.0;          // s between two warnings of one kind
constexpr double kTransformRetryPeriod = 0.01;  // s between checks for awaited transforms
// Readings inserted under one hold of the map's lock: ~50 ms at 5 cm, the longest insertion
// keeps a query waiting.
constexpr std::size_t kReadingsPerLock = 16384;

/// Creates ~map_directory if missing and returns the map a server starts with: ~map_file if set,
/// else an empty one. Throws mvog::ConfigError naming the parameter at fault.
mvog::Map initialMap(const MapperConfig& config) {
  try {
    makeDirectories(config.map_files.map_directory);
  } catch (const PathRefused& e) {
    throw mvog::ConfigError("~map_directory: " + std::string(e.what()));
  }
  if (config.map_files.map_file.empty()) return mvog::Map(config.map);
  try {
    mvog::Map map = mvog::loadMap(
        resolveMapPath(config.map_files.map_directory, config.map_files.map_file, false));
    ROS_INFO("mvog: loaded ~map_file '%s' (resolution %.3f m)", config.map_files.map_file.c_str(),
             map.resolution());
    return map;
  } catch (const std::exception& e) {  // PathRefused or mvog::MapFileError
    throw mvog::ConfigError("~map_file: " + std::string(e.what()));
  }
}

}  // namespace

void Mapper::Counters::reset() {
  for (std::atomic<std::uint64_t>* counter :
       {&readings_inserted, &readings_rejected, &messages_inserted, &messages_dropped_tf,
        &messages_dropped_queue, &messages_dropped_invalid, &insertion_nanoseconds}) {
    counter->store(0);
  }
}

Mapper::Mapper(ros::NodeHandle nh, ros::NodeHandle private_nh)
    : nh_(nh),
      private_nh_(private_nh),
      config_(MapperConfig::fromParameters(private_nh)),
      map_(initialMap(config_)),
      tf_listener_(tf_buffer_, nh) {
  // Outputs. Every one is latched; a new subscriber is also sent the complete current state.
  auto marker_publisher = [&](const std::string& name, bool occupied_only) {
    return private_nh_.advertise<visualization_msgs::MarkerArray>(
        name, 1,
        [this, occupied_only](const ros::SingleSubscriberPublisher& s) {
          sendAllMarkers(s, occupied_only);
        },
        ros::SubscriberStatusCallback(), ros::VoidConstPtr(), true);
  };
  volumes_publisher_ = marker_publisher("volumes", false);
  occupied_publisher_ = marker_publisher("occupied", true);

  const std::int64_t max_grid_cells = config_.max_cross_section_cells;
  grids_.emplace_back(config_.publications.projection_min_z, max_grid_cells,
                      [this](const mvog::Map& map, const mvog::CellRange& cells) {
                        return toOccupancyGrid(map.projection(config_.publications.projection_min_z,
                                                              config_.publications.projection_max_z,
                                                              config_.occupancy_threshold, cells),
                                               0.0, "", ros::Time())
                            .data;
                      });
  std::vector<std::string> grid_topics{"projected_map"};
  for (std::size_t k = 0; k < config_.publications.cross_section_heights.size(); ++k) {
    const double height = config_.publications.cross_section_heights[k];
    grids_.emplace_back(
        height, max_grid_cells, [height](const mvog::Map& map, const mvog::CellRange& cells) {
          return toOccupancyGrid(map.crossSection(height, cells), height, "", ros::Time()).data;
        });
    grid_topics.push_back("cross_section_" + std::to_string(k));
    ROS_INFO("mvog: ~%s is the cross-section at z = %.3f m", grid_topics.back().c_str(), height);
  }
  for (std::size_t k = 0; k < grids_.size(); ++k) {
    grid_publishers_.push_back(private_nh_.advertise<nav_msgs::OccupancyGrid>(
        grid_topics[k], 1, [this, k](const ros::SingleSubscriberPublisher& s) { sendGrid(s, k); },
        ros::SubscriberStatusCallback(), ros::VoidConstPtr(), true));
    grid_update_publishers_.push_back(
        private_nh_.advertise<map_msgs::OccupancyGridUpdate>(grid_topics[k] + "_updates", 10));
  }
  binary_map_publisher_ = private_nh_.advertise<mvog::MapBinary>(
      "map", 1, [this](const ros::SingleSubscriberPublisher& s) { sendBinaryMap(s); },
      ros::SubscriberStatusCallback(), ros::VoidConstPtr(), true);
  statistics_publisher_ = private_nh_.advertise<mvog::MapStatistics>("statistics", 1, true);

  services_.push_back(private_nh_.advertiseService("get_occupancy", &Mapper::getOccupancy, this));
  services_.push_back(
      private_nh_.advertiseService("get_cross_section", &Mapper::getCrossSection, this));
  services_.push_back(private_nh_.advertiseService("save_map", &Mapper::saveMap, this));
  services_.push_back(private_nh_.advertiseService("load_map", &Mapper::loadMap, this));
  services_.push_back(private_nh_.advertiseService("reset", &Mapper::reset, this));

  timers_.push_back(nh_.createTimer(ros::Duration(config_.publications.publish_period),
                                    &Mapper::publishChanges, this));
  timers_.push_back(nh_.createTimer(ros::Duration(config_.publications.statistics_period),
                                    &Mapper::publishStatistics, this));
  if (config_.publications.binary_map_period > 0.0) {
    timers_.push_back(nh_.createTimer(ros::Duration(config_.publications.binary_map_period),
                                      &Mapper::publishBinaryMap, this));
  }
  if (config_.decay.enabled()) {
    timers_.push_back(
        nh_.createTimer(ros::Duration(config_.decay.decay_period), &Mapper::decay, this));
  }
  if (config_.map_files.autosave_period > 0.0) {
    timers_.push_back(nh_.createTimer(ros::Duration(config_.map_files.autosave_period),
                                      [this](const ros::TimerEvent&) { autosave(); }));
  }
  last_statistics_time_ = ros::WallTime::now();
  insertion_thread_ = std::thread(&Mapper::insertionLoop, this);

  // Inputs last, once everything they feed exists.
  subscribe<sensor_msgs::LaserScan>("scan");
  for (const std::string& topic : config_.inputs.scan_topics)
    subscribe<sensor_msgs::LaserScan>(topic);
  subscribe<sensor_msgs::PointCloud2>("cloud_in");
  for (const std::string& topic : config_.inputs.cloud_topics) {
    subscribe<sensor_msgs::PointCloud2>(topic);
  }
  timers_.push_back(
      nh_.createTimer(ros::Duration(kTransformRetryPeriod), &Mapper::retryWaitingMessages, this));
  ROS_INFO("mvog: mapping in '%s' at %.3f m, %zu scan and %zu cloud topics",
           config_.frame_id.c_str(), map_.resolution(), config_.inputs.scan_topics.size() + 1,
           config_.inputs.cloud_topics.size() + 1);
}

Mapper::~Mapper() {
  for (const std::unique_ptr<SensorInput>& input : inputs_) input->subscriber.shutdown();
  for (ros::Timer& timer : timers_) timer.stop();
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    stopping_ = true;
  }
  queue_changed_.notify_all();
  insertion_thread_.join();
  // A clean shutdown loses nothing mapped since the last autosave.
  if (config_.map_files.autosave_period > 0.0) autosave();
}

template <class Message>
void Mapper::subscribe(const std::string& topic) {
  inputs_.push_back(std::make_unique<SensorInput>());
  SensorInput* input = inputs_.back().get();
  input->subscriber = nh_.subscribe<Message>(
      topic, static_cast<std::uint32_t>(config_.inputs.sensor_queue_size),
      [this, input](const boost::shared_ptr<const Message>& message) {
        receive(*input, {message->header, [this, message](const Eigen::Isometry3d& pose) {
                           if constexpr (std::is_same_v<Message, sensor_msgs::LaserScan>) {
                             insertScan(*message, pose);
                           } else {
                             insertCloud(*message, pose);
                           }
                         }});
      });
}

void Mapper::receive(SensorInput& input, SensorMessage&& message) {
  std::string& frame_id = message.header.frame_id;
  if (!frame_id.empty() && frame_id.front() == '/') frame_id.erase(0, 1);  // tf1 style
  if (frame_id.empty()) {
    dropForTransform(message.header, "its frame_id is empty");
    return;
  }
  std::lock_guard<std::mutex> lock(input.mutex);
  input.waiting.push_back(std::move(message));
  insertTransformable(input);
  if (input.waiting.size() > static_cast<std::size_t>(config_.inputs.sensor_queue_size)) {
    dropForTransform(input.waiting.front().header,
                     "no transform to the map frame before ~sensor_queue_size newer messages");
    input.waiting.pop_front();
  }
}

void Mapper::insertTransformable(SensorInput& input) {
  for (auto message = input.waiting.begin(); message != input.waiting.end();) {
    if (!tf_buffer_.canTransform(config_.frame_id, message->header.frame_id,
                                 message->header.stamp)) {
      ++message;
      continue;
    }
    try {
      message->insert(tf2::transformToEigen(tf_buffer_.lookupTransform(
          config_.frame_id, message->header.frame_id, message->header.stamp)));
    } catch (const tf2::TransformException& e) {  // gone from the cache since canTransform
      dropForTransform(message->header, e.what());
    }
    message = input.waiting.erase(message);
  }
}

void Mapper::retryWaitingMessages(const ros::TimerEvent&) {
  for (const std::unique_ptr<SensorInput>& input : inputs_) {
    std::lock_guard<std::mutex> lock(input->mutex);
    insertTransformable(*input);
  }
}

void Mapper::dropForTransform(const std_msgs::Header& header, const std::string& why) {
  ++counters_.messages_dropped_tf;
  ROS_WARN_THROTTLE(kWarningPeriod,
                    "mvog: dropped a message from frame '%s' at %.3f: %s (%llu so far)",
                    header.frame_id.c_str(), header.stamp.toSec(), why.c_str(),
                    static_cast<unsigned long long>(counters_.messages_dropped_tf.load()));
}

void Mapper::rejectMessage(const std::string& topic_kind, const std::string& why) {
  ++counters_.messages_dropped_invalid;
  ROS_WARN_THROTTLE(kWarningPeriod, "mvog: dropped an invalid %s: %s (%llu invalid so far)",
                    topic_kind.c_str(), why.c_str(),
                    static_cast<unsigned long long>(counters_.messages_dropped_invalid.load()));
}

void Mapper::insertScan(const sensor_msgs::LaserScan& scan,
                        const Eigen::Isometry3d& map_from_sensor) {
  try {
    std::size_t skipped = 0;
    PendingScan pending{
        laserScanToScan(scan, map_from_sensor, config_.insertion.max_range,
                        static_cast<std::size_t>(config_.inputs.max_points_per_message), skipped),
        "LaserScan"};
    counters_.readings_rejected += skipped;
    enqueue(std::move(pending));
  } catch (const InvalidMessage& e) {
    rejectMessage("LaserScan", e.what());
  }
}

void Mapper::insertCloud(const sensor_msgs::PointCloud2& cloud,
                         const Eigen::Isometry3d& map_from_sensor) {
  try {
    PendingScan pending{
        pointCloudToScan(cloud, map_from_sensor,
                         static_cast<std::size_t>(config_.inputs.max_points_per_message)),
        "PointCloud2"};
    if (config_.inputs.voxel_filter_size > 0.0) {
      counters_.readings_rejected +=
          voxelFilter(pending.scan.hits, config_.inputs.voxel_filter_size);
    }
    enqueue(std::move(pending));
  } catch (const InvalidMessage& e) {
    rejectMessage("PointCloud2", e.what());
  }
}

void Mapper::enqueue(PendingScan&& pending) {
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    if (queue_.size() >= static_cast<std::size_t>(config_.insertion.insertion_queue_size)) {
      queue_.pop_front();  // keep the newest: the oldest view is the least useful
      ++counters_.messages_dropped_queue;
      ROS_WARN_THROTTLE(kWarningPeriod,
                        "mvog: insertion is slower than the sensors; dropped the oldest waiting "
                        "message (%llu so far)",
                        static_cast<unsigned long long>(counters_.messages_dropped_queue.load()));
    }
    queue_.push_back(std::move(pending));
  }
  queue_changed_.notify_one();
}

void Mapper::insertionLoop() {
  for (;;) {
    PendingScan pending;
    {
      std::unique_lock<std::mutex> lock(queue_mutex_);
      queue_changed_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
      if (queue_.empty()) return;  // stopping, and what was queued is in the map
      pending = std::move(queue_.front());
      queue_.pop_front();
    }
    const auto start = std::chrono::steady_clock::now();
    mvog::InsertionResult result;
    if (config_.insertion.clear_conflicting_free_space) {
      // Sec. V.B's conflicts are those within one scan: the scan goes in whole.
      std::unique_lock<WriterPreferringMutex> lock(map_mutex_);
      result = map_.insertScan(pending.scan, config_.insertion);
    } else {
      // Piece by piece, the same map (mvog::splitScan), and queries and publications wait for
      // one piece at most instead of a whole cloud.
      for (const mvog::Scan& piece : mvog::splitScan(pending.scan, kReadingsPerLock)) {
        std::unique_lock<WriterPreferringMutex> lock(map_mutex_);
        result += map_.insertScan(piece, config_.insertion);
      }
    }
    counters_.insertion_nanoseconds +=
        static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                       std::chrono::steady_clock::now() - start)
                                       .count());
    counters_.readings_inserted += result.inserted();
    counters_.readings_rejected += result.rejected();
    ++counters_.messages_inserted;
    if (result.rejected_out_of_bounds > 0) {
      ROS_WARN_THROTTLE(kWarningPeriod,
                        "mvog: %zu readings of a %s lie beyond ~max_coordinate and were rejected",
                        result.rejected_out_of_bounds, pending.source.c_str());
    }
  }
}

// ---- Publication ---------------------------------------------------------------------------

void Mapper::publishChanges(const ros::TimerEvent&) {
  std::lock_guard<std::mutex> publish_lock(publish_mutex_);
  std::shared_lock<WriterPreferringMutex> lock(map_mutex_);
  if (map_.revision() == published_revision_) return;
  const std::vector<mvog::TileIndex> changed = map_.tilesModifiedSince(published_revision_);
  published_revision_ = map_.revision();
  const ros::Time stamp = ros::Time::now();

  if (volumes_publisher_.getNumSubscribers() > 0 || occupied_publisher_.getNumSubscribers() > 0) {
    visualization_msgs::MarkerArray volumes;
    visualization_msgs::MarkerArray occupied;
    for (const mvog::TileIndex& tile : changed) {
      if (volumes_publisher_.getNumSubscribers() > 0) {
        appendVolumeMarkers(map_, tile, config_.frame_id, stamp, volumes);
      }
      if (occupied_publisher_.getNumSubscribers() > 0) {
        appendOccupiedMarkers(map_, tile, config_.occupancy_threshold, config_.frame_id, stamp,
                              occupied);
      }
    }
    if (!volumes.markers.empty()) volumes_publisher_.publish(volumes);
    if (!occupied.markers.empty()) occupied_publisher_.publish(occupied);
  }
  for (std::size_t k = 0; k < grids_.size(); ++k) {
    bool relaid_out = false;
    const std::optional<mvog::CellRange> touched = updateGrid(k, changed, relaid_out);
    if (!touched || touched->empty()) continue;
    nav_msgs::OccupancyGrid grid = grids_[k].grid();
    grid.header.frame_id = config_.frame_id;
    grid.header.stamp = stamp;
    grid.info.map_load_time = stamp;
    if (grid_publishers_[k].getNumSubscribers() > 0) grid_publishers_[k].publish(grid);
    if (!relaid_out && grid_update_publishers_[k].getNumSubscribers() > 0) {
      map_msgs::OccupancyGridUpdate update = grids_[k].updateOf(*touched);
      update.header = grid.header;
      grid_update_publishers_[k].publish(update);
    }
  }
}

void Mapper::sendAllMarkers(const ros::SingleSubscriberPublisher& subscriber, bool occupied_only) {
  std::lock_guard<std::mutex> publish_lock(publish_mutex_);
  std::shared_lock<WriterPreferringMutex> lock(map_mutex_);
  const ros::Time stamp = ros::Time::now();
  visualization_msgs::MarkerArray markers;
  markers.markers.push_back(deleteAllMarker(config_.frame_id, stamp));
  for (const mvog::TileIndex& tile : map_.tilesModifiedSince(0)) {
    if (occupied_only) {
      appendOccupiedMarkers(map_, tile, config_.occupancy_threshold, config_.frame_id, stamp,
                            markers);
    } else {
      appendVolumeMarkers(map_, tile, config_.frame_id, stamp, markers);
    }
  }
  subscriber.publish(markers);
}

void Mapper::sendGrid(const ros::SingleSubscriberPublisher& subscriber, std::size_t layer) {
  std::lock_guard<std::mutex> publish_lock(publish_mutex_);
  std::shared_lock<WriterPreferringMutex> lock(map_mutex_);
  bool relaid_out = false;
  if (!updateGrid(layer, map_.tilesModifiedSince(published_revision_), relaid_out) ||
      grids_[layer].cells().empty()) {  // too large, or nothing mapped yet
    return;
  }
  nav_msgs::OccupancyGrid grid = grids_[layer].grid();
  grid.header.frame_id = config_.frame_id;
  grid.header.stamp = ros::Time::now();
  subscriber.publish(grid);
}

std::optional<mvog::CellRange> Mapper::updateGrid(std::size_t layer,
                                                  const std::vector<mvog::TileIndex>& changed,
                                                  bool& relaid_out) {
  try {
    return grids_[layer].update(map_, changed, relaid_out);
  } catch (const GridTooLarge& e) {
    ROS_WARN_THROTTLE(kWarningPeriod,
                      "mvog: %s not published: %s, more than ~max_cross_section_cells (%d); "
                      "readings far away? (~max_coordinate, ~max_range)",
                      grid_publishers_[layer].getTopic().c_str(), e.what(),
                      config_.max_cross_section_cells);
    return std::nullopt;
  }
}

mvog::MapBinary Mapper::binaryMapMessage() const {
  mvog::MapBinary message;
  message.data = mvog::serializeMap(map_);
  message.resolution = map_.resolution();
  message.header.frame_id = config_.frame_id;
  message.header.stamp = ros::Time::now();
  message.format_version = mvog::kMapFormatVersion;
  return message;
}

void Mapper::sendBinaryMap(const ros::SingleSubscriberPublisher& subscriber) {
  mvog::MapBinary message;
  {
    std::shared_lock<WriterPreferringMutex> lock(map_mutex_);
    message = binaryMapMessage();
  }
  subscriber.publish(message);
}

void Mapper::publishBinaryMap(const ros::TimerEvent&) {
  if (binary_map_publisher_.getNumSubscribers() == 0) return;
  std::lock_guard<std::mutex> publish_lock(publish_mutex_);
  mvog::MapBinary message;
  {
    std::shared_lock<WriterPreferringMutex> lock(map_mutex_);
    if (map_.revision() == binary_revision_) return;
    binary_revision_ = map_.revision();
    message = binaryMapMessage();
  }
  binary_map_publisher_.publish(message);
}

void Mapper::publishStatistics(const ros::TimerEvent&) {
  mvog::MapStatistics statistics;
  {
    std::shared_lock<WriterPreferringMutex> lock(map_mutex_);
    const mvog::MemoryUsage memory = map_.memoryUsage();
    statistics.resolution = map_.resolution();
    statistics.cells_with_volumes = memory.cells_with_volumes;
    statistics.positive_volumes = memory.positive_volumes;
    statistics.negative_volumes = memory.negative_volumes;
    statistics.minimal_grid_cells = memory.minimal_grid_cells;
    statistics.bytes_held = memory.bytes_held;
    statistics.table_one_bytes = memory.table_one_bytes;
  }
  const ros::WallTime now = ros::WallTime::now();
  statistics.readings_inserted = counters_.readings_inserted.load();
  const double elapsed = (now - last_statistics_time_).toSec();
  if (elapsed > 0.0 && statistics.readings_inserted >= readings_at_last_statistics_) {
    statistics.readings_per_second =
        static_cast<double>(statistics.readings_inserted - readings_at_last_statistics_) / elapsed;
  }
  readings_at_last_statistics_ = statistics.readings_inserted;
  last_statistics_time_ = now;
  statistics.readings_rejected = counters_.readings_rejected.load();
  statistics.insertion_seconds = 1e-9 * static_cast<double>(counters_.insertion_nanoseconds.load());
  statistics.messages_inserted = counters_.messages_inserted.load();
  statistics.messages_dropped_tf = counters_.messages_dropped_tf.load();
  statistics.messages_dropped_queue = counters_.messages_dropped_queue.load();
  statistics.messages_dropped_invalid = counters_.messages_dropped_invalid.load();
  statistics.header.frame_id = config_.frame_id;
  statistics.header.stamp = ros::Time::now();
  statistics_publisher_.publish(statistics);
}

void Mapper::decay(const ros::TimerEvent&) {
  std::unique_lock<WriterPreferringMutex> lock(map_mutex_);
  map_.decay(config_.decay.decay_factor);
}

void Mapper::autosave() {
  std::lock_guard<std::mutex> autosave_lock(autosave_mutex_);
  try {
    std::uint64_t generation = 0;
    std::uint64_t revision = 0;
    std::vector<std::uint8_t> bytes;
    {
      std::shared_lock<WriterPreferringMutex> lock(map_mutex_);
      generation = map_generation_;
      revision = map_.revision();
      if (generation == saved_generation_ && revision == saved_revision_) return;
      bytes = mvog::serializeMap(map_);
    }
    // Written without the map's lock: insertion and queries go on meanwhile.
    mvog::saveMapBytes(bytes, resolveMapPath(config_.map_files.map_directory,
                                             config_.map_files.autosave_file, true));
    saved_generation_ = generation;
    saved_revision_ = revision;
  } catch (const std::exception& e) {
    ROS_WARN_THROTTLE(kWarningPeriod, "mvog: autosave failed: %s", e.what());
  }
}

void Mapper::restartPublication() {
  const ros::Time stamp = ros::Time::now();
  visualization_msgs::MarkerArray clear;
  clear.markers.push_back(deleteAllMarker(config_.frame_id, stamp));
  volumes_publisher_.publish(clear);
  occupied_publisher_.publish(clear);
  // The latched grids would show the previous map to every new subscriber: replace them by
  // unknown ones until the new map has something to show.
  for (std::size_t k = 0; k < grids_.size(); ++k) {
    nav_msgs::OccupancyGrid unknown = grids_[k].grid();
    if (!unknown.data.empty()) {
      std::fill(unknown.data.begin(), unknown.data.end(), std::int8_t{-1});
      unknown.header.frame_id = config_.frame_id;
      unknown.header.stamp = stamp;
      unknown.info.map_load_time = stamp;
      grid_publishers_[k].publish(unknown);
    }
    grids_[k].clear();
  }
  published_revision_ = 0;
  binary_revision_ = 0;
}

// ---- Services ------------------------------------------------------------------------------

bool Mapper::getOccupancy(mvog::GetOccupancy::Request& request,
                          mvog::GetOccupancy::Response& response) {
  if (request.points.size() > static_cast<std::size_t>(config_.queries.max_query_points)) {
    response.message = "refused: " + std::to_string(request.points.size()) +
                       " points exceed ~max_query_points (" +
                       std::to_string(config_.queries.max_query_points) + ")";
    return true;
  }
  Eigen::Isometry3d map_from_frame = Eigen::Isometry3d::Identity();
  if (!request.frame_id.empty() && request.frame_id != config_.frame_id) {
    try {
      map_from_frame = tf2::transformToEigen(
          tf_buffer_.lookupTransform(config_.frame_id, request.frame_id, ros::Time(0),
                                     ros::Duration(config_.queries.tf_timeout)));
    } catch (const tf2::TransformException& e) {
      response.message = "cannot transform from '" + request.frame_id + "' to '" +
                         config_.frame_id + "': " + e.what();
      return true;
    }
  }
  response.probability.resize(request.points.size());
  response.state.resize(request.points.size());
  std::shared_lock<WriterPreferringMutex> lock(map_mutex_);
  for (std::size_t k = 0; k < request.points.size(); ++k) {
    const geometry_msgs::Point& p = request.points[k];
    const mvog::PointOccupancy occupancy =
        map_.occupancy(map_from_frame * Eigen::Vector3d(p.x, p.y, p.z));
    response.probability[k] = occupancy.probability.value_or(std::nanf(""));
    response.state[k] = static_cast<std::uint8_t>(occupancy.state(config_.occupancy_threshold));
  }
  response.success = true;
  return true;
}

bool Mapper::getCrossSection(mvog::GetCrossSection::Request& request,
                             mvog::GetCrossSection::Response& response) {
  if (!std::isfinite(request.height)) {
    response.message = "height must be finite";
    return true;
  }
  std::shared_lock<WriterPreferringMutex> lock(map_mutex_);
  mvog::CellRange cells = map_.bounds();
  if (request.use_bounds) {
    if (!std::isfinite(request.min_x) || !std::isfinite(request.min_y) ||
        !std::isfinite(request.max_x) || !std::isfinite(request.max_y) ||
        request.min_x > request.max_x || request.min_y > request.max_y ||
        std::fmax(std::fabs(request.min_x), std::fabs(request.max_x)) >
            config_.map.max_coordinate ||
        std::fmax(std::fabs(request.min_y), std::fabs(request.max_y)) >
            config_.map.max_coordinate) {
      response.message = "bounds must be finite, ordered and within ~max_coordinate";
      return true;
    }
    cells = map_.cellsInRectangle(request.min_x, request.min_y, request.max_x, request.max_y);
  }
  if (cells.empty()) {
    response.message = "the map is empty";
    return true;
  }
  if (cells.width() * cells.height() > config_.max_cross_section_cells) {
    response.message = "refused: the cross-section would have " +
                       std::to_string(cells.width() * cells.height()) +
                       " cells, more than ~max_cross_section_cells";
    return true;
  }
  response.map = toOccupancyGrid(map_.crossSection(request.height, cells), request.height,
                                 config_.frame_id, ros::Time::now());
  response.success = true;
  return true;
}

bool Mapper::saveMap(mvog::MapFile::Request& request, mvog::MapFile::Response& response) {
  try {
    const std::string path = resolveMapPath(config_.map_files.map_directory, request.path, true);
    std::vector<std::uint8_t> bytes;
    {
      std::shared_lock<WriterPreferringMutex> lock(map_mutex_);
      bytes = mvog::serializeMap(map_);
    }
    mvog::saveMapBytes(bytes, path);  // without the map's lock
    response.message = "saved " + path;
    response.success = true;
  } catch (const std::exception& e) {
    response.message = e.what();
  }
  return true;
}

bool Mapper::loadMap(mvog::MapFile::Request& request, mvog::MapFile::Response& response) {
  try {
    const std::string path = resolveMapPath(config_.map_files.map_directory, request.path, false);
    mvog::Map loaded = mvog::loadMap(path);  // the current map stays untouched until this worked
    response.message = "loaded " + path;
    replaceMap(std::move(loaded));
    response.success = true;
  } catch (const std::exception& e) {
    response.message = e.what();
  }
  return true;
}

bool Mapper::reset(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& response) {
  mvog::MapConfig config;
  {
    std::shared_lock<WriterPreferringMutex> lock(map_mutex_);
    config = map_.config();
  }
  replaceMap(mvog::Map(config));
  counters_.reset();
  response.success = true;
  response.message = "the map is empty";
  return true;
}

void Mapper::replaceMap(mvog::Map&& map) {
  std::lock_guard<std::mutex> publish_lock(publish_mutex_);
  std::unique_lock<WriterPreferringMutex> lock(map_mutex_);
  map_ = std::move(map);
  ++map_generation_;  // revisions of the new map say nothing about the autosaved file
  restartPublication();
}

}  // namespace mvog_ros
