#pragma once
// Bag-of-words histograms and the one-vs-rest linear classifier over them.
//
// The "optimised BoW" of the paper is, here: RootSIFT words (Hellinger instead of L2),
// TF-IDF weighting, power (square-root) normalisation + L2 of the histogram (reduces
// burstiness: repeated texture no longer dominates), one-vs-rest linear SVMs with
// class-balanced weights and a calibrated (Platt) probability. Measured on grocery-packages
// this alone gives ~36 % top-1 (~55 % ignoring its rejection threshold): sibling products
// share most of their words. What brings it to ~67 % is in recognition.h: nearest-neighbour
// votes with a ratio test between classes, and colour-checked geometric verification of the
// shortlisted classes against the database photos. The SVM still shortlists classes the
// votes miss, and breaks ties.
#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace sketchnav::landmarks {

/// TF-IDF, square-rooted, L2-normalised histogram (1 x K CV_32F) of `words` (K = idf.size()).
cv::Mat bowHistogram(const std::vector<int>& words, const std::vector<float>& idf);

/// One-vs-rest linear classifier: score_c = w_c · h − rho_c; p_c = 1 / (1 + exp(−(a s + b))).
struct LinearClassifier {
  cv::Mat weights;         // C x K CV_32F
  std::vector<float> rho;  // C
  float platt_a = 1, platt_b = 0;

  int classes() const { return weights.rows; }
  /// Raw decision values (C) for one histogram.
  std::vector<float> decision(const cv::Mat& hist) const;
  /// Calibrated per-class probabilities (independent one-vs-rest, not summing to 1).
  std::vector<float> probabilities(const cv::Mat& hist) const;

  /// Trains C linear SVMs (cv::ml) over `hists` (N x K) with labels in [0, C); calibrates
  /// the Platt sigmoid on 2-fold cross-validated decision values. With one class, every
  /// histogram scores 1 (rejection then rests on geometric verification).
  static LinearClassifier train(const cv::Mat& hists, const std::vector<int>& labels, int classes,
                                double c, unsigned seed);
};

}  // namespace sketchnav::landmarks
