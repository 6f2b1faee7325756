// Where the tests find the shared recordings: $MVOG_DATA_DIR, else ../shared/data beside the
// source tree (MVOG_SOURCE_DIR, defined by the build). A test that needs a missing recording is
// skipped, except under CI=true, where it fails.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>

namespace mvog_test {

inline std::string dataDirectory() {
  const char* from_environment = std::getenv("MVOG_DATA_DIR");
  if (from_environment != nullptr && from_environment[0] != '\0') return from_environment;
  return std::string(MVOG_SOURCE_DIR) + "/../shared/data";
}

inline bool inCi() {
  const char* ci = std::getenv("CI");
  return ci != nullptr && std::strcmp(ci, "true") == 0;
}

}  // namespace mvog_test

/// Skips the test (fails it under CI=true) unless the file `path` can be read.
#define MVOG_REQUIRE_RECORDING(path)                                                           \
  do {                                                                                         \
    if (!std::ifstream(path)) {                                                                \
      if (::mvog_test::inCi())                                                                 \
        FAIL() << (path) << " is missing (set MVOG_DATA_DIR to the shared data)";              \
      GTEST_SKIP() << (path) << " is missing: set MVOG_DATA_DIR to the shared data directory"; \
    }                                                                                          \
  } while (false)
