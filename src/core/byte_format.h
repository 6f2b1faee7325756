// What the map file and the map update formats share (internal to the core): little-endian
// values, the checksum, the model's rules as bits, and the cell encoding.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "mvog/config.h"
#include "mvog/map.h"

namespace mvog {
namespace detail {

static_assert(sizeof(float) == 4 && sizeof(double) == 8, "IEEE 754 sizes assumed");

constexpr std::size_t kChecksumBytes = 8;
/// int32 x, int32 y, uint32 n_positive, uint32 n_negative (then the volumes).
constexpr std::size_t kCellRecordBytes = 16;
constexpr std::size_t kVolumeRecordBytes = 12;

inline std::uint64_t fnv1a64(const std::uint8_t* data, std::size_t size) {
  std::uint64_t hash = 0xcbf29ce484222325ull;
  for (std::size_t k = 0; k < size; ++k) {
    hash ^= data[k];
    hash *= 0x100000001b3ull;
  }
  return hash;
}

/// Appends values little-endian, whatever the host's byte order.
class Writer {
 public:
  explicit Writer(std::vector<std::uint8_t>& out) : out_(out) {}
  void bytes(const void* data, std::size_t size) {
    const auto* p = static_cast<const std::uint8_t*>(data);
    for (std::size_t k = 0; k < size; ++k) out_.push_back(p[k]);
  }
  void u32(std::uint32_t v) { unsignedLe(v, 4); }
  void u64(std::uint64_t v) { unsignedLe(v, 8); }
  void i32(std::int32_t v) { u32(static_cast<std::uint32_t>(v)); }
  void i64(std::int64_t v) { u64(static_cast<std::uint64_t>(v)); }
  void f32(float v) {
    std::uint32_t bits;
    std::memcpy(&bits, &v, 4);
    u32(bits);
  }
  void f64(double v) {
    std::uint64_t bits;
    std::memcpy(&bits, &v, 8);
    u64(bits);
  }
  /// The checksum of everything written so far, appended.
  void checksum() { u64(fnv1a64(out_.data(), out_.size())); }

 private:
  void unsignedLe(std::uint64_t v, int size) {
    for (int k = 0; k < size; ++k) out_.push_back(static_cast<std::uint8_t>(v >> (8 * k)));
  }
  std::vector<std::uint8_t>& out_;
};

/// Reads little-endian values; the caller has checked that they are there.
class Reader {
 public:
  Reader(const std::uint8_t* data, std::size_t offset) : data_(data), offset_(offset) {}
  std::uint32_t u32() { return static_cast<std::uint32_t>(unsignedLe(4)); }
  std::uint64_t u64() { return unsignedLe(8); }
  std::int32_t i32() { return static_cast<std::int32_t>(u32()); }
  std::int64_t i64() { return static_cast<std::int64_t>(u64()); }
  float f32() {
    const std::uint32_t bits = u32();
    float v;
    std::memcpy(&v, &bits, 4);
    return v;
  }
  double f64() {
    const std::uint64_t bits = u64();
    double v;
    std::memcpy(&v, &bits, 8);
    return v;
  }
  std::size_t offset() const { return offset_; }

 private:
  std::uint64_t unsignedLe(int size) {
    std::uint64_t v = 0;
    for (int k = 0; k < size; ++k) v |= std::uint64_t{data_[offset_ + k]} << (8 * k);
    offset_ += static_cast<std::size_t>(size);
    return v;
  }
  const std::uint8_t* data_;
  std::size_t offset_;
};

/// Whether the last 8 bytes of data[0, size) (size >= 8) are the checksum of those before.
inline bool checksumMatches(const std::uint8_t* data, std::size_t size) {
  const std::size_t checksum_offset = size - kChecksumBytes;
  return Reader(data, checksum_offset).u64() == fnv1a64(data, checksum_offset);
}

/// The model's rules as stored: bit 0 clip_free_space_at_hits, bit 1 per-scan mass_counting,
/// bit 2 split_free_space_at_obstacles (out_of_range_free_length is a field of its own).
constexpr std::uint32_t kAllRuleBits = 7u;
std::uint32_t rulesBits(const ModelRules& rules);
/// The rules of those bits, with the paper's out_of_range_free_length.
ModelRules rulesOf(std::uint32_t bits);

/// Appends a cell in the map file's cell encoding: int32 x, int32 y, uint32 n_positive,
/// uint32 n_negative, then the volumes (float32 bottom, top, mass), positive list first.
void writeCell(Writer& writer, const CellIndex& cell, const Volume* positive,
               std::uint32_t num_positive, const Volume* negative, std::uint32_t num_negative);
/// Reads a cell in that encoding into `cell` and `volumes`, whose bytes the caller has checked
/// are there for up to `volumes_left` volumes. Returns what is wrong with it (a cell without a
/// volume, or with more than `volumes_left`), empty if nothing; the lists are not checked.
std::string readCell(Reader& reader, std::uint64_t volumes_left, CellIndex& cell,
                     CellVolumes& volumes);

}  // namespace detail
}  // namespace mvog
