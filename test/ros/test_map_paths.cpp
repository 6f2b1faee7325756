// Service path resolution (mvog_ros/map_paths.h): everything a save or load may touch stays inside
// ~map_directory, whatever ".." or symlinks the request holds.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <climits>
#include <cstdlib>
#include <fstream>
#include <string>

#include "mvog_ros/map_paths.h"

namespace mvog_ros {
namespace {

/// A fresh temporary tree, removed at the end:
///   root/maps/              the map directory
///   root/maps/sub/          a subdirectory
///   root/maps/map.mvog      a map file
///   root/outside.mvog       a file outside the map directory
class MapPathsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char pattern[] = "/tmp/mvog_test_map_paths_XXXXXX";
    ASSERT_NE(::mkdtemp(pattern), nullptr);
    char real[PATH_MAX];
    ASSERT_NE(::realpath(pattern, real), nullptr);  // resolved paths are compared below
    root_ = real;
    maps_ = root_ + "/maps";
    ASSERT_EQ(::mkdir(maps_.c_str(), 0755), 0);
    ASSERT_EQ(::mkdir((maps_ + "/sub").c_str(), 0755), 0);
    touch(maps_ + "/map.mvog");
    touch(maps_ + "/sub/inner.mvog");
    touch(root_ + "/outside.mvog");
  }
  void TearDown() override {
    if (!root_.empty()) {
      EXPECT_EQ(std::system(("rm -rf '" + root_ + "'").c_str()), 0);
    }
  }

  static void touch(const std::string& path) { std::ofstream(path) << "data"; }
  void link(const std::string& target, const std::string& name) {
    ASSERT_EQ(::symlink(target.c_str(), (maps_ + "/" + name).c_str()), 0) << name;
  }
  void expectRefused(const std::string& requested, bool for_writing) {
    EXPECT_THROW(resolveMapPath(maps_, requested, for_writing), PathRefused)
        << "'" << requested << "' for " << (for_writing ? "writing" : "reading");
  }
  void expectRefusedBothWays(const std::string& requested) {
    expectRefused(requested, false);
    expectRefused(requested, true);
  }

  std::string root_;
  std::string maps_;
};

TEST_F(MapPathsTest, ResolvesRelativePathsInside) {
  EXPECT_EQ(resolveMapPath(maps_, "map.mvog", false), maps_ + "/map.mvog");
  EXPECT_EQ(resolveMapPath(maps_, "map.mvog", true), maps_ + "/map.mvog");
  EXPECT_EQ(resolveMapPath(maps_, "sub/inner.mvog", false), maps_ + "/sub/inner.mvog");
  EXPECT_EQ(resolveMapPath(maps_, "./sub/../map.mvog", false), maps_ + "/map.mvog");
}

TEST_F(MapPathsTest, AcceptsAbsolutePathsInside) {
  EXPECT_EQ(resolveMapPath(maps_, maps_ + "/map.mvog", false), maps_ + "/map.mvog");
  EXPECT_EQ(resolveMapPath(maps_, maps_ + "/sub/new.mvog", true), maps_ + "/sub/new.mvog");
}

TEST_F(MapPathsTest, AcceptsANewFileForSavingOnly) {
  EXPECT_EQ(resolveMapPath(maps_, "new.mvog", true), maps_ + "/new.mvog");
  EXPECT_EQ(resolveMapPath(maps_, "sub/new.mvog", true), maps_ + "/sub/new.mvog");
  expectRefused("new.mvog", false);
  expectRefused("missing/new.mvog", true);  // its directory does not exist
}

TEST_F(MapPathsTest, RefusesAbsolutePathsOutside) {
  expectRefusedBothWays(root_ + "/outside.mvog");
  expectRefused(root_ + "/new.mvog", true);
  expectRefused("/etc/passwd", false);
  expectRefused("/etc/passwd", true);
  expectRefused("/tmp/mvog_new_outside.mvog", true);
}

TEST_F(MapPathsTest, RefusesDotDotEscapes) {
  expectRefusedBothWays("../outside.mvog");
  expectRefused("../new.mvog", true);
  expectRefusedBothWays("sub/../../outside.mvog");
  expectRefused("sub/../../new.mvog", true);
  expectRefusedBothWays(maps_ + "/../outside.mvog");
  // A directory whose name starts like the map directory's is outside it.
  ASSERT_EQ(::mkdir((root_ + "/maps2").c_str(), 0755), 0);
  touch(root_ + "/maps2/map.mvog");
  expectRefusedBothWays("../maps2/map.mvog");
  expectRefusedBothWays(root_ + "/maps2/map.mvog");
}

TEST_F(MapPathsTest, RefusesSymlinksPointingOut) {
  link(root_ + "/outside.mvog", "to_file.mvog");
  expectRefusedBothWays("to_file.mvog");
  link(root_, "to_root");
  expectRefusedBothWays("to_root/outside.mvog");
  expectRefused("to_root/new.mvog", true);
}

TEST_F(MapPathsTest, AcceptsSymlinksPointingInside) {
  link(maps_ + "/sub/inner.mvog", "to_inner.mvog");
  EXPECT_EQ(resolveMapPath(maps_, "to_inner.mvog", false), maps_ + "/sub/inner.mvog");
  EXPECT_EQ(resolveMapPath(maps_, "to_inner.mvog", true), maps_ + "/sub/inner.mvog");
}

TEST_F(MapPathsTest, RefusesDanglingSymlinks) {
  link(root_ + "/not_there.mvog", "dangling_out.mvog");
  expectRefusedBothWays("dangling_out.mvog");
  link(maps_ + "/not_there.mvog", "dangling_in.mvog");
  expectRefusedBothWays("dangling_in.mvog");
}

TEST_F(MapPathsTest, RefusesWhatIsNotAFile) {
  expectRefusedBothWays("");
  expectRefusedBothWays(".");
  expectRefusedBothWays("sub");
  expectRefusedBothWays("sub/");
  expectRefused("new/", true);
  expectRefusedBothWays(std::string("map.mvog\0/../x", 14));
}

TEST_F(MapPathsTest, RefusesHiddenNamesReservedForTheTemporariesOfSaves) {
  touch(maps_ + "/.map.mvog.saving-Ab3xZ9");
  expectRefusedBothWays(".map.mvog.saving-Ab3xZ9");  // would be removed by the next save
  expectRefused(".new.mvog", true);
  expectRefusedBothWays("sub/../.map.mvog.saving-Ab3xZ9");
  link(maps_ + "/.map.mvog.saving-Ab3xZ9", "to_temporary.mvog");
  expectRefusedBothWays("to_temporary.mvog");
  // A hidden directory on the way is not a hidden name.
  ASSERT_EQ(::mkdir((maps_ + "/.robot").c_str(), 0755), 0);
  EXPECT_EQ(resolveMapPath(maps_, ".robot/map.mvog", true), maps_ + "/.robot/map.mvog");
}

TEST_F(MapPathsTest, RefusesAMissingMapDirectory) {
  EXPECT_THROW(resolveMapPath(maps_ + "/missing", "map.mvog", true), PathRefused);
}

TEST_F(MapPathsTest, MakeDirectoriesCreatesMissingParents) {
  const std::string nested = root_ + "/a/b/c";
  makeDirectories(nested);
  makeDirectories(nested + "/");  // existing: nothing to do
  struct stat status {};
  ASSERT_EQ(::stat(nested.c_str(), &status), 0);
  EXPECT_TRUE(S_ISDIR(status.st_mode));
  EXPECT_THROW(makeDirectories(root_ + "/outside.mvog/below"), PathRefused);
}

}  // namespace
}  // namespace mvog_ros
