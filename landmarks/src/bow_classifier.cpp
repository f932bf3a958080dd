#include <opencv2/ml.hpp>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "sketchnav/landmarks/bow.h"

namespace sketchnav::landmarks {

cv::Mat bowHistogram(const std::vector<int>& words, const std::vector<float>& idf) {
  cv::Mat h = cv::Mat::zeros(1, static_cast<int>(idf.size()), CV_32F);
  if (words.empty()) return h;
  float* p = h.ptr<float>();
  for (int w : words) p[w] += 1.0f;
  // tf-idf, then square root (power normalisation), then L2: the BoW counterpart of RootSIFT.
  double ss = 0;
  const float inv_n = 1.0f / static_cast<float>(words.size());
  for (int i = 0; i < h.cols; ++i) {
    if (p[i] == 0) continue;
    p[i] = std::sqrt(p[i] * inv_n * idf[i]);
    ss += static_cast<double>(p[i]) * p[i];
  }
  if (ss > 0) h *= 1.0 / std::sqrt(ss);
  return h;
}

std::vector<float> LinearClassifier::decision(const cv::Mat& hist) const {
  std::vector<float> s(classes(), 0.0f);
  if (classes() == 1) {
    s[0] = 1e3f;  // one class: BoW cannot reject, verification does
    return s;
  }
  cv::Mat d = weights * hist.t();  // C x 1
  for (int c = 0; c < classes(); ++c) s[c] = d.at<float>(c) - rho[c];
  return s;
}

std::vector<float> LinearClassifier::probabilities(const cv::Mat& hist) const {
  std::vector<float> s = decision(hist);
  for (auto& v : s) v = 1.0f / (1.0f + std::exp(-(platt_a * v + platt_b)));
  return s;
}

namespace {

// One binary linear SVM, as (w, rho) with w·x − rho > 0 for the positive class.
void trainBinary(const cv::Mat& x, const std::vector<int>& positive, double c, cv::Mat& w,
                 float& rho) {
  const int n = x.rows;
  int npos = 0;
  cv::Mat y(n, 1, CV_32S);
  for (int i = 0; i < n; ++i) {
    y.at<int>(i) = positive[i] ? 1 : -1;
    npos += positive[i] ? 1 : 0;
  }
  w = cv::Mat::zeros(1, x.cols, CV_32F);
  rho = 0;
  if (npos == 0 || npos == n) {  // degenerate fold: constant score
    rho = npos == 0 ? 1.0f : -1.0f;
    return;
  }
  auto svm = cv::ml::SVM::create();
  svm->setType(cv::ml::SVM::C_SVC);
  svm->setKernel(cv::ml::SVM::LINEAR);
  svm->setC(c);
  // Class-balanced: a class has ~1/C of the photos, so weigh its errors up accordingly.
  cv::Mat cw = (cv::Mat_<double>(2, 1) << 1.0, static_cast<double>(n - npos) / npos);
  svm->setClassWeights(cw);
  svm->setTermCriteria(
      cv::TermCriteria(cv::TermCriteria::MAX_ITER | cv::TermCriteria::EPS, 10000, 1e-4));
  svm->train(cv::ml::TrainData::create(x, cv::ml::ROW_SAMPLE, y));
  cv::Mat sv = svm->getSupportVectors();  // linear kernel: compressed to w
  cv::Mat alpha, svidx;
  const double r = svm->getDecisionFunction(0, alpha, svidx);
  alpha.convertTo(alpha, CV_32F);
  for (int i = 0; i < static_cast<int>(svidx.total()); ++i)
    w += alpha.at<float>(i) * sv.row(svidx.at<int>(i));
  rho = static_cast<float>(r);
  // cv::ml's sign convention depends on label order: orient by the training data.
  cv::Mat d = x * w.t();
  double mp = 0, mn = 0;
  for (int i = 0; i < n; ++i) (positive[i] ? mp : mn) += d.at<float>(i) - rho;
  if (mp / npos < mn / (n - npos)) {
    w = -w;
    rho = -rho;
  }
}

// Platt (1999) sigmoid fit p = 1 / (1 + exp(-(a s + b))) by Newton's method on the
// regularised targets.
void fitPlatt(const std::vector<float>& s, const std::vector<int>& y, float& a_out, float& b_out) {
  double np = 0, nn = 0;
  for (int v : y) (v ? np : nn) += 1;
  const double tp = (np + 1) / (np + 2), tn = 1 / (nn + 2);
  double a = 1, b = 0;
  for (int it = 0; it < 50; ++it) {
    double g1 = 0, g2 = 0, h11 = 1e-9, h22 = 1e-9, h12 = 0;
    for (size_t i = 0; i < s.size(); ++i) {
      const double t = y[i] ? tp : tn;
      const double p = 1 / (1 + std::exp(-(a * s[i] + b)));
      const double d = p - t, q = std::max(p * (1 - p), 1e-12);
      g1 += d * s[i];
      g2 += d;
      h11 += q * s[i] * s[i];
      h22 += q;
      h12 += q * s[i];
    }
    const double det = h11 * h22 - h12 * h12;
    if (std::abs(det) < 1e-15) break;
    const double da = (h22 * g1 - h12 * g2) / det, db = (h11 * g2 - h12 * g1) / det;
    a -= da;
    b -= db;
    if (std::abs(da) + std::abs(db) < 1e-7) break;
  }
  a_out = static_cast<float>(a);
  b_out = static_cast<float>(b);
}

}  // namespace

LinearClassifier LinearClassifier::train(const cv::Mat& hists, const std::vector<int>& labels,
                                         int classes, double c, unsigned seed) {
  LinearClassifier lc;
  const int n = hists.rows;
  lc.weights = cv::Mat::zeros(classes, hists.cols, CV_32F);
  lc.rho.assign(classes, 0.0f);
  if (classes == 1) return lc;
  std::vector<int> pos(n);
  for (int k = 0; k < classes; ++k) {
    for (int i = 0; i < n; ++i) pos[i] = labels[i] == k;
    cv::Mat w;
    trainBinary(hists, pos, c, w, lc.rho[k]);
    w.copyTo(lc.weights.row(k));
  }
  // Calibration on held-out scores: 2 folds, stratified per class, seeded.
  std::vector<int> fold(n);
  {
    std::mt19937 rng(seed);
    std::vector<std::vector<int>> per(classes);
    for (int i = 0; i < n; ++i) per[labels[i]].push_back(i);
    for (auto& v : per) {
      std::shuffle(v.begin(), v.end(), rng);
      for (size_t j = 0; j < v.size(); ++j) fold[v[j]] = static_cast<int>(j % 2);
    }
  }
  std::vector<float> scores;
  std::vector<int> truth;
  for (int f = 0; f < 2; ++f) {
    std::vector<int> tr, te;
    for (int i = 0; i < n; ++i) (fold[i] == f ? te : tr).push_back(i);
    if (tr.empty() || te.empty()) continue;
    cv::Mat xtr(static_cast<int>(tr.size()), hists.cols, CV_32F);
    for (size_t j = 0; j < tr.size(); ++j) hists.row(tr[j]).copyTo(xtr.row(static_cast<int>(j)));
    for (int k = 0; k < classes; ++k) {
      std::vector<int> p(tr.size());
      int npos = 0;
      for (size_t j = 0; j < tr.size(); ++j) npos += p[j] = labels[tr[j]] == k;
      if (npos == 0) continue;  // class absent from this fold's training half
      cv::Mat w;
      float r;
      trainBinary(xtr, p, c, w, r);
      for (int i : te) {
        scores.push_back(static_cast<float>(hists.row(i).dot(w)) - r);
        truth.push_back(labels[i] == k);
      }
    }
  }
  if (!scores.empty()) fitPlatt(scores, truth, lc.platt_a, lc.platt_b);
  return lc;
}

}  // namespace sketchnav::landmarks
