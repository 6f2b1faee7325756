#pragma once

#include <stdexcept>
#include <string>

namespace mvog_ros {

/// A path a service was asked to use that is refused; the message says why.
class PathRefused : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Resolves `requested` (relative to `directory`, or absolute) for reading or writing a map and
/// refuses anything that resolves outside `directory` once every symlink and ".." is followed:
/// a service must not become a way to read or write arbitrary files. For writing, the file may
/// not exist yet, but its parent directory must (inside `directory`). Hidden names (".x") are
/// refused: the temporaries of saves have them. Returns the real path.
std::string resolveMapPath(const std::string& directory, const std::string& requested,
                           bool for_writing);

/// Creates `directory` and its parents if they are missing. Throws PathRefused on failure.
void makeDirectories(const std::string& directory);

}  // namespace mvog_ros
