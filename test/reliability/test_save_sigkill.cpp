// mvog::saveMap is atomic (a temporary file in the same directory, fsync, rename): a process
// killed with SIGKILL at any moment of a save leaves the previous complete map or the new one at
// the path, never a partial file. A child process saves two different maps in turn, over and
// over; the parent kills it at a random moment, many times, and every time loads the file left.
// Run by scripts/sanitizers.sh (AddressSanitizer + UBSan). No wall-clock time is asserted: the
// length of one save only scales the random moments at which the child is killed.
#include <dirent.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "mvog/map.h"
#include "mvog/map_io.h"

namespace {

constexpr int kKills = 60;

mvog::Map makeMap(std::uint32_t seed, std::size_t rays) {
  mvog::MapConfig config;
  config.resolution = 0.2;
  config.max_coordinate = 100.0;
  mvog::Map map(config);
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI);
  std::uniform_real_distribution<double> range(1.0, 8.0);
  std::uniform_real_distribution<double> height(0.0, 2.5);
  mvog::Scan scan;
  scan.origin = {0.0, 0.0, 1.0};
  for (std::size_t k = 0; k < rays; ++k) {
    const double a = angle(random);
    const double r = range(random);
    scan.hits.emplace_back(static_cast<float>(r * std::cos(a)), static_cast<float>(r * std::sin(a)),
                           static_cast<float>(height(random)));
  }
  map.insertScan(scan);
  return map;
}

std::vector<std::string> temporariesBeside(const std::string& directory, const std::string& name) {
  std::vector<std::string> found;
  DIR* dir = ::opendir(directory.c_str());
  if (dir == nullptr) return found;
  while (const dirent* entry = ::readdir(dir)) {
    const std::string file = entry->d_name;
    if (file.rfind("." + name + ".saving-", 0) == 0) found.push_back(directory + "/" + file);
  }
  ::closedir(dir);
  return found;
}

TEST(SaveUnderSigkill, EveryKillLeavesAMapThatLoads) {
  char directory_template[] = "/tmp/mvog_sigkill_XXXXXX";
  ASSERT_NE(::mkdtemp(directory_template), nullptr);
  const std::string directory = directory_template;
  const std::string path = directory + "/autosave.mvog";

  const mvog::Map map_a = makeMap(1, 2000);
  const mvog::Map map_b = makeMap(2, 1500);
  const std::vector<std::uint8_t> bytes_a = mvog::serializeMap(map_a);
  const std::vector<std::uint8_t> bytes_b = mvog::serializeMap(map_b);
  ASSERT_NE(bytes_a, bytes_b);

  // One save's duration, to spread the kills over whole saves (not asserted).
  const auto start = std::chrono::steady_clock::now();
  mvog::saveMap(map_a, path);
  const auto save_time = std::chrono::duration_cast<std::chrono::microseconds>(
                             std::chrono::steady_clock::now() - start)
                             .count();
  std::mt19937 random(12345);
  std::uniform_int_distribution<long> delay(0, 2 * save_time + 1);
  std::uniform_int_distribution<long> short_delay(0, 2000);

  int kills_leaving_a_temporary = 0;
  int loaded_a = 0;
  int loaded_b = 0;
  for (int kill = 0; kill < kKills; ++kill) {
    int ready[2];
    ASSERT_EQ(::pipe(ready), 0);
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      ::prctl(PR_SET_PDEATHSIG, SIGKILL);  // never outlive a test that failed
      ::close(ready[0]);
      const char byte = 1;
      if (::write(ready[1], &byte, 1) != 1) ::_exit(2);
      for (int k = 0;; ++k) mvog::saveMap(k % 2 == 0 ? map_b : map_a, path);
    }
    ::close(ready[1]);
    char byte = 0;
    ASSERT_EQ(::read(ready[0], &byte, 1), 1);
    ::close(ready[0]);
    if (kill % 2 == 0) {
      // Any moment of a save (most of which is serialising in memory).
      std::this_thread::sleep_for(std::chrono::microseconds(delay(random)));
    } else {
      // Once the temporary exists (writing, fsync, rename), a little later.
      for (long polls = 0; polls < 1000000 && temporariesBeside(directory, "autosave.mvog").empty();
           ++polls) {
      }
      std::this_thread::sleep_for(std::chrono::microseconds(short_delay(random)));
    }
    ASSERT_EQ(::kill(child, SIGKILL), 0);
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL)
        << "the saving child ended by itself: status " << status;

    std::vector<std::uint8_t> loaded;
    try {
      loaded = mvog::serializeMap(mvog::loadMap(path));
    } catch (const mvog::MapFileError& e) {
      FAIL() << "after kill " << kill << " the file does not load: " << e.what();
    }
    if (loaded == bytes_a) {
      ++loaded_a;
    } else if (loaded == bytes_b) {
      ++loaded_b;
    } else {
      FAIL() << "after kill " << kill << " the file holds neither of the maps saved";
    }
    // A kill during a save leaves its temporary (never at the path itself): clean up.
    const std::vector<std::string> temporaries = temporariesBeside(directory, "autosave.mvog");
    if (!temporaries.empty()) ++kills_leaving_a_temporary;
    for (const std::string& temporary : temporaries) ::unlink(temporary.c_str());
  }
  std::printf(
      "%d kills: %d left map A, %d map B; %d interrupted a save (left a temporary); "
      "files of %zu and %zu bytes; one save takes ~%ld us\n",
      kKills, loaded_a, loaded_b, kills_leaving_a_temporary, bytes_a.size(), bytes_b.size(),
      static_cast<long>(save_time));
  RecordProperty("kills_interrupting_a_save", kills_leaving_a_temporary);
  // The test killed some saves between creating the temporary and renaming it.
  EXPECT_GT(kills_leaving_a_temporary, 0);
  ::unlink(path.c_str());
  ::rmdir(directory.c_str());
}

}  // namespace
