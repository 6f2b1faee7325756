#include "mvog/map_io.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <unordered_set>

#include "byte_format.h"
#include "tile_block.h"

namespace mvog {
namespace {

constexpr char kMapFileMagic[8] = {'M', 'V', 'O', 'G', 'M', 'A', 'P', '\0'};
constexpr std::size_t kCellRecordBytes = detail::kCellRecordBytes;
constexpr std::size_t kChecksumBytes = detail::kChecksumBytes;
using detail::Reader;
using detail::Writer;

[[noreturn]] void invalidMap(const std::string& what) {
  throw MapFileError("invalid map: " + what);
}

std::string systemError(const std::string& what, const std::string& path) {
  return what + " '" + path + "': " + std::strerror(errno);
}

}  // namespace

std::vector<std::uint8_t> serializeMap(const Map& map) {
  // Two passes over the volumes (forEachVolume gives each cell's positives, then its negatives,
  // a cell at a time): the first counts them for the header, the second writes each cell once
  // its volumes have passed. Beside the map and its bytes, only one cell's volumes are held.
  std::size_t cell_count = 0;
  std::size_t volume_count = 0;
  CellIndex counted{};
  map.forEachVolume([&](const CellIndex& cell, VolumeSign, const Volume&) {
    if (volume_count == 0 || cell != counted) ++cell_count;
    counted = cell;
    ++volume_count;
  });

  std::vector<std::uint8_t> out;
  out.reserve(kMapHeaderBytes + kCellRecordBytes * cell_count +
              detail::kVolumeRecordBytes * volume_count + kChecksumBytes);
  Writer writer(out);
  writer.bytes(kMapFileMagic, sizeof(kMapFileMagic));
  writer.u32(kMapFormatVersion);
  writer.u32(static_cast<std::uint32_t>(kMapHeaderBytes));
  writer.f64(map.config().resolution);
  writer.f64(map.config().max_coordinate);
  writer.u64(cell_count);
  writer.u64(volume_count);
  writer.u32(detail::rulesBits(map.config().rules));
  writer.f64(map.config().rules.out_of_range_free_length);
  writer.u32(0);
  CellIndex current{};
  CellVolumes volumes;
  auto write_current = [&] {
    if (volumes.positive.empty() && volumes.negative.empty()) return;
    detail::writeCell(writer, current, volumes.positive.data(),
                      static_cast<std::uint32_t>(volumes.positive.size()), volumes.negative.data(),
                      static_cast<std::uint32_t>(volumes.negative.size()));
    volumes.positive.clear();
    volumes.negative.clear();
  };
  map.forEachVolume([&](const CellIndex& cell, VolumeSign sign, const Volume& volume) {
    if (cell != current) write_current();
    current = cell;
    (sign == VolumeSign::kPositive ? volumes.positive : volumes.negative).push_back(volume);
  });
  write_current();
  writer.checksum();
  return out;
}

Map deserializeMap(const std::uint8_t* data, std::size_t size) {
  if (data == nullptr || size < kMapHeaderBytes + kChecksumBytes) {
    invalidMap("truncated: " + std::to_string(size) +
               " bytes is less than a header and a checksum");
  }
  if (std::memcmp(data, kMapFileMagic, sizeof(kMapFileMagic)) != 0) {
    invalidMap("not an MVOG map (bad magic)");
  }
  Reader header(data, sizeof(kMapFileMagic));
  const std::uint32_t version = header.u32();
  if (version != kMapFormatVersion && version != 1) {
    invalidMap("format version " + std::to_string(version) + " is not supported (expected 1 or " +
               std::to_string(kMapFormatVersion) + ")");
  }
  if (header.u32() != kMapHeaderBytes) invalidMap("unexpected header size");
  MapConfig config;
  config.resolution = header.f64();
  config.max_coordinate = header.f64();
  const std::uint64_t cell_count = header.u64();
  const std::uint64_t volume_count = header.u64();
  const std::uint32_t rules = header.u32();
  if (version == 1) {
    // Version 1's 16 bytes at 48 were reserved (zero): its maps are the paper's model.
    if (rules != 0 || header.u64() != 0 || header.u32() != 0) {
      invalidMap("reserved header bytes are not zero");
    }
    config.rules = ModelRules::paper();
  } else {
    if (rules & ~detail::kAllRuleBits) invalidMap("unknown bits in the model's rules");
    config.rules = detail::rulesOf(rules);
    config.rules.out_of_range_free_length = header.f64();
    if (header.u32() != 0) invalidMap("reserved header bytes are not zero");
  }
  // Check the counts against the real size before trusting them for anything.
  const std::size_t body = size - kMapHeaderBytes - kChecksumBytes;
  if (cell_count > body / kCellRecordBytes || volume_count > body / detail::kVolumeRecordBytes ||
      cell_count * kCellRecordBytes + volume_count * detail::kVolumeRecordBytes != body) {
    invalidMap("the header's counts (" + std::to_string(cell_count) + " cells, " +
               std::to_string(volume_count) + " volumes) do not match the size of " +
               std::to_string(size) + " bytes (truncated or corrupted)");
  }
  if (!detail::checksumMatches(data, size)) invalidMap("checksum mismatch (corrupted)");
  Map map = [&] {
    try {
      return Map(config);
    } catch (const ConfigError& e) {
      invalidMap(std::string("bad header: ") + e.what());
    }
  }();

  // The cells go to the map in batches of whole tiles, so that beside the bytes and the map only
  // a batch of cells is held (and `seen`, a key a cell). A file from serializeMap lists a tile's
  // cells together; in another order a batch rewrites every tile it touches, up to once a cell
  // (slower, the same map). A batch's constraint error may come before a later cell's format
  // error; a failed read discards the map either way.
  constexpr std::size_t kCellsPerBatch = 4096;
  Reader reader(data, kMapHeaderBytes);
  std::unordered_set<std::uint64_t> seen;
  std::uint64_t volumes_read = 0;
  std::vector<Map::CellAssignment> batch;
  auto apply_batch = [&] {
    try {
      map.setCellVolumes(batch);  // checks the constraints and max_coordinate
    } catch (const ConfigError& e) {
      invalidMap(e.what());
    }
    batch.clear();
  };
  for (std::uint64_t c = 0; c < cell_count; ++c) {
    Map::CellAssignment assignment;
    const std::string problem =
        detail::readCell(reader, volume_count - volumes_read, assignment.cell, assignment.volumes);
    if (!problem.empty()) invalidMap(problem);
    const CellIndex& cell = assignment.cell;
    if (!seen.insert(detail::cellKey(cell)).second) {
      invalidMap(detail::cellName(cell).append(" appears twice"));
    }
    volumes_read += assignment.volumes.positive.size() + assignment.volumes.negative.size();
    if (batch.size() >= kCellsPerBatch &&
        detail::tileKeyOf(cell) != detail::tileKeyOf(batch.back().cell)) {
      apply_batch();
    }
    batch.push_back(std::move(assignment));
  }
  if (volumes_read != volume_count) invalidMap("fewer volumes than the header counts");
  apply_batch();
  return map;
}

namespace {

// A save writes `.NAME.saving-XXXXXX` beside NAME (mkstemp's template): hidden, and a name no
// map path of the server can take (src/ros/map_paths.cpp refuses hidden names).
std::string temporaryPrefix(const std::filesystem::path& target) {
  return "." + target.filename().string() + ".saving-";
}
constexpr std::size_t kTemporaryRandomChars = 6;
constexpr int kTemporaryAttempts = 100;

bool sameFile(int fd, const std::string& path) {
  struct stat by_fd {};
  struct stat by_path {};
  return ::fstat(fd, &by_fd) == 0 && ::lstat(path.c_str(), &by_path) == 0 &&
         by_fd.st_dev == by_path.st_dev && by_fd.st_ino == by_path.st_ino;
}

/// A temporary of a save to `path`, locked (flock) until the save ends: the lock goes with the
/// process, so a temporary nobody holds locked is the leftover of a killed save. On a file system
/// without flock the temporary stays unlocked, and no clean-up there can tell leftovers (it
/// removes none). Assumes a local file system: over NFS, flock is emulated per process.
int createLockedTemporary(const std::string& path, std::string& temporary) {
  const std::filesystem::path target(path);
  for (int attempt = 0; attempt < kTemporaryAttempts; ++attempt) {
    temporary = (target.parent_path() / temporaryPrefix(target)).string() +
                std::string(kTemporaryRandomChars, 'X');
    const int fd = ::mkostemp(temporary.data(), O_CLOEXEC);
    if (fd < 0) throw MapFileError(systemError("cannot create a temporary file beside", path));
    if (::flock(fd, LOCK_EX) != 0) return fd;
    if (sameFile(fd, temporary)) return fd;
    // Between mkostemp and flock, another save's clean-up took it for a leftover and removed it.
    ::close(fd);
  }
  throw MapFileError("cannot keep a temporary file beside '" + path + "': removed " +
                     std::to_string(kTemporaryAttempts) + " times by other saves");
}

/// Removes the temporaries that saves of `path` killed before their rename left (a robot's
/// autosave killed again and again would otherwise fill its disk). Best effort: a temporary that
/// cannot be inspected stays.
void removeLeftoverTemporaries(const std::string& path) {
  const std::filesystem::path target(path);
  const std::string prefix = temporaryPrefix(target);
  const std::filesystem::path directory =
      target.has_parent_path() ? target.parent_path() : std::filesystem::path(".");
  std::error_code error;
  for (std::filesystem::directory_iterator it(directory, error), end; !error && it != end;
       it.increment(error)) {
    const std::string name = it->path().filename().string();
    if (name.size() != prefix.size() + kTemporaryRandomChars ||
        name.compare(0, prefix.size(), prefix) != 0) {
      continue;
    }
    const std::string candidate = it->path().string();
    // Not following links, not blocking on a FIFO; read-write, as flock over NFS requires.
    const int fd = ::open(candidate.c_str(), O_RDWR | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) continue;
    struct stat status {};
    if (::fstat(fd, &status) == 0 && S_ISREG(status.st_mode) &&
        ::flock(fd, LOCK_EX | LOCK_NB) == 0 && sameFile(fd, candidate)) {
      ::unlink(candidate.c_str());  // before close: the lock is held until it is gone
    }
    ::close(fd);
  }
}

}  // namespace

void saveMap(const Map& map, const std::string& path) { saveMapBytes(serializeMap(map), path); }

void saveMapBytes(const std::vector<std::uint8_t>& bytes, const std::string& path) {
  writeFileAtomically(bytes.data(), bytes.size(), path);
}

void writeFileAtomically(const void* data, std::size_t size, const std::string& path) {
  const auto* bytes = static_cast<const std::uint8_t*>(data);
  removeLeftoverTemporaries(path);
  std::string temporary;
  const int fd = createLockedTemporary(path, temporary);
  auto abandon = [&](const std::string& message) {
    ::unlink(temporary.c_str());
    ::close(fd);
    throw MapFileError(message);
  };
  std::size_t written = 0;
  while (written < size) {
    const ssize_t n = ::write(fd, bytes + written, size - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) abandon(systemError("cannot write", temporary));
    written += static_cast<std::size_t>(n);
  }
  if (::fchmod(fd, 0644) != 0) abandon(systemError("cannot set the permissions of", temporary));
  if (::fsync(fd) != 0) abandon(systemError("cannot flush", temporary));
  // Renamed while still open and locked, so that no clean-up takes it for a leftover.
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    abandon(systemError("cannot rename the temporary file to", path));
  }
  ::close(fd);  // the data is already on disk (fsync): nothing left for close to report
  // Make the rename itself durable.
  const std::size_t slash = path.find_last_of('/');
  const std::string directory = slash == std::string::npos ? "." : path.substr(0, slash + 1);
  const int dir_fd = ::open(directory.c_str(), O_RDONLY | O_DIRECTORY);
  if (dir_fd >= 0) {
    ::fsync(dir_fd);
    ::close(dir_fd);
  }
}

Map loadMap(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY);
  if (fd < 0) throw MapFileError(systemError("cannot open", path));
  struct stat status {};
  if (::fstat(fd, &status) != 0 || !S_ISREG(status.st_mode)) {
    ::close(fd);
    throw MapFileError("not a regular file: '" + path + "'");
  }
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(status.st_size));
  std::size_t read_bytes = 0;
  while (read_bytes < bytes.size()) {
    const ssize_t n = ::read(fd, bytes.data() + read_bytes, bytes.size() - read_bytes);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    read_bytes += static_cast<std::size_t>(n);
  }
  ::close(fd);
  if (read_bytes != bytes.size()) throw MapFileError("cannot read all of '" + path + "'");
  try {
    return deserializeMap(bytes.data(), bytes.size());
  } catch (const MapFileError& e) {
    throw MapFileError("'" + path + "': " + e.what());
  }
}

void mergeIntoMapFile(const Map& part, const std::string& path) {
  std::error_code error;
  if (!std::filesystem::exists(path, error)) {
    if (error) throw MapFileError("cannot inspect '" + path + "': " + error.message());
    saveMap(part, path);
    return;
  }
  Map saved = loadMap(path);
  try {
    saved.merge(part);
  } catch (const ConfigError& e) {
    throw MapFileError("cannot merge into '" + path + "': " + e.what());
  }
  saveMap(saved, path);
}

}  // namespace mvog
