#include <opencv2/flann.hpp>
// After flann.hpp, which it needs (cvflann::seed_random).
#include <opencv2/flann/random.h>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <numeric>
#include <random>

#include "sketchnav/core/error.h"
#include "sketchnav/landmarks/vocabulary.h"

namespace sketchnav::landmarks {

struct Vocabulary::Index {
  cv::flann::Index index;
};

Vocabulary::Vocabulary() = default;
Vocabulary::~Vocabulary() = default;
Vocabulary::Vocabulary(const Vocabulary& o) : centres_(o.centres_), idf_(o.idf_) {
  buildIndex();
}
Vocabulary& Vocabulary::operator=(const Vocabulary& o) {
  if (this != &o) {
    centres_ = o.centres_;
    idf_ = o.idf_;
    buildIndex();
  }
  return *this;
}

void Vocabulary::buildIndex() {
  index_.reset();
  if (centres_.empty()) return;
  index_ = std::make_shared<Index>();
  // The kd-tree build draws split dimensions from FLANN's global rand(): seed it so word
  // assignment, and so every figure derived from it, is reproducible.
  cvflann::seed_random(12345);
  index_->index.build(centres_, cv::flann::KDTreeIndexParams(4));
}

Vocabulary Vocabulary::train(const cv::Mat& descriptors, const VocabularyParams& p) {
  CV_Assert(descriptors.empty() || descriptors.type() == CV_32F);
  const int n = descriptors.rows;
  const int k = std::min(p.size, n / 10);
  if (k < 2)
    throw InputError("landmark set: too few features to build a vocabulary (" + std::to_string(n) +
                     " descriptors; need at least 20 — add photos with "
                     "more texture)");
  // Sample without replacement, seeded.
  cv::Mat sample;
  if (n > p.sample) {
    std::vector<int> idx(n);
    std::iota(idx.begin(), idx.end(), 0);
    std::mt19937 rng(p.seed);
    std::shuffle(idx.begin(), idx.end(), rng);
    idx.resize(p.sample);
    std::sort(idx.begin(), idx.end());
    sample.create(p.sample, descriptors.cols, CV_32F);
    for (int i = 0; i < p.sample; ++i) descriptors.row(idx[i]).copyTo(sample.row(i));
  } else {
    sample = descriptors;
  }
  // k-means++ seeding uses cv::theRNG(): fix its state for this call and restore it after.
  cv::RNG& rng = cv::theRNG();
  const uint64 saved = rng.state;
  rng.state = 0x9E3779B97F4A7C15ull ^ p.seed;
  cv::Mat labels, centres;
  cv::kmeans(sample, k, labels,
             cv::TermCriteria(cv::TermCriteria::MAX_ITER | cv::TermCriteria::EPS,
                              std::max(1, p.iterations), 1e-4),
             1, cv::KMEANS_PP_CENTERS, centres);
  rng.state = saved;
  Vocabulary v;
  v.centres_ = centres;
  v.idf_.assign(k, 1.0f);
  v.buildIndex();
  return v;
}

Vocabulary Vocabulary::fromCentres(cv::Mat centres, std::vector<float> idf) {
  CV_Assert(centres.type() == CV_32F && static_cast<int>(idf.size()) == centres.rows);
  Vocabulary v;
  v.centres_ = centres;
  v.idf_ = std::move(idf);
  v.buildIndex();
  return v;
}

void Vocabulary::computeIdf(const std::vector<std::vector<int>>& words_per_image) {
  std::vector<int> df(size(), 0);
  std::vector<char> seen(size());
  for (const auto& ws : words_per_image) {
    std::fill(seen.begin(), seen.end(), 0);
    for (int w : ws)
      if (!seen[w]) seen[w] = 1, ++df[w];
  }
  const double n = static_cast<double>(words_per_image.size());
  idf_.resize(size());
  for (int w = 0; w < size(); ++w)
    idf_[w] = static_cast<float>(std::max(0.0, std::log(n / (1.0 + df[w]))));
}

std::vector<int> Vocabulary::assign(const cv::Mat& descriptors) const {
  std::vector<int> out;
  if (descriptors.empty() || !index_) return out;
  cv::Mat idx, dist;
  index_->index.knnSearch(descriptors, idx, dist, 1, cv::flann::SearchParams(16));
  out.resize(descriptors.rows);
  for (int i = 0; i < descriptors.rows; ++i) out[i] = idx.at<int>(i, 0);
  return out;
}

}  // namespace sketchnav::landmarks
