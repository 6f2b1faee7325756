#include <algorithm>
#include <limits>
#include <map>
#include <utility>

#include <image_transport/camera_common.h>
#include <ros/exception.h>

#include <ros/message_traits.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
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

/// The camera infos of the bag by topic and stamp.
using CameraInfos = std::map<std::pair<std::string, ros::Time>, sensor_msgs::CameraInfo::ConstPtr>;

/// A tf2 buffer holding every transform of the bag (its cache spans the whole bag), and every
/// camera info of the bag.
void indexBag(const rosbag::Bag& bag, tf2::BufferCore& buffer, CameraInfos& camera_infos) {
  for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
    if (isMessage<sensor_msgs::CameraInfo>(m)) {
      const sensor_msgs::CameraInfo::ConstPtr info = m.instantiate<sensor_msgs::CameraInfo>();
      camera_infos[{m.getTopic(), info->header.stamp}] = info;
      continue;
    }
    if (!isMessage<tf2_msgs::TFMessage>(m)) continue;
    const bool is_static = m.getTopic() == "/tf_static";
    const tf2_msgs::TFMessage::ConstPtr message = m.instantiate<tf2_msgs::TFMessage>();
    for (const geometry_msgs::TransformStamped& transform : message->transforms) {
      buffer.setTransform(transform, "bag", is_static);
    }
  }
}

/// A sensor message of the bag, read.
struct SensorMessage {
  sensor_msgs::LaserScan::ConstPtr scan;
  sensor_msgs::PointCloud2::ConstPtr cloud;
  sensor_msgs::Image::ConstPtr depth_image;

  const std_msgs::Header& header() const {
    return scan ? scan->header : cloud ? cloud->header : depth_image->header;
  }
};

/// The message if it is range data: a LaserScan, a PointCloud2 or a depth image.
bool readSensorMessage(const rosbag::MessageInstance& m, SensorMessage& message) {
  if (isMessage<sensor_msgs::LaserScan>(m)) {
    message.scan = m.instantiate<sensor_msgs::LaserScan>();
  } else if (isMessage<sensor_msgs::PointCloud2>(m)) {
    message.cloud = m.instantiate<sensor_msgs::PointCloud2>();
  } else if (isMessage<sensor_msgs::Image>(m)) {
    message.depth_image = m.instantiate<sensor_msgs::Image>();
    const std::string& encoding = message.depth_image->encoding;
    return encoding == "16UC1" || encoding == "32FC1";  // REP-118's depth encodings
  } else {
    return false;
  }
  return true;
}

}  // namespace

InputData loadBag(const std::string& path, const std::string& fixed_frame,
                  double depth_no_return_length) {
  InputData input;
  input.format = "bag";
  mvog::DepthImageConfig depth_config;
  depth_config.no_return_length = depth_no_return_length;
  try {
    rosbag::Bag bag(path, rosbag::bagmode::Read);
    rosbag::View everything(bag);
    const ros::Duration span = everything.getEndTime() - everything.getBeginTime();
    tf2::BufferCore buffer(span + ros::Duration(60.0));
    CameraInfos camera_infos;
    indexBag(bag, buffer, camera_infos);

    for (const rosbag::MessageInstance& m : everything) {
      SensorMessage message;
      if (!readSensorMessage(m, message)) continue;
      ++input.sensor_messages;
      const std_msgs::Header& header = message.header();
      sensor_msgs::CameraInfo::ConstPtr camera_info;
      if (message.depth_image) {
        // Paired as image_transport's CameraSubscriber pairs them: the sibling topic, same stamp.
        const auto found =
            camera_infos.find({image_transport::getCameraInfoTopic(m.getTopic()), header.stamp});
        if (found == camera_infos.end()) {
          ++input.without_camera_info;
          continue;
        }
        camera_info = found->second;
      }
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
        std::size_t skipped = 0;
        if (message.scan) {
          readings = mvog_ros::laserScanToScan(*message.scan, map_from_sensor,
                                               std::numeric_limits<double>::infinity(),
                                               kNoSizeLimit, skipped);
          input.skipped_beams += skipped;
        } else if (message.cloud) {
          readings = mvog_ros::pointCloudToScan(*message.cloud, map_from_sensor, kNoSizeLimit);
        } else {
          readings = mvog_ros::depthImageToScan(*message.depth_image, *camera_info, map_from_sensor,
                                                depth_config, kNoSizeLimit, skipped);
          input.skipped_pixels += skipped;
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
                     ": the bag has no sensor_msgs/LaserScan, sensor_msgs/PointCloud2 or depth "
                     "sensor_msgs/Image messages");
  }
  return input;
}

}  // namespace mvog_bench
