// The shared input rules: JSON depth limit, numbers out of range, special files refused,
// outputs only to regular files in existing folders, clipped message values.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>

#include "sketchnav/core/config.h"
#include "sketchnav/core/error.h"
#include "sketchnav/core/input_file.h"
#include "sketchnav/core/json_io.h"
#include "sketchnav/core/log.h"
#include "test_data.h"

using namespace sketchnav;

namespace {
std::string nested(int depth) {
  return std::string(static_cast<size_t>(depth), '[') + "1" +
         std::string(static_cast<size_t>(depth), ']');
}
std::string messageOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "<no InputError>";
}
void write(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}
}  // namespace

TEST(JsonIo, DepthAtTheLimitParses) {
  const Json j = parseJsonText(nested(kMaxJsonDepth), "t");
  EXPECT_TRUE(j.is_array());
}

TEST(JsonIo, DeepNestingIsAnInputErrorNamingOriginAndDepth) {
  const std::string m = messageOf([] { parseJsonText(nested(100000), "w.json"); });
  EXPECT_NE(m.find("w.json"), std::string::npos) << m;
  EXPECT_NE(m.find("deeper than 64"), std::string::npos) << m;
  const std::string o = messageOf([] { parseJsonText(std::string(70, '{') + "", "obj.json"); });
  EXPECT_NE(o.find("obj.json"), std::string::npos) << o;
}

TEST(JsonIo, NumberOutOfRangeNamesTheOrigin) {
  const std::string m = messageOf([] { parseJsonText("{\"a\": 1e400}", "c.json"); });
  EXPECT_NE(m.find("c.json"), std::string::npos) << m;
  EXPECT_NE(m.find("overflow"), std::string::npos) << m;
}

TEST(JsonIo, HugeTokenInMessageIsClipped) {
  const std::string m =
      messageOf([] { parseJsonText("[1" + std::string(100000, '0') + "e9999]", "n.json"); });
  EXPECT_LT(m.size(), 400u) << m.size();
}

TEST(InputFile, SpecialFilesAreRefusedByName) {
  const std::string dir = test::tempDir("input_file");
  const std::string fifo = dir + "/pipe.json";
  ::unlink(fifo.c_str());
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  // Opening the FIFO for reading would block for ever: the check must come first.
  std::string m = messageOf([&] { parseJsonFile(fifo, "world file"); });
  EXPECT_NE(m.find("FIFO"), std::string::npos) << m;
  EXPECT_NE(m.find(fifo), std::string::npos) << m;
  m = messageOf([&] { requireRegularFile(dir, "model"); });
  EXPECT_NE(m.find("directory"), std::string::npos) << m;
  m = messageOf([] { requireRegularFile("/dev/zero", "image"); });
  EXPECT_NE(m.find("character device"), std::string::npos) << m;
  m = messageOf([&] { Config::fromFile(dir); });
  EXPECT_NE(m.find("directory"), std::string::npos) << m;
  m = messageOf([&] { Config::fromFile(fifo); });
  EXPECT_NE(m.find("FIFO"), std::string::npos) << m;
}

TEST(InputFile, SizeBoundIsChecked) {
  const std::string p = test::tempDir("input_file") + "/big.json";
  write(p, std::string(2000, ' ') + "1");
  EXPECT_THROW(readInputFile(p, "x", 1000), InputError);
  EXPECT_EQ(readInputFile(p, "x", 5000).size(), 2001u);
}

TEST(InputFile, ConfigFileErrorsNameTheFile) {
  const std::string dir = test::tempDir("input_file");
  write(dir + "/deep.json", "{\"a\":" + nested(500) + "}");
  write(dir + "/big.json", "{\"a\": 1e400}");
  std::string m = messageOf([&] { Config::fromFile(dir + "/deep.json"); });
  EXPECT_NE(m.find("deep.json"), std::string::npos) << m;
  m = messageOf([&] { Config::fromFile(dir + "/big.json"); });
  EXPECT_NE(m.find("big.json"), std::string::npos) << m;
}

TEST(InputFile, OutputsOnlyToRegularFilesInExistingFolders) {
  const std::string dir = test::tempDir("input_file");
  EXPECT_NO_THROW(requireOutputFile(dir + "/new.png", "-o"));
  write(dir + "/old.png", "x");
  EXPECT_NO_THROW(requireOutputFile(dir + "/old.png", "-o"));
  std::string m = messageOf([] { requireOutputFile("/dev/full", "-o"); });
  EXPECT_NE(m.find("/dev/full"), std::string::npos) << m;
  m = messageOf([] { requireOutputFile("/nonexistent-dir/sub/m.png", "-o"); });
  EXPECT_NE(m.find("does not exist"), std::string::npos) << m;
  EXPECT_THROW(requireOutputFile(dir, "-o"), InputError);
  EXPECT_THROW(log::setFile("/dev/full"), InputError);
}

TEST(InputFile, AtomicWriteReplacesWholeAndLeavesNoTemporary) {
  const std::string dir = test::tempDir("atomic_write");
  const std::string path = dir + "/summary.json";
  write(path, "old, longer than the new content");
  writeFileAtomically(path, "{}\n", "run summary");
  std::ifstream in(path);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), "{}\n");
  int files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) files += e.is_regular_file();
  EXPECT_EQ(files, 1) << "a temporary file was left beside " << path;
  // Special files are refused, never renamed over.
  const std::string m = messageOf([] { writeFileAtomically("/dev/full", "x", "run summary"); });
  EXPECT_NE(m.find("run summary '/dev/full'"), std::string::npos) << m;
  struct stat st {};
  ASSERT_EQ(::stat("/dev/full", &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode));
  EXPECT_THROW(writeFileAtomically("/nonexistent-dir/sub/s.json", "x", "run summary"), InputError);
}

TEST(InputFile, ClipKeepsShortValuesAndCutsLongOnes) {
  EXPECT_EQ(clipForMessage("abc"), "abc");
  const std::string c = clipForMessage(std::string(120000, 'x'));
  EXPECT_EQ(c.size(), 80u + 3u);
  EXPECT_EQ(c.substr(80), "\xE2\x80\xA6");
}
