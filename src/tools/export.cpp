// Exports a saved MVOG map (no ROS needed):
//   mvog_export MAP --cross-section Z PREFIX        PREFIX.pgm + PREFIX.yaml at height Z (m)
//   mvog_export MAP --projection ZMIN ZMAX PREFIX   PREFIX.pgm + PREFIX.yaml over a height band
//   mvog_export MAP --render PNG                    an oblique view of the occupied space
// The PGM + YAML pairs follow map_server's format: black occupied, white free, grey (205)
// unknown, trinary thresholds; a cross-section's grey levels are 255 * (1 - p).
// Options may repeat; --threshold P (default 0.5) sets the occupancy threshold.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "mvog/column.h"
#include "mvog/height_colour.h"
#include "mvog/map.h"
#include "mvog/map_io.h"

namespace {

constexpr std::uint8_t kUnknownGrey = 205;

/// Writes `contents` to `path` atomically (a temporary file, fsync, rename).
void writeAtomically(const std::string& path, const std::string& contents) {
  mvog::writeFileAtomically(contents.data(), contents.size(), path);
}

/// Grey levels row by row from the top (+y) down, as image viewers and map_server expect.
template <class T, class Grey>
void writeMapServerPair(const mvog::Grid2D<T>& grid, const std::string& prefix, Grey grey) {
  std::ostringstream pgm;
  pgm << "P5\n" << grid.width() << " " << grid.height() << "\n255\n";
  for (std::size_t row = grid.height(); row-- > 0;) {
    for (std::size_t x = 0; x < grid.width(); ++x)
      pgm.put(static_cast<char>(grey(grid.at(x, row))));
  }
  writeAtomically(prefix + ".pgm", pgm.str());
  const std::string image = prefix.substr(prefix.find_last_of('/') + 1) + ".pgm";
  std::ostringstream yaml;
  yaml << "image: " << image << "\nmode: trinary\nresolution: " << grid.resolution << "\norigin: ["
       << grid.originX() << ", " << grid.originY()
       << ", 0.0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n";
  writeAtomically(prefix + ".yaml", yaml.str());
  std::printf("wrote %s.pgm and %s.yaml (%zu x %zu cells)\n", prefix.c_str(), prefix.c_str(),
              grid.width(), grid.height());
}

// ---- A minimal PNG writer: RGB, one zlib stream of stored (uncompressed) deflate blocks. ----

std::uint32_t crc32(const std::uint8_t* data, std::size_t size, std::uint32_t crc = 0) {
  crc = ~crc;
  for (std::size_t k = 0; k < size; ++k) {
    crc ^= data[k];
    for (int bit = 0; bit < 8; ++bit) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

void appendBigEndian(std::string& out, std::uint32_t value) {
  for (int shift = 24; shift >= 0; shift -= 8) out.push_back(static_cast<char>(value >> shift));
}

void appendChunk(std::string& png, const char* type, const std::string& data) {
  appendBigEndian(png, static_cast<std::uint32_t>(data.size()));
  const std::string typed = std::string(type, 4) + data;
  png += typed;
  appendBigEndian(png, crc32(reinterpret_cast<const std::uint8_t*>(typed.data()), typed.size()));
}

std::string encodePng(int width, int height, const std::vector<std::uint8_t>& rgb) {
  std::string raw;  // each row: filter byte 0, then the pixels
  for (int y = 0; y < height; ++y) {
    raw.push_back(0);
    raw.append(reinterpret_cast<const char*>(rgb.data()) + static_cast<std::size_t>(y) * width * 3,
               static_cast<std::size_t>(width) * 3);
  }
  std::string zlib = {0x78, 0x01};
  std::uint32_t a = 1, b = 0;  // Adler-32
  for (unsigned char c : raw) {
    a = (a + c) % 65521;
    b = (b + a) % 65521;
  }
  for (std::size_t offset = 0; offset < raw.size() || offset == 0; offset += 65535) {
    const std::size_t length = std::min<std::size_t>(65535, raw.size() - offset);
    zlib.push_back(offset + length >= raw.size() ? 1 : 0);
    zlib.push_back(static_cast<char>(length & 0xff));
    zlib.push_back(static_cast<char>(length >> 8));
    zlib.push_back(static_cast<char>(~length & 0xff));
    zlib.push_back(static_cast<char>((~length >> 8) & 0xff));
    zlib.append(raw, offset, length);
    if (length == 0) break;
  }
  appendBigEndian(zlib, (b << 16) | a);
  std::string png = "\x89PNG\r\n\x1a\n";
  std::string header;
  appendBigEndian(header, static_cast<std::uint32_t>(width));
  appendBigEndian(header, static_cast<std::uint32_t>(height));
  header += std::string("\x08\x02\x00\x00\x00", 5);  // 8-bit RGB
  appendChunk(png, "IHDR", header);
  appendChunk(png, "IDAT", zlib);
  appendChunk(png, "IEND", "");
  return png;
}

/// Oblique orthographic view of the occupied space (p > threshold): every occupied segment is
/// splatted as a column of cubes with a depth test, coloured by height and shaded by depth.
void renderOccupied(const mvog::Map& map, double threshold, const std::string& path) {
  struct Splat {
    double x, y, z;
  };
  std::vector<Splat> splats;
  double z_min = INFINITY, z_max = -INFINITY;
  const mvog::CellRange bounds = map.bounds();
  const double r = map.resolution();
  for (std::int32_t y = bounds.min.y; !bounds.empty() && y <= bounds.max.y; ++y) {
    for (std::int32_t x = bounds.min.x; x <= bounds.max.x; ++x) {
      for (const mvog::ColumnSegment& s : mvog::columnProfile(map.cellVolumes({x, y}))) {
        if (s.probability <= threshold) continue;
        for (float z = s.bottom + 0.5f; z < s.top; z += 1.0f) {
          splats.push_back({(x + 0.5) * r, (y + 0.5) * r, z * r});
          z_min = std::min(z_min, z * r);
          z_max = std::max(z_max, z * r);
        }
      }
    }
  }
  if (splats.empty()) throw std::runtime_error("nothing is occupied: no render");
  // View from the south-west, 35 degrees above the horizon.
  const double yaw = -0.8, pitch = 0.6;
  auto project = [&](const Splat& s, double& u, double& v, double& depth) {
    const double xr = std::cos(yaw) * s.x - std::sin(yaw) * s.y;
    const double yr = std::sin(yaw) * s.x + std::cos(yaw) * s.y;
    u = xr;
    v = s.z * std::cos(pitch) + yr * std::sin(pitch);
    depth = yr * std::cos(pitch) - s.z * std::sin(pitch);
  };
  double u_min = INFINITY, u_max = -INFINITY, v_min = INFINITY, v_max = -INFINITY;
  for (const Splat& s : splats) {
    double u, v, d;
    project(s, u, v, d);
    u_min = std::min(u_min, u), u_max = std::max(u_max, u);
    v_min = std::min(v_min, v), v_max = std::max(v_max, v);
  }
  const int width = 1200;
  const double scale = (width - 40) / std::max(u_max - u_min, 1e-6);
  const int height = std::clamp(static_cast<int>((v_max - v_min) * scale) + 40, 100, 1600);
  std::vector<std::uint8_t> rgb(static_cast<std::size_t>(width) * height * 3, 40);
  std::vector<double> depth_buffer(static_cast<std::size_t>(width) * height, INFINITY);
  const int radius = std::max(1, static_cast<int>(std::ceil(0.6 * r * scale)));
  for (const Splat& s : splats) {
    double u, v, d;
    project(s, u, v, d);
    const int cu = 20 + static_cast<int>((u - u_min) * scale);
    const int cv = height - 20 - static_cast<int>((v - v_min) * scale);
    const mvog::Rgb colour = mvog::heightColour((s.z - z_min) / std::max(z_max - z_min, 1e-6));
    const float c[3] = {colour.r, colour.g, colour.b};
    for (int dv = -radius; dv <= radius; ++dv) {
      for (int du = -radius; du <= radius; ++du) {
        const int px = cu + du, py = cv + dv;
        if (px < 0 || py < 0 || px >= width || py >= height) continue;
        const std::size_t k = static_cast<std::size_t>(py) * width + px;
        if (d >= depth_buffer[k]) continue;
        depth_buffer[k] = d;
        const float shade = (du == -radius || dv == -radius) ? 0.55f : 0.9f;  // cube edges
        for (int ch = 0; ch < 3; ++ch)
          rgb[k * 3 + ch] = static_cast<std::uint8_t>(255 * c[ch] * shade);
      }
    }
  }
  writeAtomically(path, encodePng(width, height, rgb));
  std::printf("wrote %s (%zu occupied cubes)\n", path.c_str(), splats.size());
}

int usage(const char* program) {
  std::fprintf(stderr,
               "usage: %s MAP [--threshold P] [--cross-section Z PREFIX]... "
               "[--projection ZMIN ZMAX PREFIX]... [--render PNG]\n",
               program);
  return 2;
}

double number(const char* text) {
  char* end = nullptr;
  const double value = std::strtod(text, &end);
  if (end == text || *end != '\0' || !std::isfinite(value)) {
    throw std::runtime_error(std::string("not a finite number: ") + text);
  }
  return value;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) return usage(argv[0]);
  try {
    const mvog::Map map = mvog::loadMap(argv[1]);
    if (map.empty()) throw std::runtime_error("the map is empty");
    double threshold = 0.5;
    for (int k = 2; k < argc; ++k) {
      const std::string option = argv[k];
      if (option == "--threshold" && k + 1 < argc) {
        threshold = number(argv[++k]);
      } else if (option == "--cross-section" && k + 2 < argc) {
        const double z = number(argv[k + 1]);
        writeMapServerPair(map.crossSection(z, map.bounds()), argv[k + 2], [](float p) {
          return std::isnan(p) ? kUnknownGrey
                               : static_cast<std::uint8_t>(std::lround(255.0f * (1.0f - p)));
        });
        k += 2;
      } else if (option == "--projection" && k + 3 < argc) {
        const mvog::Projection projection =
            map.projection(number(argv[k + 1]), number(argv[k + 2]), threshold, map.bounds());
        writeMapServerPair(projection, argv[k + 3], [](mvog::OccupancyState state) {
          return state == mvog::OccupancyState::kOccupied ? std::uint8_t{0}
                 : state == mvog::OccupancyState::kFree   ? std::uint8_t{254}
                                                          : kUnknownGrey;
        });
        k += 3;
      } else if (option == "--render" && k + 1 < argc) {
        renderOccupied(map, threshold, argv[++k]);
      } else {
        return usage(argv[0]);
      }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mvog_export: %s\n", e.what());
    return 1;
  }
  return 0;
}
