// libFuzzer target: the map update decoder, mvog::MapMirror::apply, on arbitrary bytes.
//
// Whatever the bytes, apply returns a status or throws MapFileError, and then the mirror is as
// it was: no crash, no undefined behaviour, no allocation beyond what the size bounds. The bytes
// go to a mirror holding nothing, and to one holding a small map under the source and revision
// the bytes name (so that incremental updates reach the decoder of tiles); then again with their
// last 8 bytes made their checksum (so that mutations reach past it). A mirror that applied them
// holds a valid map: it serialises, its serialisation loads back to the same bytes, and a full
// update of it rebuilds it bit for bit in another mirror.
// Also replayed without libFuzzer by fuzz_replay (test/fuzz/corpus and test/fuzz/regressions).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "mvog/map.h"
#include "mvog/map_io.h"

namespace {

void check(bool condition) {
  if (!condition) std::abort();
}

void putLe(std::vector<std::uint8_t>& bytes, std::size_t offset, std::uint64_t value) {
  for (int k = 0; k < 8; ++k) bytes[offset + k] = static_cast<std::uint8_t>(value >> (8 * k));
}

/// Makes the last 8 bytes the FNV-1a 64 checksum of those before (map_io.h).
void fixChecksum(std::vector<std::uint8_t>& bytes) {
  std::uint64_t hash = 0xcbf29ce484222325ull;
  for (std::size_t k = 0; k + 8 < bytes.size(); ++k) hash = (hash ^ bytes[k]) * 0x100000001b3ull;
  putLe(bytes, bytes.size() - 8, hash);
}

/// A full update of the small map of make_seeds.py's map_update seeds, naming `source` at
/// `revision` (the offsets and the checksum of map_io.h's layout).
std::vector<std::uint8_t> baseUpdate(std::uint64_t source, std::uint64_t revision) {
  static const std::vector<std::uint8_t> base = [] {
    mvog::MapConfig config;
    config.resolution = 1.0;
    config.max_coordinate = 1000.0;
    mvog::Map map(config);
    map.setCellVolumes({{{3, 4}, {{{0, 1, 2}}, {{-4, -1, 3}}}},
                        {{5, 4}, {{}, {{2, 5, 3}}}},
                        {{17, 0}, {{{1, 2, 1}}, {}}},
                        {{-3, 40}, {{{0, 2, 2}}, {}}}});
    return mvog::serializeMapUpdate(map, 0);
  }();
  std::vector<std::uint8_t> bytes = base;
  putLe(bytes, 48, source);
  putLe(bytes, 64, revision);
  fixChecksum(bytes);
  return bytes;
}

void checkHoldsAValidMap(const mvog::MapMirror& mirror) {
  const std::vector<std::uint8_t> bytes = mvog::serializeMap(mirror.map());
  const mvog::Map again = mvog::deserializeMap(bytes.data(), bytes.size());
  check(mvog::serializeMap(again) == bytes);
  const std::vector<std::uint8_t> full = mvog::serializeMapUpdate(mirror.map(), 0);
  mvog::MapMirror rebuilt;
  check(rebuilt.apply(full.data(), full.size()).status == mvog::MapUpdateStatus::kApplied);
  check(mvog::serializeMap(rebuilt.map()) == bytes);
}

void feed(mvog::MapMirror& mirror, const std::uint8_t* data, std::size_t size) {
  const std::vector<std::uint8_t> before = mvog::serializeMap(mirror.map());
  const std::uint64_t revision = mirror.sourceRevision();
  try {
    if (mirror.apply(data, size).status == mvog::MapUpdateStatus::kApplied) {
      checkHoldsAValidMap(mirror);
      return;
    }
  } catch (const mvog::MapFileError&) {
    // refused, with a message: the expected outcome for almost every input
  }
  check(mvog::serializeMap(mirror.map()) == before && mirror.sourceRevision() == revision);
}

/// The bytes to an empty mirror, and to one synchronised with the source they name.
void feedBoth(const std::uint8_t* data, std::size_t size) {
  mvog::MapMirror empty;
  feed(empty, data, size);
  mvog::MapUpdateInfo info;
  try {
    info = mvog::readMapUpdateInfo(data, size);
  } catch (const mvog::MapFileError&) {
    return;
  }
  if (info.full) return;
  mvog::MapMirror synced;
  const std::vector<std::uint8_t> base =
      baseUpdate(info.source, std::max<std::uint64_t>(info.from_revision, 1));
  check(synced.apply(base.data(), base.size()).status == mvog::MapUpdateStatus::kApplied);
  feed(synced, data, size);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  feedBoth(data, size);
  if (size >= 8) {
    std::vector<std::uint8_t> checksummed(data, data + size);
    fixChecksum(checksummed);
    feedBoth(checksummed.data(), checksummed.size());
  }
  return 0;
}
