// The binary map format of map_io.h: round trips in memory and on disk, the documented layout,
// and refusal of every kind of broken buffer or file.
#include <gtest/gtest.h>

#include <dirent.h>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "mvog/map_io.h"
#include "test_util.h"

namespace mvog {
namespace {

using Bytes = std::vector<std::uint8_t>;
using test::allVolumes;
using test::fixChecksum;
using test::kFloatInf;
using test::kFloatNaN;
using test::kInf;
using test::kNaN;
using test::putLe;

// ---- The format written out independently of map_io.cpp ---------------------------------------

void appendLe(Bytes& out, std::uint64_t value, int size) {
  out.resize(out.size() + size);
  putLe(out, out.size() - size, value, size);
}
std::uint64_t bitsOf(double v) {
  std::uint64_t b;
  std::memcpy(&b, &v, 8);
  return b;
}
std::uint32_t bitsOf(float v) {
  std::uint32_t b;
  std::memcpy(&b, &v, 4);
  return b;
}

/// Header field offsets (map_io.h).
constexpr std::size_t kVersionOffset = 8;
constexpr std::size_t kHeaderSizeOffset = 12;
constexpr std::size_t kResolutionOffset = 16;
constexpr std::size_t kMaxCoordinateOffset = 24;
constexpr std::size_t kCellCountOffset = 32;
constexpr std::size_t kVolumeCountOffset = 40;
constexpr std::size_t kRulesOffset = 48;
constexpr std::size_t kReservedOffset = 60;

struct CellRecord {
  std::int32_t x;
  std::int32_t y;
  std::vector<Volume> positive;
  std::vector<Volume> negative;
};

/// A file in the documented layout, with the counts and the checksum filled in.
/// The documented layout, written by hand: version 2 with the rules' bits (0b111 for the defaults:
/// clip, per scan, split), or version 1 (rules_bits must then be 0).
Bytes buildFile(double resolution, double max_coordinate, const std::vector<CellRecord>& cells,
                std::uint32_t version = 2, std::uint32_t rules_bits = 7) {
  Bytes out = {'M', 'V', 'O', 'G', 'M', 'A', 'P', '\0'};
  appendLe(out, version, 4);
  appendLe(out, 64, 4);
  appendLe(out, bitsOf(resolution), 8);
  appendLe(out, bitsOf(max_coordinate), 8);
  std::uint64_t volumes = 0;
  for (const CellRecord& c : cells) volumes += c.positive.size() + c.negative.size();
  appendLe(out, cells.size(), 8);
  appendLe(out, volumes, 8);
  appendLe(out, rules_bits, 4);
  appendLe(out, version == 1 ? 0 : bitsOf(kDefaultOutOfRangeFreeLength), 8);
  appendLe(out, 0, 4);
  for (const CellRecord& c : cells) {
    appendLe(out, static_cast<std::uint32_t>(c.x), 4);
    appendLe(out, static_cast<std::uint32_t>(c.y), 4);
    appendLe(out, c.positive.size(), 4);
    appendLe(out, c.negative.size(), 4);
    for (const std::vector<Volume>* list : {&c.positive, &c.negative}) {
      for (const Volume& v : *list) {
        appendLe(out, bitsOf(v.bottom), 4);
        appendLe(out, bitsOf(v.top), 4);
        appendLe(out, bitsOf(v.mass), 4);
      }
    }
  }
  appendLe(out, 0, 8);
  fixChecksum(out);
  return out;
}

/// A small valid map: three cells over two tiles, both signs.
std::vector<CellRecord> smallCells() {
  return {{-1, 0, {{0.0f, 1.0f, 1.0f}}, {}},
          {0, 0, {{2.5f, 4.0f, 3.0f}}, {{-3.0f, 2.0f, 5.0f}, {5.5f, 7.0f, 0.5f}}},
          {1, 0, {}, {{0.0f, 1.25f, 2.0f}}}};
}

Map smallMap() {
  Map map(MapConfig{0.5, 100.0, ModelRules{}});
  for (const CellRecord& c : smallCells()) {
    map.setCellVolumes({c.x, c.y}, CellVolumes{c.positive, c.negative});
  }
  return map;
}

/// `data` is refused with MapFileError (and nothing else).
::testing::AssertionResult refused(const Bytes& data) {
  try {
    deserializeMap(data.data(), data.size());
  } catch (const MapFileError&) {
    return ::testing::AssertionSuccess();
  } catch (const std::exception& e) {
    return ::testing::AssertionFailure() << "threw something else: " << e.what();
  }
  return ::testing::AssertionFailure() << "accepted";
}

// ---- Round trips
// ------------------------------------------------------------------------------------

TEST(MapIo, LayoutIsTheDocumentedOne) {
  // Cells in the order the map stores them: rows of tiles from the lowest, tile (-1, 0) first.
  EXPECT_EQ(serializeMap(smallMap()), buildFile(0.5, 100.0, smallCells()));
  const Bytes empty = serializeMap(Map(MapConfig{0.25, 50.0, ModelRules{}}));
  EXPECT_EQ(empty, buildFile(0.25, 50.0, {}));
  EXPECT_EQ(empty.size(), kMapHeaderBytes + 8);
}

TEST(MapIo, TheModelsRulesTravelWithTheMap) {
  // A map keeps being built by the rules it was built with: they are in the file.
  for (const ModelRules& rules : {ModelRules{}, ModelRules::paper()}) {
    MapConfig config;
    config.rules = rules;
    const Bytes bytes = serializeMap(Map(config));
    EXPECT_TRUE(deserializeMap(bytes.data(), bytes.size()).config().rules == rules);
  }
  ModelRules clip_only = ModelRules::paper();
  clip_only.clip_free_space_at_hits = true;
  clip_only.out_of_range_free_length = kDefaultOutOfRangeFreeLength;
  const Bytes file = buildFile(0.5, 100.0, smallCells(), 2, 1);
  EXPECT_TRUE(deserializeMap(file.data(), file.size()).config().rules == clip_only);
}

TEST(MapIo, VersionOneFilesAreReadAsThePapersModel) {
  // Maps saved before the rules existed were built by the paper's model.
  const Bytes file = buildFile(0.5, 100.0, smallCells(), 1, 0);
  const Map map = deserializeMap(file.data(), file.size());
  EXPECT_TRUE(map.config().rules == ModelRules::paper());
  EXPECT_EQ(test::observedCells(map).size(), 3u);
}

TEST(MapIo, SerializeDeserializeIsTheIdentity) {
  const Map map = test::randomMap(1, 0.1, 3.0);
  const Bytes bytes = serializeMap(map);
  const std::vector<test::VolumeRecord> volumes = allVolumes(map);
  EXPECT_EQ(bytes.size(), 64 + 16 * test::observedCells(map).size() + 12 * volumes.size() + 8);
  const Map loaded = deserializeMap(bytes.data(), bytes.size());
  EXPECT_EQ(loaded.resolution(), map.resolution());
  EXPECT_EQ(loaded.config().max_coordinate, map.config().max_coordinate);
  EXPECT_TRUE(test::sameVolumes(allVolumes(loaded), volumes));
  EXPECT_EQ(loaded.bounds().min, map.bounds().min);
  EXPECT_EQ(loaded.bounds().max, map.bounds().max);
  EXPECT_TRUE(test::sameProbabilities(test::probabilityBits(loaded, 3.0, 2.0),
                                      test::probabilityBits(map, 3.0, 2.0)));
  EXPECT_EQ(serializeMap(loaded), bytes);
}

TEST(MapIo, ReadsManyCellsInAnyOrder) {
  // A file need not list a tile's cells together, as serializeMap does, and a reader takes its
  // cells in batches: thousands of cells over many tiles, listed in a shuffled order, read back
  // as the map they describe; a cell listed twice is refused however far apart its records lie.
  std::vector<CellRecord> cells;
  for (std::int32_t x = -60; x < 60; ++x) {
    for (std::int32_t y = -50; y < 50; ++y) {
      const auto low = static_cast<float>(x & 3);
      const auto high = static_cast<float>(y & 3);
      cells.push_back({x, y, {{0.0f, 1.0f + low, 2.0f}}, {{5.0f + high, 12.0f, 3.0f + low}}});
    }
  }
  std::shuffle(cells.begin(), cells.end(), std::mt19937(7));
  Map expected(MapConfig{0.5, 100.0, ModelRules{}});
  std::vector<Map::CellAssignment> assignments;
  assignments.reserve(cells.size());
  for (const CellRecord& c : cells) {
    assignments.push_back({{c.x, c.y}, CellVolumes{c.positive, c.negative}});
  }
  expected.setCellVolumes(assignments);
  const Bytes file = buildFile(0.5, 100.0, cells);
  const Bytes grouped = serializeMap(expected);  // a tile's cells together, batches by tile
  EXPECT_EQ(serializeMap(deserializeMap(file.data(), file.size())), grouped);
  EXPECT_EQ(serializeMap(deserializeMap(grouped.data(), grouped.size())), grouped);
  cells.push_back(cells.front());
  EXPECT_TRUE(refused(buildFile(0.5, 100.0, cells)));
}

TEST(MapIo, DecayedMapRoundTrip) {
  // The file holds the masses as of saving, decay folded in and rounded to float: the volumes
  // read back are the map's, and the probabilities computed from them agree up to that rounding.
  Map map = test::randomMap(2, 0.1, 3.0);
  map.decay(0.7);
  map.decay(0.3);
  const Bytes bytes = serializeMap(map);
  const Map loaded = deserializeMap(bytes.data(), bytes.size());
  EXPECT_TRUE(test::sameVolumes(allVolumes(loaded), allVolumes(map)));
  EXPECT_EQ(serializeMap(loaded), bytes);
  for (double x = -3.0; x <= 3.0; x += 0.07) {
    for (double z = -2.0; z <= 2.0; z += 0.05) {
      const PointOccupancy a = map.occupancy({x, 0.3 * x, z});
      const PointOccupancy b = loaded.occupancy({x, 0.3 * x, z});
      ASSERT_EQ(a.known(), b.known());
      if (a.known()) {
        ASSERT_NEAR(*a.probability, *b.probability, 1e-6);
        ASSERT_NEAR(a.positive_density, b.positive_density, 1e-6 * a.positive_density);
        ASSERT_NEAR(a.negative_density, b.negative_density, 1e-6 * a.negative_density);
      }
    }
  }
}

TEST(MapIo, EmptyMapRoundTrip) {
  const Bytes bytes = serializeMap(Map());
  const Map loaded = deserializeMap(bytes.data(), bytes.size());
  EXPECT_TRUE(loaded.empty());
  EXPECT_EQ(loaded.resolution(), 0.1);
}

// ---- Files
// -------------------------------------------------------------------------------------------

/// A fresh directory under the test temp dir, removed with its files at the end of the test.
class TempDir {
 public:
  TempDir() {
    std::string pattern = ::testing::TempDir() + "/mvog_io_XXXXXX";
    if (mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
    path_ = pattern;
  }
  ~TempDir() {
    for (const std::string& name : entries()) {
      const std::string path = path_ + "/" + name;
      if (::unlink(path.c_str()) != 0) ::rmdir(path.c_str());
    }
    ::rmdir(path_.c_str());
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::string& path() const { return path_; }
  std::set<std::string> entries() const {
    std::set<std::string> names;
    if (DIR* dir = ::opendir(path_.c_str())) {
      while (const dirent* entry = ::readdir(dir)) {
        const std::string name = entry->d_name;
        if (name != "." && name != "..") names.insert(name);
      }
      ::closedir(dir);
    }
    return names;
  }

 private:
  std::string path_;
};

Bytes readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void writeFile(const std::string& path, const Bytes& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
}

TEST(MapIo, SaveLoadRoundTrip) {
  TempDir dir;
  const std::string path = dir.path() + "/map.mvog";
  const Map map = test::randomMap(2, 0.1, 3.0);
  saveMap(map, path);
  EXPECT_EQ(dir.entries(), (std::set<std::string>{"map.mvog"}));
  EXPECT_EQ(readFile(path), serializeMap(map));
  const Map loaded = loadMap(path);
  EXPECT_TRUE(test::sameVolumes(allVolumes(loaded), allVolumes(map)));
  EXPECT_EQ(loaded.resolution(), map.resolution());
}

TEST(MapIo, SaveReplacesAnExistingFile) {
  TempDir dir;
  const std::string path = dir.path() + "/map.mvog";
  const Map first = test::randomMap(3, 0.1, 3.0);
  const Map second = smallMap();
  saveMap(first, path);
  saveMap(second, path);
  EXPECT_EQ(dir.entries(), (std::set<std::string>{"map.mvog"}));  // no temporary file left
  EXPECT_EQ(readFile(path), serializeMap(second));
  EXPECT_TRUE(test::sameVolumes(allVolumes(loadMap(path)), allVolumes(second)));
}

TEST(MapIo, FailedSaveThrowsAndLeavesNoTemporaryFile) {
  TempDir dir;
  const Map map = smallMap();
  // Missing directory.
  EXPECT_THROW(saveMap(map, dir.path() + "/missing/map.mvog"), MapFileError);
  EXPECT_TRUE(dir.entries().empty());
  // A directory in the way of the rename: the save fails and the directory stays as it was.
  const std::string blocked = dir.path() + "/blocked";
  ASSERT_EQ(::mkdir(blocked.c_str(), 0755), 0);
  const std::string inside = blocked + "/keep";
  writeFile(inside, {1, 2, 3});
  EXPECT_THROW(saveMap(map, blocked), MapFileError);
  EXPECT_EQ(dir.entries(), (std::set<std::string>{"blocked"}));
  EXPECT_EQ(readFile(inside), (Bytes{1, 2, 3}));
  ::unlink(inside.c_str());
}

TEST(MapIo, SaveRemovesTheTemporariesOfKilledSavesOnly) {
  TempDir dir;
  const std::string path = dir.path() + "/map.mvog";
  const std::string temporaries = dir.path() + "/.map.mvog.saving-";
  const std::string outside = dir.path() + "/outside";
  writeFile(outside, {7});
  // Left by a save killed before its rename: nobody holds it locked.
  writeFile(temporaries + "Ab3xZ9", {1, 2});
  // A save of the same path running in another process: locked (flock) until it renames.
  const std::string running = temporaries + "Run123";
  writeFile(running, {3});
  const int running_fd = ::open(running.c_str(), O_RDONLY);
  ASSERT_GE(running_fd, 0);
  ASSERT_EQ(::flock(running_fd, LOCK_EX), 0);
  // Not temporaries of this path: another map's, a longer name, a user's file named like a
  // temporary, a link to a file elsewhere, a FIFO (opening it must not block the save).
  writeFile(dir.path() + "/.other.mvog.saving-Ab3xZ9", {4});
  writeFile(temporaries + "Ab3xZ9x", {5});
  writeFile(path + ".tmp.backup", {6});
  ASSERT_EQ(::symlink(outside.c_str(), (temporaries + "Link00").c_str()), 0);
  ASSERT_EQ(::mkfifo((temporaries + "Fifo00").c_str(), 0644), 0);

  saveMap(smallMap(), path);
  EXPECT_EQ(dir.entries(),
            (std::set<std::string>{"map.mvog", ".map.mvog.saving-Run123", ".map.mvog.saving-Link00",
                                   ".map.mvog.saving-Fifo00", ".map.mvog.saving-Ab3xZ9x",
                                   ".other.mvog.saving-Ab3xZ9", "map.mvog.tmp.backup", "outside"}));
  EXPECT_EQ(readFile(outside), (Bytes{7}));
  EXPECT_TRUE(test::sameVolumes(allVolumes(loadMap(path)), allVolumes(smallMap())));
  // Once that save's process is gone (its lock with it), the next save removes its temporary.
  ::close(running_fd);
  saveMap(smallMap(), path);
  EXPECT_EQ(dir.entries().count(".map.mvog.saving-Run123"), 0u);
}

TEST(MapIo, SaveMapBytesWritesWhatSerializeMapGave) {
  TempDir dir;
  const std::string path = dir.path() + "/map.mvog";
  const Map map = test::randomMap(4, 0.1, 3.0);
  saveMapBytes(serializeMap(map), path);
  EXPECT_EQ(dir.entries(), (std::set<std::string>{"map.mvog"}));
  EXPECT_TRUE(test::sameVolumes(allVolumes(loadMap(path)), allVolumes(map)));
}

TEST(MapIo, LoadRefusesMissingDirectoriesAndBrokenFiles) {
  TempDir dir;
  EXPECT_THROW(loadMap(dir.path() + "/missing.mvog"), MapFileError);
  EXPECT_THROW(loadMap(dir.path()), MapFileError);
  const std::string path = dir.path() + "/broken.mvog";
  writeFile(path, {});
  EXPECT_THROW(loadMap(path), MapFileError);
  Bytes truncated = serializeMap(smallMap());
  truncated.pop_back();
  writeFile(path, truncated);
  EXPECT_THROW(loadMap(path), MapFileError);
}

// ---- Broken buffers
// -------------------------------------------------------------------------------

TEST(MapIo, RefusesEmptyBuffers) {
  EXPECT_THROW(deserializeMap(nullptr, 0), MapFileError);
  const Bytes bytes = serializeMap(smallMap());
  EXPECT_THROW(deserializeMap(bytes.data(), 0), MapFileError);
  EXPECT_THROW(deserializeMap(nullptr, bytes.size()), MapFileError);
}

TEST(MapIo, RefusesEveryTruncation) {
  const Bytes bytes = serializeMap(smallMap());
  for (std::size_t size = 0; size < bytes.size(); ++size) {
    const Bytes prefix(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(size));
    EXPECT_TRUE(refused(prefix)) << "prefix of " << size << " bytes";
  }
  Bytes longer = bytes;
  longer.push_back(0);
  EXPECT_TRUE(refused(longer));
}

TEST(MapIo, RefusesEveryFlippedBit) {
  const Bytes bytes = serializeMap(smallMap());
  for (std::size_t k = 0; k < bytes.size(); ++k) {
    for (int bit = 0; bit < 8; ++bit) {
      Bytes flipped = bytes;
      flipped[k] ^= static_cast<std::uint8_t>(1u << bit);
      EXPECT_TRUE(refused(flipped)) << "byte " << k << " bit " << bit;
    }
  }
}

TEST(MapIo, RefusesBadMagicVersionAndHeaderSize) {
  Bytes file = buildFile(0.5, 100.0, smallCells());
  Bytes bad = file;
  bad[0] = 'X';
  fixChecksum(bad);
  EXPECT_TRUE(refused(bad));
  bad = file;
  bad[7] = '1';
  fixChecksum(bad);
  EXPECT_TRUE(refused(bad));
  for (std::uint32_t version : {0u, 3u, 0xffffffffu}) {
    bad = file;
    putLe(bad, kVersionOffset, version, 4);
    fixChecksum(bad);
    EXPECT_TRUE(refused(bad)) << "version " << version;
  }
  for (std::uint32_t header_size : {0u, 56u, 72u}) {
    bad = file;
    putLe(bad, kHeaderSizeOffset, header_size, 4);
    fixChecksum(bad);
    EXPECT_TRUE(refused(bad)) << "header size " << header_size;
  }
  bad = file;
  bad[kReservedOffset + 1] = 1;
  fixChecksum(bad);
  EXPECT_TRUE(refused(bad));
  bad = file;
  putLe(bad, kRulesOffset, 8, 4);  // a rule this version does not know
  fixChecksum(bad);
  EXPECT_TRUE(refused(bad));
}

TEST(MapIo, RefusesCountsThatDoNotMatchTheSize) {
  const Bytes file = buildFile(0.5, 100.0, smallCells());  // 3 cells, 5 volumes
  const std::vector<std::pair<std::uint64_t, std::uint64_t>> counts{
      {1ull << 60, 5}, {3, 1ull << 60}, {1ull << 60, 1ull << 60},
      {~0ull, 5},      {3, ~0ull},      {~0ull / 16 + 1, 5},
      {4, 5},          {3, 4},          {0, 5},
      {3, 0},          {6, 1},  // 6 * 16 + 12 = 3 * 16 + 5 * 12: sizes match
      {0, 9}};                  // 9 * 12 = 3 * 16 + 5 * 12
  for (const auto& [cells, volumes] : counts) {
    Bytes bad = file;
    putLe(bad, kCellCountOffset, cells, 8);
    putLe(bad, kVolumeCountOffset, volumes, 8);
    fixChecksum(bad);
    EXPECT_TRUE(refused(bad)) << cells << " cells, " << volumes << " volumes";
  }
}

TEST(MapIo, RefusesBadResolutionOrMaxCoordinate) {
  for (double resolution : {kNaN, -0.5, 0.0, kInf, -kInf}) {
    EXPECT_TRUE(refused(buildFile(resolution, 100.0, smallCells()))) << resolution;
  }
  for (double max_coordinate : {kNaN, -1.0, 0.0, kInf, 1e12}) {
    EXPECT_TRUE(refused(buildFile(0.5, max_coordinate, smallCells()))) << max_coordinate;
  }
}

TEST(MapIo, RefusesCellsBreakingTheConstraints) {
  const std::vector<std::vector<Volume>> bad_lists{{{0, 0.5f, 1}},          // height below 1
                                                   {{1, 0, 1}},             // upside down
                                                   {{0, 2, 1}, {1, 3, 1}},  // overlap
                                                   {{0, 1, 1}, {2, 3, 1}},  // gap of exactly 1
                                                   {{4, 5, 1}, {0, 1, 1}},  // unsorted
                                                   {{0, 1, -1}},            // negative mass
                                                   {{0, 1, kFloatNaN}},     // NaN mass
                                                   {{0, 1, kFloatInf}},     // infinite mass
                                                   {{kFloatNaN, 1, 1}},     // NaN height
                                                   {{0, kFloatInf, 1}}};    // infinite height
  for (const std::vector<Volume>& list : bad_lists) {
    for (bool positive : {true, false}) {
      std::vector<CellRecord> cells = smallCells();
      (positive ? cells[1].positive : cells[1].negative) = list;
      EXPECT_TRUE(refused(buildFile(0.5, 100.0, cells)))
          << (positive ? "positive " : "negative ") << "[" << list[0].bottom << ", " << list[0].top
          << "] mass " << list[0].mass;
    }
  }
}

TEST(MapIo, RefusesBadCells) {
  std::vector<CellRecord> cells = smallCells();
  cells.push_back(cells[1]);  // duplicate of (0, 0)
  EXPECT_TRUE(refused(buildFile(0.5, 100.0, cells)));
  cells = smallCells();
  cells.push_back({5, 5, {}, {}});  // a cell without volumes
  EXPECT_TRUE(refused(buildFile(0.5, 100.0, cells)));
  cells = smallCells();
  cells.push_back({1000, 0, {{0, 1, 1}}, {}});  // beyond max_coordinate (100 m = 200 cells)
  EXPECT_TRUE(refused(buildFile(0.5, 100.0, cells)));
  cells = smallCells();
  cells.push_back({0, std::numeric_limits<std::int32_t>::min(), {{0, 1, 1}}, {}});
  EXPECT_TRUE(refused(buildFile(0.5, 100.0, cells)));
  // A cell claiming more volumes than the file holds (counts fixed to keep the size right).
  Bytes bad = buildFile(0.5, 100.0, smallCells());
  putLe(bad, 64 + 8, 1000, 4);  // first cell: n_positive
  fixChecksum(bad);
  EXPECT_TRUE(refused(bad));
  // Within the limits, the same cells load.
  EXPECT_FALSE(refused(buildFile(0.5, 100.0, smallCells())));
}

TEST(MapIo, RandomCorruptionsNeverCrash) {
  // Random bytes rewritten, checksum made valid: every buffer either loads into a valid map or
  // is refused with MapFileError.
  const Bytes file = buildFile(0.5, 100.0, smallCells());
  std::mt19937 rng(12);
  std::uniform_int_distribution<std::size_t> position(0, file.size() - 9);
  std::uniform_int_distribution<int> byte(0, 255);
  std::size_t loaded = 0;
  for (int k = 0; k < 20000; ++k) {
    Bytes bad = file;
    for (int n = 0; n < 1 + k % 4; ++n) bad[position(rng)] = static_cast<std::uint8_t>(byte(rng));
    fixChecksum(bad);
    try {
      const Map map = deserializeMap(bad.data(), bad.size());
      ASSERT_TRUE(test::mapSatisfiesConstraints(map));
      ++loaded;
    } catch (const MapFileError&) {
    }
  }
  EXPECT_GT(loaded, 0u);  // changed masses and heights can be valid
}

TEST(MapIo, AMapWhoseFirstCellIsTheOriginRoundTrips) {
  // Cell (0, 0) first (and alone): counted in the header like any other.
  Map map(test::unitConfig());
  map.setCellVolumes({0, 0}, CellVolumes{{{0.0f, 1.0f, 1.0f}}, {{2.5f, 4.0f, 1.5f}}});
  const Bytes bytes = serializeMap(map);
  EXPECT_EQ(bytes.size(), 64u + 16u + 2u * 12u + 8u);
  const Map loaded = deserializeMap(bytes.data(), bytes.size());
  EXPECT_TRUE(test::sameVolumes(allVolumes(loaded), allVolumes(map)));
}

TEST(MapIo, RefusesCountsThatLeaveBytesUnread) {
  // The size must equal 64 + 16 C + 12 V + 8: counts describing the first two cells only
  // (2 cells, 4 volumes) leave the third cell's bytes over.
  Bytes bad = buildFile(0.5, 100.0, smallCells());
  putLe(bad, kCellCountOffset, 2, 8);
  putLe(bad, kVolumeCountOffset, 4, 8);
  fixChecksum(bad);
  EXPECT_TRUE(refused(bad));
}

TEST(MapIo, RefusesVersionOneFilesWithReservedBytesSet) {
  // Version 1 had 16 reserved bytes (zero) at 48, where version 2 keeps the rules: a version 1
  // file with rule bits there is not the paper's model it claims to be.
  const Bytes file = buildFile(0.5, 100.0, smallCells(), 1, 0);
  ASSERT_FALSE(refused(file));
  for (const std::size_t offset : {48u, 52u, 56u, 60u}) {
    Bytes bad = file;
    bad[offset] = 1;
    fixChecksum(bad);
    EXPECT_TRUE(refused(bad)) << offset;
  }
}

}  // namespace
}  // namespace mvog
