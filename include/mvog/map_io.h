#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
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

/// Writes atomically (writeFileAtomically). Throws MapFileError on failure (and leaves any
/// previous file at `path` untouched).
void saveMap(const Map& map, const std::string& path);
/// The same for bytes of serializeMap: a caller that shares the map with other threads can
/// serialise under its lock and write after releasing it.
void saveMapBytes(const std::vector<std::uint8_t>& bytes, const std::string& path);
/// Writes `size` bytes to `path` atomically, whatever they are (maps, the exported images): a
/// temporary file in the same directory (`.NAME.saving-XXXXXX`), fsync, rename over `path`, fsync
/// of the directory. Throws MapFileError on failure (and leaves any previous file at `path`
/// untouched). Also removes the temporaries that earlier writes of `path`, killed before their
/// rename, left beside it (on a local file system with flock).
void writeFileAtomically(const void* data, std::size_t size, const std::string& path);
/// Throws MapFileError if the file cannot be read or is not a valid map.
Map loadMap(const std::string& path);
/// Merges `part` (Map::merge, no transform) into the map saved at `path`, or saves it there if
/// there is no file, atomically (saveMap): what a map's tiles dropped by dropTilesFartherThan
/// are kept in. Throws MapFileError, leaving the file as it was, if it cannot be read, is not a
/// valid map or cannot take `part` (another resolution or mass counting).
void mergeIntoMapFile(const Map& part, const std::string& path);

/// Incremental map updates, format version 1: what changed in a map after a revision, for a
/// mirror (MapMirror) to become equal to it bit for bit. Little-endian, no padding:
///
///   offset  size  field
///        0     8  magic "MVOGUPD\0"
///        8     4  uint32 format version (1)
///       12     4  uint32 header size in bytes (128)
///       16     8  float64 resolution (m)
///       24     8  float64 max_coordinate (m)
///       32     4  uint32 the model's rules, as in the map file (offset 48 there)
///       36     8  float64 ModelRules::out_of_range_free_length (m, may be infinite)
///       44     4  uint32 flags: bit 0 full (the mirror drops every tile first and takes this
///                 configuration; the from revision is 0 and no tile is listed removed); the
///                 other bits zero
///       48     8  uint64 source: the id of the map it comes from (a number that tells maps apart)
///       56     8  uint64 from revision: the update holds every change of the source after it
///       64     8  uint64 to revision: up to and including this one (the source's revision())
///       72     8  float64 mass unit, in (0.5, 1]
///       80     8  int64 unit exponent, in [-2^24, 0]: a tile of exponent e stores masses in
///                 units of mass unit * 2^(unit exponent - e) (Map::decay: a decay step changes
///                 these two only, so an update after one lists no tile)
///       88     8  uint64 R, tiles removed
///       96     8  uint64 T, tiles changed
///      104     8  uint64 C, cells of the tiles changed
///      112     8  uint64 V, their volumes
///      120     8  reserved, zero
///      128     .  R tiles removed: int32 tile x, int32 tile y (Map::TileIndex); each once, none
///                 among the tiles changed
///              .  T tiles changed, in rows from the lowest (by tile y, then x), each once:
///                 int32 tile x, int32 tile y, int32 exponent (in [unit exponent, 2^24]), uint32 n
///                 (1 to 256), then the tile's n cells in the map file's cell encoding (int32 x,
///                 int32 y, uint32 n_positive, uint32 n_negative, volumes of float32 bottom, top,
///                 mass), the masses as stored (in the tile's unit), the cells in the tile's
///                 order (rows along +x, from the lowest) and inside it. A cell of the tile not
///                 listed holds nothing.
///   end - 8    8  uint64 FNV-1a 64 checksum of every byte before it
///
/// The size must equal 128 + 8 R + 16 T + 16 C + 12 V + 8, which bounds every count before
/// anything is allocated; every list must satisfy the constraints under the update's rules (a
/// free list is stored as the merge cuts it, as Map::setCellVolumes stores it: what a source
/// built by mvog sends already).
constexpr std::uint32_t kMapUpdateFormatVersion = 1;
constexpr std::size_t kMapUpdateHeaderBytes = 128;

/// What an update says about itself (its header).
struct MapUpdateInfo {
  bool full = false;  ///< every tile of the source (the mirror starts again from it)
  std::uint64_t source = 0;
  std::uint64_t from_revision = 0;  ///< it holds every change of the source after this revision
  std::uint64_t to_revision = 0;    ///< up to and including this one
  double resolution = 0.0;
  std::size_t tiles_changed = 0;
  std::size_t tiles_removed = 0;
};

/// An update of `map` with what changed after `since_revision` (usually the map's revision() at
/// the previous update): every cell of the tiles modified since, the tiles removed since, and
/// the mass unit (which decay changes without marking a tile). It is a full update, holding
/// every tile, when the map cannot tell what changed: `since_revision` 0 or later than the
/// map's revision (another map's), clear() or more removals than the map remembers since, or a
/// decay step since that rebased the tiles' exponents (once per 2^24 binary orders of decay).
/// Its size grows with what changed, not with the map.
std::vector<std::uint8_t> serializeMapUpdate(const Map& map, std::uint64_t since_revision);
/// The header of an update, checked with its checksum (not the tiles). Throws MapFileError.
MapUpdateInfo readMapUpdateInfo(const std::uint8_t* data, std::size_t size);

enum class MapUpdateStatus : std::uint8_t {
  kApplied,  ///< the mirror now equals the source at the update's to_revision
  kMissed,   ///< not applied: it starts after the mirror's revision (updates were missed), or
             ///< comes from another source than the mirror's (or there is none yet); the mirror
             ///< needs a full update
  kOutdated  ///< not applied: it ends before the mirror's revision of the same source
};

struct MapUpdateResult {
  MapUpdateStatus status = MapUpdateStatus::kMissed;
  MapUpdateInfo update;
};

/// A map rebuilt from another map's updates (serializeMapUpdate), equal to it bit for bit after
/// each (serializeMap gives the same bytes), decay included. It starts from a full update;
/// then each update must start at or before the revision it holds (from_revision <= it <=
/// to_revision), so that a missed update is detected, never silently skipped. Its map is an
/// ordinary map: queries, publication (tilesModifiedSince, tilesRemovedSince: a full update
/// changes every tile), saving, and updates of its own for mirrors further on.
class MapMirror {
 public:
  /// Applies an update if it follows what the mirror holds (see MapUpdateStatus). Throws
  /// MapFileError, changing nothing, for bytes that are not a complete, valid update, or an
  /// incremental one that contradicts its source's earlier ones (another configuration, a mass
  /// unit grown).
  MapUpdateResult apply(const std::uint8_t* data, std::size_t size);
  const Map& map() const { return map_; }
  /// Exchanges the mirror's map with `other`, for a caller that keeps the map where others read
  /// it under a lock (a server's shared map): it swaps the map in before apply() and back out
  /// after. Anything else done to the map meanwhile makes the updates that follow describe
  /// another map than the one they are applied to.
  void swapMap(Map& other) noexcept { std::swap(map_, other); }
  /// The source's revision the map equals (0: no full update applied yet).
  std::uint64_t sourceRevision() const { return source_revision_; }

 private:
  Map map_;
  std::uint64_t source_ = 0;
  std::uint64_t source_revision_ = 0;
};

}  // namespace mvog
