#include "mvog_ros/map_paths.h"

#include <sys/stat.h>

#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>

namespace mvog_ros {
namespace {

/// realpath(3), or nothing if the path does not exist.
bool realPath(const std::string& path, std::string& resolved) {
  char buffer[PATH_MAX];
  if (::realpath(path.c_str(), buffer) == nullptr) return false;
  resolved = buffer;
  return true;
}

bool isInside(const std::string& path, const std::string& root) {
  return path.size() > root.size() && path.compare(0, root.size(), root) == 0 &&
         (root.back() == '/' || path[root.size()] == '/');
}

/// Whether the last component of `path` is a hidden name: reserved for the temporaries of saves
/// (mvog::saveMap writes `.NAME.saving-XXXXXX` and removes those nobody holds).
bool isHiddenName(const std::string& path) {
  const std::string name = path.substr(path.find_last_of('/') + 1);
  return name.size() > 1 && name.front() == '.' && name != "..";
}

}  // namespace

std::string resolveMapPath(const std::string& directory, const std::string& requested,
                           bool for_writing) {
  if (requested.empty()) throw PathRefused("the path is empty");
  if (requested.find('\0') != std::string::npos) throw PathRefused("the path contains NUL");
  std::string root;
  if (!realPath(directory, root)) {
    throw PathRefused("the map directory '" + directory + "' does not exist");
  }
  const std::string joined = requested.front() == '/' ? requested : directory + "/" + requested;
  std::string resolved;
  if (realPath(joined, resolved)) {
    // It exists: wherever its symlinks lead must be inside the directory.
    struct stat status {};
    if (::stat(resolved.c_str(), &status) != 0 || !S_ISREG(status.st_mode)) {
      throw PathRefused("'" + requested + "' is not a regular file");
    }
  } else {
    if (!for_writing) throw PathRefused("'" + requested + "' does not exist");
    if (errno != ENOENT) {
      throw PathRefused("'" + requested + "' cannot be resolved: " + std::strerror(errno));
    }
    const std::size_t slash = joined.find_last_of('/');
    const std::string name = joined.substr(slash + 1);
    if (name.empty() || name == "." || name == "..") {
      throw PathRefused("'" + requested + "' does not name a file");
    }
    std::string parent;
    if (!realPath(joined.substr(0, slash), parent)) {
      throw PathRefused("the directory of '" + requested + "' does not exist");
    }
    resolved = parent + "/" + name;
    // A dangling symlink would let the write land elsewhere.
    struct stat link_status {};
    if (::lstat(resolved.c_str(), &link_status) == 0) {
      throw PathRefused("'" + requested + "' is a dangling symlink");
    }
  }
  if (!isInside(resolved, root)) {
    throw PathRefused("'" + requested + "' resolves outside the map directory '" + root + "'");
  }
  if (isHiddenName(requested) || isHiddenName(resolved)) {
    throw PathRefused("'" + requested +
                      "' is a hidden name (reserved for the temporaries of saves)");
  }
  return resolved;
}

void makeDirectories(const std::string& directory) {
  for (std::size_t slash = 0; slash != std::string::npos;) {
    slash = directory.find('/', slash + 1);
    const std::string prefix = directory.substr(0, slash);
    if (::mkdir(prefix.c_str(), 0755) != 0 && errno != EEXIST) {
      throw PathRefused("cannot create '" + prefix + "': " + std::strerror(errno));
    }
  }
}

}  // namespace mvog_ros
