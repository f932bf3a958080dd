// The demo model cache of `experiments`, `scenarios`, `tune` and `replay` (run::ensureModel):
// trained with the run's landmarks.train settings, retrained when the cached file was trained
// with others (another version's defaults, or --set), left alone otherwise.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "sketchnav/core/config.h"
#include "sketchnav/landmarks/model.h"
#include "sketchnav/run/scenario.h"
#include "test_data.h"

namespace sketchnav::run {
namespace {

// Sets an environment variable for one test and restores it after.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::string& value) : name_(name) {
    if (const char* old = std::getenv(name)) had_ = true, old_ = old;
    ::setenv(name, value.c_str(), 1);
  }
  ~ScopedEnv() {
    if (had_)
      ::setenv(name_, old_.c_str(), 1);
    else
      ::unsetenv(name_);
  }

 private:
  const char* name_;
  bool had_ = false;
  std::string old_;
};

TEST(EnsureModel, RetrainsADemoCacheTrainedWithOtherSettings) {
  const ScopedEnv cache("XDG_CACHE_HOME", test::tempDir("ensure-model"));
  landmarks::ModelParams a;  // small and quick: what is checked is which settings it has
  a.features.max_features = 40;
  a.vocabulary_size = 40;
  a.kmeans_iterations = 2;
  const std::string path = ensureModel("", false, a);
  ASSERT_TRUE(std::filesystem::exists(path));
  EXPECT_EQ(paramsToJson(landmarks::LandmarkModel::load(path).params()), paramsToJson(a));
  // Other settings: the same cache file, retrained with them (it used to be used as it was).
  landmarks::ModelParams b = a;
  b.features.max_features = 60;
  EXPECT_EQ(ensureModel("", false, b), path);
  EXPECT_EQ(paramsToJson(landmarks::LandmarkModel::load(path).params()), paramsToJson(b));
  // The same settings again: the cache is used, not rewritten.
  const auto written = std::filesystem::last_write_time(path);
  EXPECT_EQ(ensureModel("", false, b), path);
  EXPECT_EQ(std::filesystem::last_write_time(path), written);
  // A model given is used whatever the settings.
  EXPECT_EQ(ensureModel(path, false, a), path);
}

}  // namespace
}  // namespace sketchnav::run
