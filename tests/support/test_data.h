#pragma once
// Test helpers: where the shared real-image data lives, and a skip (never a pass) when absent.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <unistd.h>

namespace sketchnav::test {

/// $SKETCHNAV_DATA, else <source>/../shared/data; empty when neither exists.
inline std::string dataDir() {
  namespace fs = std::filesystem;
  if (const char* env = std::getenv("SKETCHNAV_DATA"); env && *env)
    return fs::is_directory(env) ? std::string(env) : std::string();
  const fs::path p = fs::path(SKETCHNAV_TEST_SOURCE_DIR) / ".." / "shared" / "data";
  return fs::is_directory(p) ? fs::canonical(p).string() : std::string();
}

inline std::string sourceDir() { return SKETCHNAV_TEST_SOURCE_DIR; }

/// A fresh, empty temporary directory for one test.
inline std::string tempDir(const std::string& name) {
  namespace fs = std::filesystem;
  const fs::path p = fs::temp_directory_path() /
                     ("sketchnav-test-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(p);
  fs::create_directories(p);
  return p.string();
}

}  // namespace sketchnav::test

/// Resolves `var` to dataDir()/sub, or skips the test when the data is absent.
#define SKETCHNAV_REQUIRE_DATA(var, sub)                                              \
  std::string var;                                                                    \
  do {                                                                                \
    const std::string base_ = ::sketchnav::test::dataDir();                           \
    if (base_.empty() || !std::filesystem::exists(base_ + "/" + (sub)))               \
      GTEST_SKIP() << "test data '" << (sub) << "' not found (set SKETCHNAV_DATA)";   \
    var = base_ + "/" + (sub);                                                        \
  } while (0)
