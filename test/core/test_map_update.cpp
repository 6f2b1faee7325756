// Incremental map updates (map_io.h) and MapMirror: a mirror equals its source bit for bit
// after each update, a missed update is detected, and corrupt or foreign bytes are refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "mvog/map.h"
#include "mvog/map_io.h"
#include "test_util.h"

namespace mvog {
namespace {

using Bytes = std::vector<std::uint8_t>;
using test::fixChecksum;
using test::fnv1a64;
using test::putLe;

Bytes updateOf(const Map& map, std::uint64_t since) { return serializeMapUpdate(map, since); }

MapUpdateResult applyTo(MapMirror& mirror, const Bytes& bytes) {
  return mirror.apply(bytes.data(), bytes.size());
}

/// The mirror holds exactly the source's map.
::testing::AssertionResult mirrors(const MapMirror& mirror, const Map& source) {
  if (serializeMap(mirror.map()) != serializeMap(source)) {
    return ::testing::AssertionFailure()
           << "the maps differ: "
           << ::testing::PrintToString(
                  test::sameVolumes(test::allVolumes(mirror.map()), test::allVolumes(source))
                      .message());
  }
  if (mirror.sourceRevision() != source.revision()) {
    return ::testing::AssertionFailure() << "source revision " << mirror.sourceRevision()
                                         << ", the source is at " << source.revision();
  }
  return ::testing::AssertionSuccess();
}

// ---- Following a source ------------------------------------------------------------------------

TEST(MapUpdate, AMirrorFollowsItsSourceBitForBitThroughEveryKindOfChange) {
  Map source = test::randomMap(1, 0.2, 5.0, 2);
  MapMirror mirror;
  EXPECT_EQ(mirror.sourceRevision(), 0u);
  const MapUpdateResult first = applyTo(mirror, updateOf(source, 0));
  EXPECT_EQ(first.status, MapUpdateStatus::kApplied);
  EXPECT_TRUE(first.update.full);
  EXPECT_TRUE(mirrors(mirror, source));
  MapMirror chained;  // a mirror of the mirror
  EXPECT_EQ(applyTo(chained, updateOf(mirror.map(), 0)).status, MapUpdateStatus::kApplied);

  std::mt19937 rng(2);
  std::uint64_t sent = source.revision();
  std::uint64_t chained_sent = mirror.map().revision();
  for (int step = 0; step < 64; ++step) {
    const Eigen::Vector3d somewhere = test::randomPoint(rng, 4.0, 1.0);
    switch (step % 8) {
      case 0:
      case 1:
        source.insertScan(test::randomScan(rng, somewhere, 400, 150, 5.0));
        break;
      case 2:
        source.decay(0.7);
        break;
      case 3:
        source.forget(0.4);
        break;
      case 4:
        source.clearBox(somewhere, somewhere + Eigen::Vector3d(1.5, 2.0, 0.7));
        break;
      case 5:
        source.dropTilesFartherThan(somewhere.head<2>(), 5.0);
        break;
      case 6:
        source.setCellVolumes(source.cellAtPoint(somewhere.x(), somewhere.y()),
                              step % 16 == 6 ? CellVolumes{} : CellVolumes{{{0, 1, 1}}, {}});
        break;
      default: {
        InsertionConfig threads;
        threads.insertion_threads = 2;
        source.insertScan(test::randomScan(rng, somewhere, 400, 150, 5.0), threads);
      }
    }
    if (step == 40) source.clear();
    const Bytes bytes = updateOf(source, sent);
    sent = source.revision();
    const MapUpdateResult result = applyTo(mirror, bytes);
    ASSERT_EQ(result.status, MapUpdateStatus::kApplied) << "step " << step;
    EXPECT_EQ(result.update.full, step == 40) << "step " << step;
    ASSERT_TRUE(mirrors(mirror, source)) << "step " << step;
    const Bytes chained_bytes = updateOf(mirror.map(), chained_sent);
    chained_sent = mirror.map().revision();
    ASSERT_EQ(applyTo(chained, chained_bytes).status, MapUpdateStatus::kApplied) << "step " << step;
    ASSERT_EQ(serializeMap(chained.map()), serializeMap(source)) << "step " << step;
  }
}

TEST(MapUpdate, ADecayStepIsAnUpdateOfNoTileAndIsFollowedExactly) {
  Map source = test::randomMap(3, 0.2, 5.0);
  MapMirror mirror;
  applyTo(mirror, updateOf(source, 0));
  for (double k_d : {0.9, 0.37, 1e-5, 0.999}) {
    const std::uint64_t sent = source.revision();
    source.decay(k_d);
    const Bytes bytes = updateOf(source, sent);
    EXPECT_EQ(readMapUpdateInfo(bytes.data(), bytes.size()).tiles_changed, 0u);
    EXPECT_EQ(bytes.size(), kMapUpdateHeaderBytes + 8);
    applyTo(mirror, bytes);
    EXPECT_TRUE(mirrors(mirror, source));
  }
  // Later scans rescale the tiles they write, on both sides alike.
  std::mt19937 rng(4);
  const std::uint64_t sent = source.revision();
  source.insertScan(test::randomScan(rng, {0, 0, 0}, 500, 100, 5.0));
  applyTo(mirror, updateOf(source, sent));
  EXPECT_TRUE(mirrors(mirror, source));
}

TEST(MapUpdate, AMirrorWhoseMapIsKeptElsewhereFollowsWhileItIsSwappedInForEachUpdate) {
  // A server keeps its map in a place of its own, under its lock: the mirror's map lives there
  // between updates and is swapped into the mirror for each.
  Map source = test::randomMap(8, 0.2, 5.0);
  std::mt19937 rng(8);
  MapMirror mirror;
  Map kept;
  std::uint64_t sent = 0;
  for (int step = 0; step < 6; ++step) {
    if (step % 3 == 2) source.decay(0.8);
    source.insertScan(test::randomScan(rng, test::randomPoint(rng, 3.0, 1.0), 300, 100, 4.0));
    const Bytes bytes = updateOf(source, sent);
    sent = source.revision();
    mirror.swapMap(kept);
    ASSERT_EQ(applyTo(mirror, bytes).status, MapUpdateStatus::kApplied) << "step " << step;
    mirror.swapMap(kept);
    EXPECT_TRUE(mirror.map().empty());
    ASSERT_EQ(serializeMap(kept), serializeMap(source)) << "step " << step;
  }
}

TEST(MapUpdate, ItsSizeGrowsWithWhatChangedNotWithTheMap) {
  // A corridor 40 m long mapped scan by scan, each scan 6 m wide: each update holds what the
  // last scan changed, whatever the length mapped so far.
  MapConfig config;
  config.resolution = 0.05;
  Map source(config);
  std::mt19937 rng(5);
  MapMirror mirror;
  std::uint64_t sent = 0;
  const int kScans = 40;
  std::vector<std::size_t> update_bytes;
  std::vector<std::size_t> map_bytes(kScans, 0);  // after the scans compared below
  for (int k = 0; k < kScans; ++k) {
    source.insertScan(test::randomScan(rng, {k * 1.0 - 20.0, 0.0, 0.0}, 1500, 300, 3.0));
    const Bytes bytes = updateOf(source, sent);
    sent = source.revision();
    ASSERT_EQ(applyTo(mirror, bytes).status, MapUpdateStatus::kApplied);
    update_bytes.push_back(bytes.size());
    if (k == 9 || k == 19 || k == 39) map_bytes[k] = serializeMap(source).size();
  }
  EXPECT_TRUE(mirrors(mirror, source));
  for (int k : {9, 19, 39}) {
    std::printf(
        "[ figure ] corridor at 0.05 m, scan %d: update %zu bytes, map file %zu bytes "
        "(%.1f %%)\n",
        k + 1, update_bytes[k], map_bytes[k],
        100.0 * static_cast<double>(update_bytes[k]) / static_cast<double>(map_bytes[k]));
  }
  EXPECT_GT(map_bytes[39], 3 * map_bytes[9]);
  EXPECT_LT(update_bytes[39], 2 * update_bytes[9]);
  EXPECT_LT(update_bytes[39] * 4, map_bytes[39]);
}

// ---- Sequence
// -----------------------------------------------------------------------------------------

TEST(MapUpdate, AMissedUpdateIsDetectedAndAFullOneRepairs) {
  Map source = test::randomMap(6, 0.2, 5.0);
  std::mt19937 rng(7);
  MapMirror mirror;
  // Before any full update, an incremental one cannot be applied.
  const std::uint64_t r0 = source.revision();
  source.insertScan(test::randomScan(rng, {1, 1, 0}, 300, 100, 4.0));
  EXPECT_EQ(applyTo(mirror, updateOf(source, r0)).status, MapUpdateStatus::kMissed);
  EXPECT_TRUE(mirror.map().empty());

  applyTo(mirror, updateOf(source, 0));
  const std::uint64_t r1 = source.revision();
  source.insertScan(test::randomScan(rng, {-1, 2, 0}, 300, 100, 4.0));
  const Bytes u1 = updateOf(source, r1);
  const std::uint64_t r2 = source.revision();
  source.clearBox({-2, -2, -1}, {0, 0, 1});
  const Bytes u2 = updateOf(source, r2);
  const Bytes mirrored = serializeMap(mirror.map());

  const MapUpdateResult missed = applyTo(mirror, u2);  // u1 was lost
  EXPECT_EQ(missed.status, MapUpdateStatus::kMissed);
  EXPECT_EQ(missed.update.from_revision, r2);
  EXPECT_EQ(mirror.sourceRevision(), r1);
  EXPECT_EQ(serializeMap(mirror.map()), mirrored);
  EXPECT_EQ(applyTo(mirror, u1).status, MapUpdateStatus::kApplied);  // late, in order: fine
  EXPECT_EQ(applyTo(mirror, u2).status, MapUpdateStatus::kApplied);
  EXPECT_TRUE(mirrors(mirror, source));
  EXPECT_EQ(applyTo(mirror, u1).status, MapUpdateStatus::kOutdated);  // again: ignored
  EXPECT_TRUE(mirrors(mirror, source));

  // An update since an older revision still applies (it holds every change since).
  const std::uint64_t r3 = source.revision();
  source.insertScan(test::randomScan(rng, {0, -2, 0}, 300, 100, 4.0));
  EXPECT_EQ(applyTo(mirror, updateOf(source, r1)).status, MapUpdateStatus::kApplied);
  EXPECT_TRUE(mirrors(mirror, source));
  EXPECT_GT(source.revision(), r3);

  // Lost updates repaired by a full one; an older full one is outdated.
  const Bytes old_full = updateOf(source, 0);
  source.insertScan(test::randomScan(rng, {2, 0, 0}, 300, 100, 4.0));
  source.insertScan(test::randomScan(rng, {2, 1, 0}, 300, 100, 4.0));
  EXPECT_EQ(applyTo(mirror, updateOf(source, source.revision() - 1)).status,
            MapUpdateStatus::kMissed);
  EXPECT_EQ(applyTo(mirror, updateOf(source, 0)).status, MapUpdateStatus::kApplied);
  EXPECT_TRUE(mirrors(mirror, source));
  EXPECT_EQ(applyTo(mirror, old_full).status, MapUpdateStatus::kOutdated);

  // Another map's incremental updates do not apply (its revisions are not this source's).
  Map other = test::randomMap(6, 0.2, 5.0);
  const std::uint64_t other_revision = other.revision();
  other.insertScan(test::randomScan(rng, {0, 0, 0}, 300, 100, 4.0));
  EXPECT_EQ(applyTo(mirror, updateOf(other, other_revision)).status, MapUpdateStatus::kMissed);
  EXPECT_TRUE(mirrors(mirror, source));
  // A full update of another map replaces the mirror's.
  EXPECT_EQ(applyTo(mirror, updateOf(other, 0)).status, MapUpdateStatus::kApplied);
  EXPECT_TRUE(mirrors(mirror, other));
}

TEST(MapUpdate, IsFullWhenTheMapCannotTellWhatChanged) {
  Map source = test::randomMap(8, 0.2, 5.0);
  auto full = [&](std::uint64_t since) {
    const Bytes bytes = updateOf(source, since);
    return readMapUpdateInfo(bytes.data(), bytes.size()).full;
  };
  const std::uint64_t r = source.revision();
  EXPECT_TRUE(full(0));
  EXPECT_FALSE(full(r));
  EXPECT_TRUE(full(r + 1));  // later than the map: another map's revision
  source.decay(0.5);
  EXPECT_FALSE(full(r));
  // Decay rebasing the tiles' exponents (once per 2^24 binary orders) changes their stored form.
  MapMirror mirror;
  applyTo(mirror, updateOf(source, 0));
  std::uint64_t sent = source.revision();
  const std::uint64_t before_rebase = source.revision();
  for (int k = 0; k < 20000; ++k) {
    source.decay(std::numeric_limits<double>::denorm_min());
    applyTo(mirror, updateOf(source, sent));
    sent = source.revision();
  }
  EXPECT_TRUE(full(before_rebase));
  EXPECT_TRUE(mirrors(mirror, source));
  // clear() lists no removed tile: older revisions get a full update.
  const std::uint64_t before_clear = source.revision();
  source.clear();
  EXPECT_TRUE(full(before_clear));
  EXPECT_FALSE(full(source.revision()));
}

// ---- The format
// ------------------------------------------------------------------------------------

std::uint64_t readLe(const Bytes& bytes, std::size_t offset, int size) {
  std::uint64_t value = 0;
  for (int k = 0; k < size; ++k) value |= std::uint64_t{bytes[offset + k]} << (8 * k);
  return value;
}
double readDouble(const Bytes& bytes, std::size_t offset) {
  const std::uint64_t bits = readLe(bytes, offset, 8);
  double value;
  std::memcpy(&value, &bits, 8);
  return value;
}

/// A small source: cells in tiles (0, 0), (1, 0) and (-1, 2), then (1, 0) emptied and a cell of
/// (0, 0) changed; `since` is the revision before those two changes.
struct Small {
  Map source{test::unitConfig(1000.0, ModelRules{})};
  std::uint64_t since = 0;
  Small() {
    source.setCellVolumes({{{3, 4}, {{{0, 1, 2}}, {{-4, -1, 3}}}},
                           {{5, 4}, {{}, {{2, 5, 3}}}},
                           {{17, 0}, {{{1, 2, 1}}, {}}},
                           {{-3, 40}, {{{0, 2, 2}}, {}}}});
    since = source.revision();
    source.setCellVolumes({17, 0}, CellVolumes{});
    source.setCellVolumes({3, 4}, CellVolumes{{{0, 1, 4}}, {{-4, -1, 3}}});
  }
};

TEST(MapUpdate, LayoutIsTheDocumentedOne) {
  Small small;
  small.source.decay(0.75);
  const Bytes bytes = updateOf(small.source, small.since);
  EXPECT_EQ(std::string(bytes.begin(), bytes.begin() + 8), std::string("MVOGUPD\0", 8));
  EXPECT_EQ(readLe(bytes, 8, 4), kMapUpdateFormatVersion);
  EXPECT_EQ(readLe(bytes, 12, 4), kMapUpdateHeaderBytes);
  EXPECT_EQ(readDouble(bytes, 16), 1.0);
  EXPECT_EQ(readDouble(bytes, 24), 1000.0);
  EXPECT_EQ(readLe(bytes, 32, 4), 7u);  // the default rules
  EXPECT_EQ(readDouble(bytes, 36), kDefaultOutOfRangeFreeLength);
  EXPECT_EQ(readLe(bytes, 44, 4), 0u);  // not full
  EXPECT_EQ(readLe(bytes, 56, 8), small.since);
  EXPECT_EQ(readLe(bytes, 64, 8), small.source.revision());
  EXPECT_EQ(readDouble(bytes, 72), 0.75);  // 0.75 * 2^0
  EXPECT_EQ(static_cast<std::int64_t>(readLe(bytes, 80, 8)), 0);
  EXPECT_EQ(readLe(bytes, 88, 8), 1u);   // R: tile (1, 0)
  EXPECT_EQ(readLe(bytes, 96, 8), 1u);   // T: tile (0, 0)
  EXPECT_EQ(readLe(bytes, 104, 8), 2u);  // C
  EXPECT_EQ(readLe(bytes, 112, 8), 3u);  // V
  EXPECT_EQ(readLe(bytes, 120, 8), 0u);
  EXPECT_EQ(bytes.size(), 128u + 8 * 1 + 16 * 1 + 16 * 2 + 12 * 3 + 8);
  EXPECT_EQ(readLe(bytes, 128, 4), 1u);  // removed: tile (1, 0)
  EXPECT_EQ(readLe(bytes, 132, 4), 0u);
  EXPECT_EQ(readLe(bytes, 136, 8), 0u);  // changed: tile (0, 0), exponent 0...
  EXPECT_EQ(readLe(bytes, 144, 4), 0u);
  EXPECT_EQ(readLe(bytes, 148, 4), 2u);  // ... 2 cells: (3, 4) first
  EXPECT_EQ(readLe(bytes, 152, 4), 3u);
  EXPECT_EQ(readLe(bytes, 156, 4), 4u);
  EXPECT_EQ(readLe(bytes, 160, 4), 1u);
  EXPECT_EQ(readLe(bytes, 164, 4), 1u);
  float mass;
  const std::uint32_t mass_bits = static_cast<std::uint32_t>(readLe(bytes, 176, 4));
  std::memcpy(&mass, &mass_bits, 4);
  EXPECT_EQ(mass, 4.0f);  // as stored, in the unit it was written in (before the decay step)
  EXPECT_EQ(readLe(bytes, bytes.size() - 8, 8), fnv1a64(bytes.data(), bytes.size() - 8));
  const MapUpdateInfo info = readMapUpdateInfo(bytes.data(), bytes.size());
  EXPECT_EQ(info.from_revision, small.since);
  EXPECT_EQ(info.to_revision, small.source.revision());
  EXPECT_EQ(info.tiles_changed, 1u);
  EXPECT_EQ(info.tiles_removed, 1u);
  EXPECT_EQ(info.resolution, 1.0);
}

/// A mirror of `small` at its `since`, and the update from there.
struct Synced {
  MapMirror mirror;
  Bytes update;
  Bytes mirrored;
  explicit Synced(const Small& small) {
    Map at_since(small.source.config());
    // The source as it was at `since`, sent whole, under the source's identity: replay its
    // first change into a map whose full update is patched to name the source.
    at_since.setCellVolumes({{{3, 4}, {{{0, 1, 2}}, {{-4, -1, 3}}}},
                             {{5, 4}, {{}, {{2, 5, 3}}}},
                             {{17, 0}, {{{1, 2, 1}}, {}}},
                             {{-3, 40}, {{{0, 2, 2}}, {}}}});
    Bytes full = updateOf(at_since, 0);
    update = updateOf(small.source, small.since);
    putLe(full, 48, readLe(update, 48, 8), 8);  // the source's id
    putLe(full, 64, small.since, 8);            // at the source's revision
    fixChecksum(full);
    EXPECT_EQ(applyTo(mirror, full).status, MapUpdateStatus::kApplied);
    mirrored = serializeMap(mirror.map());
  }
};

TEST(MapUpdate, TheSyncedSmallCaseApplies) {
  Small small;
  Synced synced(small);
  EXPECT_EQ(applyTo(synced.mirror, synced.update).status, MapUpdateStatus::kApplied);
  EXPECT_TRUE(mirrors(synced.mirror, small.source));
}

TEST(MapUpdate, AFreeListAcrossAnObstacleIsStoredAsTheMergeCutsIt) {
  // Sec. III-A allows one free volume across an obstacle. Under split_free_space_at_obstacles
  // a map stores it cut at the obstacle's bottom and top (as setCellVolumes does), which a
  // source built by mvog always sends; an update that sends it whole (a source under the paper's
  // rules, its rules word then saying split) is stored cut too, and the mirror's map is then
  // one whose file loads back to the same bytes.
  Map source(test::unitConfig(1000.0, ModelRules::paper()));
  source.setCellVolumes({3, 4}, CellVolumes{{{2, 3, 1}}, {{0, 10, 5}}});
  Bytes full = updateOf(source, 0);
  putLe(full, 32, readLe(full, 32, 4) | 4u, 4);  // bit 2: split_free_space_at_obstacles
  fixChecksum(full);
  MapMirror mirror;
  ASSERT_EQ(applyTo(mirror, full).status, MapUpdateStatus::kApplied);
  ASSERT_TRUE(mirror.map().config().rules.split_free_space_at_obstacles);
  EXPECT_EQ(test::allVolumes(mirror.map()),
            (std::vector<test::VolumeRecord>{{3, 4, 0, 2.f, 3.f, 1.f},
                                             {3, 4, 1, 0.f, 2.f, 1.f},
                                             {3, 4, 1, 2.f, 3.f, 0.5f},
                                             {3, 4, 1, 3.f, 10.f, 3.5f}}));
  const Bytes file = serializeMap(mirror.map());
  EXPECT_EQ(serializeMap(deserializeMap(file.data(), file.size())), file);
}

TEST(MapUpdate, AFullUpdateOfTheMirrorsOwnRevisionIsApplied) {
  // Outdated means ending before the mirror's revision of the same source: a full update ending
  // at it is applied.
  Small small;
  MapMirror mirror;
  const Bytes full = updateOf(small.source, 0);
  ASSERT_EQ(applyTo(mirror, full).status, MapUpdateStatus::kApplied);
  EXPECT_EQ(applyTo(mirror, full).status, MapUpdateStatus::kApplied);
  EXPECT_TRUE(mirrors(mirror, small.source));
}

TEST(MapUpdate, AFullUpdateWithAMassUnitOrUnitExponentOutOfRangeIsRefused) {
  // The header's mass unit lies in (0.5, 1] and its unit exponent in [-2^24, 0], whether the
  // update holds tiles or not.
  Small small;
  std::uint64_t bits_half;
  const double half = 0.5;
  std::memcpy(&bits_half, &half, 8);
  const Map empty(small.source.config());
  for (const Map* source : std::vector<const Map*>{&small.source, &empty}) {
    const Bytes full = updateOf(*source, 0);
    auto patched = [&](std::size_t offset, std::uint64_t value) {
      Bytes bytes = full;
      putLe(bytes, offset, value, 8);
      fixChecksum(bytes);
      return bytes;
    };
    for (const Bytes& bytes : {patched(72, bits_half), patched(80, 1)}) {
      MapMirror mirror;
      EXPECT_THROW(applyTo(mirror, bytes), MapFileError);
      EXPECT_EQ(mirror.sourceRevision(), 0u);
    }
  }
}

TEST(MapUpdate, RefusesChangedTilesOutOfOrder) {
  // The changed tiles come in the order of the map file's, rows from the lowest: two tiles of one
  // cell and one volume each (records of 16 + 16 + 12 bytes after the 128-byte header of a full
  // update), swapped, are refused, though each record is valid on its own.
  Map source(test::unitConfig());
  source.setCellVolumes({{{3, 4}, {{{0, 1, 2}}, {}}}, {{20, 4}, {{{0, 1, 2}}, {}}}});
  const Bytes full = updateOf(source, 0);
  constexpr std::size_t kHeader = 128, kTileRecord = 16 + 16 + 12;
  ASSERT_EQ(full.size(), kHeader + 2 * kTileRecord + 8);
  MapMirror accepted;
  ASSERT_EQ(applyTo(accepted, full).status, MapUpdateStatus::kApplied);
  Bytes swapped = full;
  std::rotate(swapped.begin() + kHeader, swapped.begin() + kHeader + kTileRecord,
              swapped.begin() + kHeader + 2 * kTileRecord);
  fixChecksum(swapped);
  MapMirror mirror;
  EXPECT_THROW(applyTo(mirror, swapped), MapFileError);
  EXPECT_EQ(mirror.sourceRevision(), 0u);
}

TEST(MapUpdate, RefusesCorruptOrForeignBytesChangingNothing) {
  Small small;
  Synced synced(small);
  const Bytes& update = synced.update;
  const std::uint64_t revision = synced.mirror.sourceRevision();
  auto refused = [&](const Bytes& bytes) -> ::testing::AssertionResult {
    try {
      synced.mirror.apply(bytes.data(), bytes.size());
    } catch (const MapFileError&) {
      if (serializeMap(synced.mirror.map()) != synced.mirrored ||
          synced.mirror.sourceRevision() != revision) {
        return ::testing::AssertionFailure() << "refused, but the mirror changed";
      }
      return ::testing::AssertionSuccess();
    }
    return ::testing::AssertionFailure() << "accepted";
  };
  EXPECT_TRUE(refused({}));
  for (std::size_t size = 0; size < update.size(); ++size) {
    EXPECT_TRUE(refused(Bytes(update.begin(), update.begin() + size))) << "truncated to " << size;
  }
  for (std::size_t offset = 0; offset < update.size(); ++offset) {
    Bytes flipped = update;
    flipped[offset] ^= 0x10;
    EXPECT_TRUE(refused(flipped)) << "byte " << offset;
  }
  // Foreign: a map file, and an update with a longer tail.
  EXPECT_TRUE(refused(serializeMap(small.source)));
  Bytes longer = update;
  longer.insert(longer.end() - 8, 8, 0);
  fixChecksum(longer);
  EXPECT_TRUE(refused(longer));
  // Consistent checksums over inconsistent contents.
  auto patched = [&](std::size_t offset, std::uint64_t value, int size) {
    Bytes bytes = update;
    putLe(bytes, offset, value, size);
    fixChecksum(bytes);
    return bytes;
  };
  const std::size_t tile = 136;  // the changed tile's record
  const std::size_t first_cell = tile + 16;
  const std::size_t first_volume = first_cell + 16;
  std::uint64_t bits_nan;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::memcpy(&bits_nan, &nan, 8);
  std::uint64_t bits_two;
  const double two = 2.0;
  std::memcpy(&bits_two, &two, 8);
  const struct {
    const char* what;
    Bytes bytes;
  } cases[] = {
      {"version 2", patched(8, 2, 4)},
      {"header size", patched(12, 120, 4)},
      {"NaN resolution", patched(16, bits_nan, 8)},
      {"another resolution (same source)", patched(16, bits_two, 8)},
      {"unknown rule bits", patched(32, 15, 4)},
      {"other rules (same source)", patched(32, 3, 4)},
      {"unknown flags", patched(44, 2, 4)},
      {"full with a from revision", patched(44, 1, 4)},
      {"from after to", patched(56, small.source.revision() + 1, 8)},
      {"mass unit 2", patched(72, bits_two, 8)},
      {"unit exponent 1", patched(80, 1, 8)},
      {"R off by one", patched(88, 2, 8)},
      {"C off by one", patched(104, 3, 8)},
      {"reserved", patched(120, 1, 8)},
      {"the tile both changed and removed", patched(128, 0, 4)},
      {"tile exponent below the unit's", patched(tile + 8, static_cast<std::uint32_t>(-1), 4)},
      {"tile exponent too large", patched(tile + 8, (1u << 24) + 1, 4)},
      {"a tile of 0 cells", patched(tile + 12, 0, 4)},
      {"a tile of 3 cells", patched(tile + 12, 3, 4)},
      {"a cell outside its tile", patched(first_cell, 20, 4)},
      {"cells out of order", patched(first_cell, 6, 4)},
      {"a cell listed twice", patched(first_cell, 5, 4)},
      {"a cell's count changed", patched(first_cell + 8, 0, 4)},
      {"a volume lower than 1", patched(first_volume + 4, 0x3f000000, 4)},
      {"a negative mass", patched(first_volume + 8, 0xbf800000, 4)},
  };
  for (const auto& c : cases) EXPECT_TRUE(refused(c.bytes)) << c.what;
  // The removed tile listed twice, the counts and the checksum fixed.
  Bytes removed_twice = update;
  removed_twice.insert(removed_twice.begin() + tile, update.begin() + 128, update.begin() + tile);
  putLe(removed_twice, 88, 2, 8);
  fixChecksum(removed_twice);
  EXPECT_TRUE(refused(removed_twice)) << "a tile listed removed twice";
  // After a decay step, an incremental update with the unit of before would raise the mirror's.
  const std::uint64_t before_decay = small.source.revision();
  small.source.decay(0.5);
  Bytes decayed = updateOf(small.source, before_decay);
  ASSERT_EQ(applyTo(synced.mirror, synced.update).status, MapUpdateStatus::kApplied);
  ASSERT_EQ(applyTo(synced.mirror, decayed).status, MapUpdateStatus::kApplied);
  putLe(decayed, 80, readLe(update, 80, 8), 8);  // the unit exponent before the decay step
  putLe(decayed, 56, small.source.revision(), 8);
  fixChecksum(decayed);
  const Bytes now = serializeMap(synced.mirror.map());
  EXPECT_THROW(applyTo(synced.mirror, decayed), MapFileError);
  EXPECT_EQ(serializeMap(synced.mirror.map()), now);
  EXPECT_THROW(readMapUpdateInfo(nullptr, 0), MapFileError);
}

}  // namespace
}  // namespace mvog
