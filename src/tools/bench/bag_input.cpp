#include <algorithm>
#include <limits>

#include <ros/exception.h>

#include <ros/message_traits.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2/buffer_core.h>
#include <tf2/exceptions.h>
#include <tf2_eigen/tf2_eigen.h>
#include <tf2_msgs/TFMessage.h>

#include "input.h"
#include "mvog_ros/conversions.h"

namespace mvog_bench {
namespace {

constexpr std::size_t kNoSizeLimit = std::numeric_limits<std::size_t>::max();

template <class Message>
bool isMessage(const rosbag::MessageInstance& m) {
  return m.getDataType() == ros::message_traits::DataType<Message>::value();
}

/// A tf2 buffer holding every transform of the bag: its cache spans the whole bag.
void fillTransforms(const rosbag::Bag& bag, tf2::BufferCore& buffer) {
  for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
    if (!isMessage<tf2_msgs::TFMessage>(m)) continue;
    const bool is_static = m.getTopic() == "/tf_static";
    const tf2_msgs::TFMessage::ConstPtr message = m.instantiate<tf2_msgs::TFMessage>();
    for (const geometry_msgs::TransformStamped& transform : message->transforms) {
      buffer.setTransform(transform, "bag", is_static);
    }
  }
}

}  // namespace

InputData loadBag(const std::string& path, const std::string& fixed_frame) {
  InputData input;
  input.format = "bag";
  try {
    rosbag::Bag bag(path, rosbag::bagmode::Read);
    rosbag::View everything(bag);
    const ros::Duration span = everything.getEndTime() - everything.getBeginTime();
    tf2::BufferCore buffer(span + ros::Duration(60.0));
    fillTransforms(bag, buffer);

    for (const rosbag::MessageInstance& m : everything) {
      const bool is_scan = isMessage<sensor_msgs::LaserScan>(m);
      if (!is_scan && !isMessage<sensor_msgs::PointCloud2>(m)) continue;
      ++input.sensor_messages;
      const sensor_msgs::LaserScan::ConstPtr scan =
          is_scan ? m.instantiate<sensor_msgs::LaserScan>() : nullptr;
      const sensor_msgs::PointCloud2::ConstPtr cloud =
          is_scan ? nullptr : m.instantiate<sensor_msgs::PointCloud2>();
      const std_msgs::Header& header = is_scan ? scan->header : cloud->header;
      Eigen::Isometry3d map_from_sensor;
      try {
        map_from_sensor = tf2::transformToEigen(
            buffer.lookupTransform(fixed_frame, header.frame_id, header.stamp));
      } catch (const tf2::TransformException&) {
        ++input.without_transform;
        continue;
      }
      // Both backends take single-precision points; the origin is rounded the same way.
      map_from_sensor.translation() = map_from_sensor.translation().cast<float>().cast<double>();
      mvog::Scan readings;
      try {
        if (is_scan) {
          std::size_t skipped = 0;
          readings = mvog_ros::laserScanToScan(*scan, map_from_sensor,
                                               std::numeric_limits<double>::infinity(),
                                               kNoSizeLimit, skipped);
          input.skipped_beams += skipped;
        } else {
          readings = mvog_ros::pointCloudToScan(*cloud, map_from_sensor, kNoSizeLimit);
        }
      } catch (const mvog_ros::InvalidMessage&) {
        ++input.invalid_messages;
        continue;
      }
      input.out_of_range_readings += readings.out_of_range.size();
      std::vector<Eigen::Vector3f> out_of_range;
      out_of_range.swap(readings.out_of_range);
      const std::size_t before = readings.hits.size();
      readings.hits.erase(std::remove_if(readings.hits.begin(), readings.hits.end(),
                                         [](const Eigen::Vector3f& p) { return !p.allFinite(); }),
                          readings.hits.end());
      input.non_finite_points += before - readings.hits.size();
      if (!readings.hits.empty()) {
        input.scans.push_back(std::move(readings));
        input.out_of_range.push_back(std::move(out_of_range));
      }
    }
  } catch (const ros::Exception& e) {  // rosbag::BagException and deserialisation errors
    throw InputError(path + ": cannot read the bag: " + e.what());
  }
  if (input.sensor_messages == 0) {
    throw InputError(path +
                     ": the bag has no sensor_msgs/LaserScan or sensor_msgs/PointCloud2 "
                     "messages");
  }
  return input;
}

}  // namespace mvog_bench
