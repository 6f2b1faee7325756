#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "mvog/map.h"

namespace mvog {

/// A map file or buffer that cannot be read or written; the message says what is wrong.
class MapFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The binary map format, version 2. Everything little-endian, no padding:
///
///   offset  size  field
///        0     8  magic "MVOGMAP\0"
///        8     4  uint32 format version (2; 1 is read too)
///       12     4  uint32 header size in bytes (64)
///       16     8  float64 resolution (m)
///       24     8  float64 max_coordinate (m)
///       32     8  uint64 number of cells C (cells holding at least one volume)
///       40     8  uint64 number of volumes V (positive and negative)
///       48     4  uint32 the model's rules (ModelRules): bit 0 clip_free_space_at_hits,
///                 bit 1 mass_counting per scan, bit 2 split_free_space_at_obstacles; the other
///                 bits zero
///       52     8  float64 ModelRules::out_of_range_free_length (m, may be infinite)
///       60     4  reserved, zero
/// Version 1 had 16 reserved bytes (zero) at 48: the paper's model.
///       64     .  C cells, each: int32 x, int32 y, uint32 n_positive, uint32 n_negative,
///                 then n_positive + n_negative volumes (float32 bottom, top, mass; heights in
///                 grid units, positive list first, each list sorted upwards)
///   end - 8    8  uint64 FNV-1a 64 checksum of every byte before it
///
/// The file size must equal 64 + 16 C + 12 V + 8, which bounds every count before anything is
/// allocated. Masses are the masses as of saving (decay folded in).
constexpr std::uint32_t kMapFormatVersion = 2;
constexpr std::size_t kMapHeaderBytes = 64;

std::vector<std::uint8_t> serializeMap(const Map& map);
/// Throws MapFileError if `data` is not a complete, valid map (nothing is half-loaded).
Map deserializeMap(const std::uint8_t* data, std::size_t size);

/// Writes atomically: a temporary file in the same directory (`.NAME.saving-XXXXXX`), fsync,
/// then rename over `path`. Throws MapFileError on failure (and leaves any previous file at `path`
/// untouched). Also removes the temporaries that earlier saves of `path`, killed before their
/// rename, left beside it (on a local file system with flock).
void saveMap(const Map& map, const std::string& path);
/// The same for bytes of serializeMap: a caller that shares the map with other threads can
/// serialise under its lock and write after releasing it.
void saveMapBytes(const std::vector<std::uint8_t>& bytes, const std::string& path);
/// Throws MapFileError if the file cannot be read or is not a valid map.
Map loadMap(const std::string& path);
/// Merges `part` (Map::merge, no transform) into the map saved at `path`, or saves it there if
/// there is no file, atomically (saveMap): what a map's tiles dropped by dropTilesFartherThan
/// are kept in. Throws MapFileError, leaving the file as it was, if it cannot be read, is not a
/// valid map or cannot take `part` (another resolution or mass counting).
void mergeIntoMapFile(const Map& part, const std::string& path);

}  // namespace mvog
