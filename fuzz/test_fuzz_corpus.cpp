// Replays every regression input (fuzz/regressions/<parser>/*: the crashing inputs of the
// bad-input campaign and of fuzzing) and the shipped seed files through the same entry points
// the libFuzzer harnesses use. An input may be accepted or refused with an InputError; a
// crash or any other exception fails the test, and so does any single allocation over 1 GiB.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <new>

#include "entry_points.h"
#include "sketchnav/core/log.h"
#include "test_data.h"

namespace fs = std::filesystem;

// libFuzzer reports an input that makes a parser allocate more than -rss_limit_mb as an OOM;
// here that has to be a failure too, and bad_alloc is no use: MRPT's rawlog code catches it and
// just ends the log (fuzz/regressions/rawlog/oom-*: length fields asking for 3.6-4.3 GB). No
// input here needs anything near 1 GiB in one piece, so such a request aborts the test.
#if defined(__SANITIZE_ADDRESS__)
extern "C" const char* __asan_default_options() {
  return "max_allocation_size_mb=1024";
}
#else
void* operator new(std::size_t n) {
  if (n > (std::size_t{1} << 30)) {
    std::fprintf(stderr, "test_fuzz_corpus: an input asked for one allocation of %zu bytes\n", n);
    std::abort();
  }
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) {
  return ::operator new(n);
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete[](void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  std::free(p);
}
#endif

namespace {
std::string readAll(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Files under `dir` (recursively) whose name ends in `suffix` ("" = all).
std::vector<fs::path> filesIn(const fs::path& dir, const std::string& suffix = "") {
  std::vector<fs::path> out;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file() && e.path().filename().string() != "README.md") {
      const std::string n = e.path().filename().string();
      if (suffix.empty() || (n.size() >= suffix.size() &&
                             n.compare(n.size() - suffix.size(), suffix.size(), suffix) == 0))
        out.push_back(e.path());
    }
  std::sort(out.begin(), out.end());
  return out;
}

int replay(const std::string& parser, const std::vector<fs::path>& files) {
  const auto f = sketchnav::fuzz::byName(parser);
  EXPECT_NE(f, nullptr);
  if (!f) return 0;
  for (const auto& p : files) {
    SCOPED_TRACE(p.string());
    const std::string data = readAll(p);
    EXPECT_NO_THROW(f(reinterpret_cast<const std::uint8_t*>(data.data()), data.size()));
  }
  return static_cast<int>(files.size());
}

const fs::path kSource = sketchnav::test::sourceDir();
}  // namespace

TEST(FuzzCorpus, SketchRegressionsAndSeeds) {
  sketchnav::log::setQuiet(true);
  EXPECT_GT(replay("sketch", filesIn(kSource / "fuzz/regressions/sketch")), 0);
  EXPECT_GT(replay("sketch", filesIn(kSource / "share/sketches", ".json")), 0);
}

TEST(FuzzCorpus, WorldRegressionsAndSeeds) {
  sketchnav::log::setQuiet(true);
  EXPECT_GT(replay("world", filesIn(kSource / "fuzz/regressions/world")), 0);
  EXPECT_GT(replay("world", filesIn(kSource / "share/worlds", ".json")), 0);
}

TEST(FuzzCorpus, ConfigRegressions) {
  EXPECT_GT(replay("config", filesIn(kSource / "fuzz/regressions/config")), 0);
}

// Issue 28: 1x4000, 4000x1, a JPEG header claiming 1x60000 (and 30000x30000), truncated and
// minimal files of each format readImageFile() takes.
TEST(FuzzCorpus, ImageRegressionsAndSeeds) {
  EXPECT_GE(replay("image", filesIn(kSource / "fuzz/regressions/image")), 10);
}

TEST(FuzzCorpus, ModelAndProtocolRegressions) {
  replay("model", filesIn(kSource / "fuzz/regressions/model"));
  replay("protocol", filesIn(kSource / "fuzz/regressions/protocol"));
  // The same files re-sealed (fuzz_*_sealed), and what those harnesses found.
  replay("model_sealed", filesIn(kSource / "fuzz/regressions/model"));
  replay("protocol_sealed", filesIn(kSource / "fuzz/regressions/protocol"));
  replay("model_sealed", filesIn(kSource / "fuzz/regressions/model_sealed"));
  replay("protocol_sealed", filesIn(kSource / "fuzz/regressions/protocol_sealed"));
}

TEST(FuzzCorpus, VocRegressionsAndSeeds) {
  sketchnav::log::setQuiet(true);
  EXPECT_GT(replay("voc", filesIn(kSource / "fuzz/regressions/voc")), 0);
}

TEST(FuzzCorpus, TruthRegressionsAndSeeds) {
  EXPECT_GT(replay("truth", filesIn(kSource / "fuzz/regressions/truth")), 0);
}

TEST(FuzzCorpus, WebUiRegressionsAndSeeds) {
  EXPECT_GT(replay("webui", filesIn(kSource / "fuzz/regressions/webui")), 0);
  EXPECT_GT(replay("webui", filesIn(kSource / "share/sketches", ".json")), 0);
}

TEST(FuzzCorpus, RawlogRegressionsAndSeeds) {
  sketchnav::log::setQuiet(true);
  EXPECT_GT(replay("rawlog", filesIn(kSource / "fuzz/regressions/rawlog")), 0);
}
