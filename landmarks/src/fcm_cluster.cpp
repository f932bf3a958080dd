// Fuzzy c-means (ccs.h). Standard Bezdek iteration; k-means++-style seeding for stability.
#include <algorithm>
#include <cmath>
#include <random>

#include "sketchnav/landmarks/ccs.h"

namespace sketchnav::landmarks {

FcmResult fcm(const cv::Mat& points, int c, double m, int max_iter, unsigned seed) {
  FcmResult r;
  const int n = points.rows, d = points.cols;
  if (n == 0 || c <= 0) return r;
  CV_Assert(points.type() == CV_32F && m > 1.0);
  c = std::min(c, n);
  std::mt19937 rng(seed);
  // Seeding: first centre uniform, the rest with probability ∝ squared distance.
  r.centers.create(c, d, CV_32F);
  std::vector<double> dist(n, std::numeric_limits<double>::max());
  int pick = std::uniform_int_distribution<int>(0, n - 1)(rng);
  for (int k = 0; k < c; ++k) {
    points.row(pick).copyTo(r.centers.row(k));
    double total = 0;
    for (int i = 0; i < n; ++i) {
      dist[i] = std::min(dist[i], cv::norm(points.row(i), r.centers.row(k), cv::NORM_L2SQR));
      total += dist[i];
    }
    if (total <= 0) {
      pick = std::uniform_int_distribution<int>(0, n - 1)(rng);
      continue;
    }
    double u = std::uniform_real_distribution<double>(0, total)(rng);
    pick = n - 1;
    for (int i = 0; i < n; ++i) {
      u -= dist[i];
      if (u <= 0) {
        pick = i;
        break;
      }
    }
  }
  r.membership.create(n, c, CV_32F);
  const double expo = 2.0 / (m - 1.0);
  std::vector<double> dk(c);
  for (int it = 0; it < max_iter; ++it) {
    r.iterations = it + 1;
    // Memberships: u_ik = 1 / Σ_j (d_ik / d_ij)^(2/(m-1)).
    for (int i = 0; i < n; ++i) {
      const float* x = points.ptr<float>(i);
      int zero = -1;
      for (int k = 0; k < c; ++k) {
        const float* v = r.centers.ptr<float>(k);
        double s = 0;
        for (int j = 0; j < d; ++j) s += double(x[j] - v[j]) * (x[j] - v[j]);
        dk[k] = std::sqrt(s);
        if (dk[k] < 1e-12) zero = k;
      }
      float* u = r.membership.ptr<float>(i);
      if (zero >= 0) {  // the point sits on a centre: crisp membership
        for (int k = 0; k < c; ++k) u[k] = k == zero ? 1.f : 0.f;
        continue;
      }
      // u_ik = d_ik^-e / Σ_j d_ij^-e (same as 1 / Σ_j (d_ik/d_ij)^e, in O(c)).
      double total = 0;
      for (int k = 0; k < c; ++k) {
        dk[k] = expo == 2.0 ? 1.0 / (dk[k] * dk[k]) : std::pow(dk[k], -expo);
        total += dk[k];
      }
      for (int k = 0; k < c; ++k) u[k] = static_cast<float>(dk[k] / total);
    }
    // Centres: weighted means with weights u^m.
    cv::Mat next(c, d, CV_32F, cv::Scalar(0));
    std::vector<double> wsum(c, 0.0);
    for (int i = 0; i < n; ++i) {
      const float* x = points.ptr<float>(i);
      const float* u = r.membership.ptr<float>(i);
      for (int k = 0; k < c; ++k) {
        const double w = m == 2.0 ? double(u[k]) * u[k] : std::pow(u[k], m);
        wsum[k] += w;
        float* v = next.ptr<float>(k);
        for (int j = 0; j < d; ++j) v[j] += static_cast<float>(w * x[j]);
      }
    }
    for (int k = 0; k < c; ++k)
      if (wsum[k] > 0)
        next.row(k) /= wsum[k];
      else
        r.centers.row(k).copyTo(next.row(k));
    const double shift = cv::norm(next, r.centers, cv::NORM_INF);
    r.centers = next;
    if (shift < 1e-4) break;
  }
  r.labels.resize(n);
  for (int i = 0; i < n; ++i) {
    const float* u = r.membership.ptr<float>(i);
    r.labels[i] = static_cast<int>(std::max_element(u, u + c) - u);
  }
  return r;
}

}  // namespace sketchnav::landmarks
