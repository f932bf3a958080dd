// Corrupt model files (issue 28): a bad-input campaign found a model whose SVM rho had 0 rows
// crash load with SIGFPE and another with SIGSEGV. The checksum catches accidents, not a
// crafted file, so these mutations re-seal it: every one must load cleanly or be an
// InputError naming the model file — never a crash, an OpenCV error or bad_alloc.
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <iostream>
#include <random>

#include "sketchnav/core/error.h"
#include "sketchnav/core/hash.h"
#include "sketchnav/landmarks/landmark_set.h"
#include "sketchnav/landmarks/model.h"
#include "test_data.h"
#include "test_recognition_support.h"

using namespace sketchnav;
using namespace sketchnav::landmarks;

namespace {
constexpr size_t kHeader = 8 + 4 + 8 + 8;

// Fixes the payload size and checksum after a mutation, so the loader's own checks run.
std::string reseal(std::string data) {
  const std::uint64_t size = data.size() - kHeader;
  const std::uint64_t sum = fnv1a(data.data() + kHeader, size);
  std::memcpy(&data[12], &size, 8);
  std::memcpy(&data[20], &sum, 8);
  return data;
}

template <class T>
T at(const std::string& d, size_t off) {
  T v;
  std::memcpy(&v, d.data() + off, sizeof v);
  return v;
}
template <class T>
void put(std::string& d, size_t off, T v) {
  std::memcpy(&d[off], &v, sizeof v);
}

// Offsets of the top-level matrix headers: vocabulary centres, idf, classifier weights, rho,
// colour weights, colour rho (format version 5 layout).
std::vector<size_t> matrixHeaders(const std::string& d) {
  size_t o = kHeader;
  o += 8 + at<std::uint64_t>(d, o);  // params
  o += 8 + at<std::uint64_t>(d, o);  // fingerprint
  const auto n = at<std::uint32_t>(d, o);
  o += 4;
  for (std::uint32_t i = 0; i < n; ++i) o += 8 + at<std::uint64_t>(d, o);
  std::vector<size_t> out;
  auto skipMat = [&] {
    out.push_back(o);
    const auto r = at<std::int32_t>(d, o), c = at<std::int32_t>(d, o + 4),
               t = at<std::int32_t>(d, o + 8);
    o += 12 + static_cast<size_t>(r) * static_cast<size_t>(c) * (t == 0 ? 1 : 4);
  };
  skipMat();  // centres
  skipMat();  // idf
  skipMat();  // weights
  skipMat();  // rho
  o += 8;     // Platt
  skipMat();  // colour weights
  skipMat();  // colour rho
  return out;
}

// "ok", "input" or the description of anything else that escaped.
std::string tryLoad(const std::string& path, std::string* msg) {
  try {
    LandmarkModel::load(path);
    return "ok";
  } catch (const InputError& e) {
    *msg = e.what();
    return "input";
  } catch (const std::exception& e) {
    *msg = e.what();
    return std::string("other: ") + e.what();
  }
}

void writeAll(const std::string& path, const std::string& data) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << data;
}
}  // namespace

TEST(ModelMutation, EveryMutatedModelLoadsOrIsAnInputErrorNamingTheFile) {
  const std::string root = test::tempDir("model-mutation-set");
  test::writeLandmarkSet(root, 2, 3, 11);
  ModelParams p;
  p.vocabulary_size = 32;
  p.features.max_features = 120;
  p.kmeans_iterations = 3;
  const std::string dir = test::tempDir("model-mutation");
  const std::string good_path = dir + "/good.slm";
  trainModel(root, p).save(good_path);
  std::ifstream in(good_path, std::ios::binary);
  const std::string good((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(good.size(), kHeader + 1000);

  std::vector<std::pair<std::string, std::string>> cases;  // (what, bytes)
  // Targeted: each top-level matrix with 0 rows, 0 cols, huge rows/cols, another type.
  const auto headers = matrixHeaders(good);
  ASSERT_EQ(headers.size(), 6u);
  for (size_t h = 0; h < headers.size(); ++h) {
    const size_t o = headers[h];
    const std::string name = "matrix " + std::to_string(h);
    for (const auto& [field, value] : std::vector<std::pair<int, std::int32_t>>{
             {0, 0}, {4, 0}, {0, 0x7fffffff}, {4, 0x7fffffff}, {0, -1}, {8, 0}, {8, 4}}) {
      std::string d = good;
      put<std::int32_t>(d, o + static_cast<size_t>(field), value);
      cases.emplace_back(name + " field " + std::to_string(field) + "=" + std::to_string(value),
                         reseal(d));
    }
  }
  // Seeded random: byte flips, random 32-bit words, truncations, all re-sealed.
  std::mt19937 rng(28);
  for (int i = 0; i < 300; ++i) {
    std::string d = good;
    const size_t span = d.size() - kHeader;
    std::uniform_int_distribution<size_t> pos(kHeader, d.size() - 1);
    switch (i % 3) {
      case 0:
        for (int k = 0; k < 1 + i % 4; ++k) d[pos(rng)] ^= static_cast<char>(1 << (rng() % 8));
        break;
      case 1: {
        const size_t o = std::min(pos(rng), d.size() - 4);
        const std::int32_t vals[] = {0, -1, 1, 0x7fffffff, static_cast<std::int32_t>(rng())};
        put<std::int32_t>(d, o, vals[rng() % 5]);
        break;
      }
      default:
        d.resize(kHeader + rng() % span);
        break;
    }
    cases.emplace_back("random " + std::to_string(i), reseal(d));
    if (i % 3 == 2) cases.back().first = "truncated " + std::to_string(i);
  }
  int ok = 0, input = 0;
  const std::string path = dir + "/mutant.slm";
  for (const auto& [what, bytes] : cases) {
    writeAll(path, bytes);
    std::string msg;
    const std::string r = tryLoad(path, &msg);
    // A targeted header change or a truncation can never describe a valid model.
    const bool must_fail = what.rfind("matrix", 0) == 0 || what.rfind("truncated", 0) == 0;
    if (r == "ok") {
      ++ok;
      EXPECT_FALSE(must_fail) << what << " was accepted";
    } else if (r == "input") {
      ++input;
      EXPECT_NE(msg.find(path), std::string::npos) << what << ": " << msg;
      EXPECT_EQ(msg.find('\n'), std::string::npos) << what << ": " << msg;
      EXPECT_LT(msg.size(), 600u) << what;
    } else {
      ADD_FAILURE() << what << ": " << r;
    }
  }
  std::cout << cases.size() << " mutants: " << ok << " load, " << input << " InputError\n";
}

// A class folder holding symlinks back up the tree made `train` walk for ever (issue 28).
TEST(LandmarkSet, SymlinkLoopsAreWalkedOnce) {
  const std::string root = test::tempDir("landmark-set-loop");
  test::writeLandmarkSet(root, 2, 3, 5);
  const std::string a = root + "/group/class0";
  std::filesystem::create_directory_symlink("..", a + "/loop");
  std::filesystem::create_directory_symlink("../..", a + "/loop2");
  std::filesystem::create_directory_symlink("../class0", root + "/group/class1/sibling");
  const LandmarkSet s = scanLandmarkSet(root);
  ASSERT_EQ(s.classes.size(), 2u);
  for (const auto& c : s.classes) EXPECT_EQ(c.photos.size(), 3u) << c.name;
}
