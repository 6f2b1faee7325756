#include "input.h"

#include <fstream>
#include <utility>

#include "truth.h"

namespace mvog_bench {

std::size_t InputData::readings() const {
  std::size_t total = 0;
  for (const mvog::Scan& scan : scans) total += scan.hits.size();
  return total;
}

InputData inputOfScans(const std::string& format, std::vector<mvog::Scan> scans) {
  InputData input;
  input.format = format;
  for (mvog::Scan& scan : scans) {
    ++input.sensor_messages;
    input.out_of_range_readings += scan.out_of_range.size();
    input.out_of_range.push_back(std::move(scan.out_of_range));
    scan.out_of_range.clear();
    input.scans.push_back(std::move(scan));
  }
  return input;
}

InputData loadInput(const std::string& path, const std::string& fixed_frame,
                    double depth_no_return_length) {
  InputData input;
  if (std::string_view(path).substr(0, kSyntheticPrefix.size()) == kSyntheticPrefix) {
    input = loadSynthetic(path.substr(kSyntheticPrefix.size()));
  } else if (std::string_view(path).substr(0, kTruthPrefix.size()) == kTruthPrefix) {
    input = loadTruth(truthScene(path.substr(kTruthPrefix.size())));
  } else {
    std::ifstream file(path, std::ios::binary);
    if (!file) throw InputError(path + ": cannot open the file (missing or unreadable)");
    static const std::string kBagMagic = "#ROSBAG V2.0\n";
    std::string head(kBagMagic.size(), '\0');
    file.read(&head[0], static_cast<std::streamsize>(head.size()));
    head.resize(static_cast<std::size_t>(file.gcount()));
    file.close();
    if (head == kBagMagic) {
      input = loadBag(path, fixed_frame, depth_no_return_length);
    } else if (path.size() >= 6 && path.compare(path.size() - 6, 6, ".graph") == 0) {
      input = loadScanGraph(path);
    } else {
      throw InputError(path + ": neither a ROS bag (format 2.0) nor an OctoMap ScanGraph (.graph)");
    }
  }
  if (input.readings() == 0) {
    throw InputError(path + ": no obstacle readings to insert (" +
                     std::to_string(input.sensor_messages) + " sensor messages, " +
                     std::to_string(input.without_transform) + " without a transform, " +
                     std::to_string(input.without_camera_info) + " without camera info, " +
                     std::to_string(input.invalid_messages) + " malformed)");
  }
  return input;
}

}  // namespace mvog_bench
