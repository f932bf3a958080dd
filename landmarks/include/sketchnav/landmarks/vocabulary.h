#pragma once
// Visual vocabulary: k-means centres over training descriptors, with a fast approximate
// nearest-centre assignment (FLANN randomised kd-trees) and per-word IDF weights.
#include <opencv2/core.hpp>

#include <memory>
#include <vector>

namespace sketchnav::landmarks {

struct VocabularyParams {
  int size = 1000;     // words; capped at (training descriptors / 10)
  int sample = 60000;  // descriptors sampled for k-means (bounds training time)
  int iterations = 8;  // k-means iterations
  unsigned seed = 1;   // sampling + k-means++ seeding: same seed, same vocabulary
};

class Vocabulary {
 public:
  Vocabulary();
  ~Vocabulary();
  Vocabulary(const Vocabulary&);
  Vocabulary& operator=(const Vocabulary&);

  /// k-means over `descriptors` (N x D CV_32F). Deterministic for a given seed.
  /// Throws InputError when there are fewer descriptors than 2 words need.
  static Vocabulary train(const cv::Mat& descriptors, const VocabularyParams& p);
  /// From stored centres (K x D CV_32F) and IDF weights (K).
  static Vocabulary fromCentres(cv::Mat centres, std::vector<float> idf);

  int size() const { return centres_.rows; }
  const cv::Mat& centres() const { return centres_; }
  const std::vector<float>& idf() const { return idf_; }
  /// Sets IDF from the per-image word lists: idf_w = log(N / (1 + n_w)) clipped at 0.
  void computeIdf(const std::vector<std::vector<int>>& words_per_image);

  /// Nearest word per descriptor row (approximate: FLANN kd-trees, exact on ties of
  /// well-separated words). Thread-safe after construction.
  std::vector<int> assign(const cv::Mat& descriptors) const;

 private:
  void buildIndex();
  cv::Mat centres_;
  std::vector<float> idf_;
  struct Index;
  std::shared_ptr<Index> index_;
};

}  // namespace sketchnav::landmarks
