// CCS proposals (ccs.h): L0 smoothing → gradient → h-minima markers → watershed → skeleton
// subset → FCM → region merging; windows scored by centre–surround saliency contrast.
#include <opencv2/imgproc.hpp>
#include <opencv2/ximgproc.hpp>

#include <algorithm>
#include <numeric>
#include <set>

#include "sketchnav/core/config.h"
#include "sketchnav/core/log.h"
#include "sketchnav/landmarks/ccs.h"

namespace sketchnav::landmarks {
namespace {

struct UnionFind {
  std::vector<int> p;
  explicit UnionFind(int n) : p(n) { std::iota(p.begin(), p.end(), 0); }
  int find(int x) {
    while (p[x] != x) x = p[x] = p[p[x]];
    return x;
  }
};

// Morphological reconstruction by erosion of `marker` (>= mask) over `mask`, 8-bit.
cv::Mat reconstructByErosion(cv::Mat marker, const cv::Mat& mask) {
  const cv::Mat k = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(3, 3));
  cv::Mat next;
  for (int it = 0; it < 1000; ++it) {
    cv::erode(marker, next, k);
    cv::max(next, mask, next);
    if (cv::countNonZero(next != marker) == 0) break;
    std::swap(marker, next);
  }
  return next.empty() ? marker : next;
}

// Relabels `labels` (CV_32S, >= 0) by union-find roots → 0..k-1; returns k.
int compact(cv::Mat& labels, UnionFind& uf) {
  std::vector<int> id(uf.p.size(), -1);
  int k = 0;
  for (int y = 0; y < labels.rows; ++y) {
    int* l = labels.ptr<int>(y);
    for (int x = 0; x < labels.cols; ++x) {
      const int r = uf.find(l[x]);
      if (id[r] < 0) id[r] = k++;
      l[x] = id[r];
    }
  }
  return k;
}

std::vector<std::set<int>> adjacency(const cv::Mat& labels, int n) {
  std::vector<std::set<int>> adj(n);
  for (int y = 0; y < labels.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    const int* d = y + 1 < labels.rows ? labels.ptr<int>(y + 1) : nullptr;
    for (int x = 0; x < labels.cols; ++x) {
      if (x + 1 < labels.cols && l[x + 1] != l[x]) {
        adj[l[x]].insert(l[x + 1]);
        adj[l[x + 1]].insert(l[x]);
      }
      if (d && d[x] != l[x]) {
        adj[l[x]].insert(d[x]);
        adj[d[x]].insert(l[x]);
      }
    }
  }
  return adj;
}

// The watershed over-segmentation and its skeleton subset, shared by every FCM cluster count.
struct Oversegmentation {
  cv::Mat labels;  // CV_32S 0..n-1, boundaries assigned to a neighbour
  int n = 0;
  cv::Mat lab;  // CV_32F 3-channel Lab of the smoothed image
  std::vector<cv::Point> skeleton;
};

double msSince(int64 t0) {
  return 1000.0 * static_cast<double>(cv::getTickCount() - t0) / cv::getTickFrequency();
}

Oversegmentation overSegment(const cv::Mat& bgr, const CcsParams& p) {
  Oversegmentation o;
  cv::Mat sm;
  int64 t0 = cv::getTickCount();
  // L0 smoothing dominates the cost (FFTs per iteration), so it runs at l0_long_side (a
  // 2·3·5-smooth size) and the piecewise-flat result is interpolated back up.
  const double ls =
      std::min(1.0, static_cast<double>(p.l0_long_side) / std::max(bgr.cols, bgr.rows));
  if (ls < 1.0) {
    cv::Mat small, small_sm;
    const cv::Size s(cv::getOptimalDFTSize(std::max(2, cvRound(bgr.cols * ls))),
                     cv::getOptimalDFTSize(std::max(2, cvRound(bgr.rows * ls))));
    cv::resize(bgr, small, s, 0, 0, cv::INTER_AREA);
    cv::ximgproc::l0Smooth(small, small_sm, p.l0_lambda, p.l0_kappa);
    cv::resize(small_sm, sm, bgr.size(), 0, 0, cv::INTER_LINEAR);
  } else {
    cv::ximgproc::l0Smooth(bgr, sm, p.l0_lambda, p.l0_kappa);
  }
  const double t_l0 = msSince(t0);
  t0 = cv::getTickCount();
  // Per-channel gradient magnitude, combined by the maximum.
  std::vector<cv::Mat> ch;
  cv::split(sm, ch);
  cv::Mat grad(sm.size(), CV_32F, cv::Scalar(0));
  for (const auto& c : ch) {
    cv::Mat gx, gy, mag;
    cv::Sobel(c, gx, CV_32F, 1, 0, 3);
    cv::Sobel(c, gy, CV_32F, 0, 1, 3);
    cv::magnitude(gx, gy, mag);
    cv::max(grad, mag, grad);
  }
  cv::Mat g8;
  grad.convertTo(g8, CV_8U, 0.25);  // Sobel 3x3 max ≈ 4·255·√2: keep within 0..255
  cv::min(g8, 254, g8);
  // h-minima transform, then its regional minima: the only allowed minima (markers).
  cv::Mat hmin = reconstructByErosion(g8 + cv::Scalar(p.h_min), g8);
  cv::Mat rmin = reconstructByErosion(hmin + cv::Scalar(1), hmin);
  cv::Mat minima = rmin > hmin;
  cv::Mat markers;
  const int nm = cv::connectedComponents(minima, markers, 8, CV_32S);
  const double t_markers = msSince(t0);
  t0 = cv::getTickCount();
  // Marker-controlled watershed on the smoothed image.
  cv::watershed(sm, markers);
  // Single skeleton refinement: thin the region interiors to a one-pixel skeleton.
  // Thinning is iterative (one pass per pixel of region half-width), so it runs on the
  // interior mask at half resolution; skeleton points are mapped back and kept when they fall
  // inside a region.
  cv::Mat interior = markers > 0, half, skel;
  cv::resize(interior, half, cv::Size((interior.cols + 1) / 2, (interior.rows + 1) / 2), 0, 0,
             cv::INTER_NEAREST);
  cv::ximgproc::thinning(half, skel, cv::ximgproc::THINNING_ZHANGSUEN);
  std::vector<cv::Point> pts;
  cv::findNonZero(skel, pts);
  for (const auto& q : pts) {
    const cv::Point full(std::min(2 * q.x, interior.cols - 1),
                         std::min(2 * q.y, interior.rows - 1));
    if (interior.at<uchar>(full)) o.skeleton.push_back(full);
  }
  // Boundary pixels (-1) join the left / upper / any neighbouring region.
  for (int pass = 0; pass < 2; ++pass)
    for (int y = 0; y < markers.rows; ++y)
      for (int x = 0; x < markers.cols; ++x) {
        int& l = markers.at<int>(y, x);
        if (l > 0) continue;
        const int dx[4] = {-1, 0, 1, 0}, dy[4] = {0, -1, 0, 1};
        for (int k = 0; k < 4 && l <= 0; ++k) {
          const int xx = x + dx[k], yy = y + dy[k];
          if (xx >= 0 && yy >= 0 && xx < markers.cols && yy < markers.rows &&
              markers.at<int>(yy, xx) > 0)
            l = markers.at<int>(yy, xx);
        }
      }
  markers.setTo(1, markers <= 0);
  markers -= 1;  // 0..nm-2
  o.labels = markers;
  o.n = std::max(1, nm - 1);
  cv::Mat f;
  sm.convertTo(f, CV_32F, 1.0 / 255.0);
  cv::cvtColor(f, o.lab, cv::COLOR_BGR2Lab);
  log::debug("ccs", "over-segmentation",
             {{"size", std::to_string(bgr.cols) + "x" + std::to_string(bgr.rows)},
              {"regions", std::to_string(o.n)},
              {"skeleton_px", std::to_string(o.skeleton.size())},
              {"l0_ms", std::to_string(t_l0)},
              {"markers_ms", std::to_string(t_markers)},
              {"watershed_skeleton_ms", std::to_string(msSince(t0))}});
  return o;
}

// FCM over the skeleton subset and region merging; returns the label maps after the FCM merge
// (fine) and after the small-region merge (coarse).
std::pair<cv::Mat, cv::Mat> fcmMerge(const Oversegmentation& o, int clusters, const CcsParams& p) {
  const int n = o.n;
  // The skeleton is the clustered subset; cap it so FCM stays cheap.
  const int stride = std::max<int>(1, static_cast<int>(o.skeleton.size()) / 600);
  cv::Mat pts;
  for (size_t i = 0; i < o.skeleton.size(); i += stride) {
    const cv::Vec3f c = o.lab.at<cv::Vec3f>(o.skeleton[i]);
    pts.push_back(cv::Mat(1, 3, CV_32F, const_cast<float*>(&c[0])).clone());
  }
  std::vector<double> area(n, 0.0);
  std::vector<cv::Vec3d> colour(n, cv::Vec3d(0, 0, 0));
  for (int y = 0; y < o.labels.rows; ++y)
    for (int x = 0; x < o.labels.cols; ++x) {
      const int l = o.labels.at<int>(y, x);
      area[l] += 1;
      const cv::Vec3f c = o.lab.at<cv::Vec3f>(y, x);
      colour[l] += cv::Vec3d(c[0], c[1], c[2]);
    }
  if (pts.rows < 2) return {o.labels.clone(), o.labels.clone()};
  const FcmResult f = fcm(pts, clusters, p.fcm_m, p.fcm_iterations, p.seed);
  const int c = f.centers.rows;
  // Region memberships from the region's mean colour against the FCM centres.
  cv::Mat memb(n, c, CV_32F, cv::Scalar(0));
  std::vector<int> cls(n, 0);
  const double expo = 2.0 / (p.fcm_m - 1.0);
  for (int r = 0; r < n; ++r) {
    if (area[r] == 0) continue;
    const cv::Vec3d m = colour[r] / area[r];
    std::vector<double> d(c);
    for (int k = 0; k < c; ++k) {
      const float* v = f.centers.ptr<float>(k);
      d[k] = std::max(1e-6, cv::norm(m - cv::Vec3d(v[0], v[1], v[2])));
    }
    for (int k = 0; k < c; ++k) {
      double s = 0;
      for (int j = 0; j < c; ++j) s += std::pow(d[k] / d[j], expo);
      memb.at<float>(r, k) = static_cast<float>(1.0 / s);
    }
    cls[r] = static_cast<int>(std::min_element(d.begin(), d.end()) - d.begin());
  }
  // Adjacent regions of the same FCM class merge.
  const auto adj = adjacency(o.labels, n);
  UnionFind uf(n);
  for (int r = 0; r < n; ++r)
    for (int s : adj[r])
      if (cls[r] == cls[s]) uf.p[uf.find(s)] = uf.find(r);
  cv::Mat fine = o.labels.clone();
  const int k = compact(fine, uf);
  // Merged-region statistics: area and area-weighted membership.
  std::vector<double> ka(k, 0.0);
  cv::Mat km(k, c, CV_64F, cv::Scalar(0));
  {
    std::vector<int> id(n, -1);
    for (int y = 0; y < o.labels.rows; ++y)
      for (int x = 0; x < o.labels.cols; ++x) id[o.labels.at<int>(y, x)] = fine.at<int>(y, x);
    for (int r = 0; r < n; ++r) {
      if (id[r] < 0) continue;
      ka[id[r]] += area[r];
      for (int j = 0; j < c; ++j) km.at<double>(id[r], j) += area[r] * memb.at<float>(r, j);
    }
  }
  // Improved merge: the smallest region under the area threshold joins the neighbour whose
  // mean membership vector is closest (L1), until none is left.
  const double total = static_cast<double>(o.labels.total());
  auto kadj = adjacency(fine, k);
  UnionFind uf2(k);
  std::vector<bool> alive(k, true);
  for (;;) {
    int small = -1;
    for (int r = 0; r < k; ++r)
      if (alive[r] && ka[r] < p.small_region_frac * total && !kadj[r].empty() &&
          (small < 0 || ka[r] < ka[small]))
        small = r;
    if (small < 0) break;
    int best = -1;
    double bd = 1e18;
    for (int s : kadj[small]) {
      double d = 0;
      for (int j = 0; j < c; ++j)
        d += std::abs(km.at<double>(small, j) / ka[small] - km.at<double>(s, j) / ka[s]);
      if (d < bd) bd = d, best = s;
    }
    alive[small] = false;
    uf2.p[small] = best;
    ka[best] += ka[small];
    km.row(best) += km.row(small);
    for (int s : kadj[small]) {
      kadj[s].erase(small);
      if (s != best) {
        kadj[s].insert(best);
        kadj[best].insert(s);
      }
    }
    kadj[best].erase(best);
    kadj[small].clear();
  }
  cv::Mat coarse = fine.clone();
  compact(coarse, uf2);
  return {fine, coarse};
}

std::vector<cv::Rect> segmentBoxes(const cv::Mat& labels, bool pairs) {
  int n = 0;
  for (int y = 0; y < labels.rows; ++y)
    for (int x = 0; x < labels.cols; ++x) n = std::max(n, labels.at<int>(y, x) + 1);
  std::vector<cv::Rect> box(n);
  for (int y = 0; y < labels.rows; ++y)
    for (int x = 0; x < labels.cols; ++x) {
      cv::Rect& b = box[labels.at<int>(y, x)];
      b = b.area() == 0 ? cv::Rect(x, y, 1, 1) : (b | cv::Rect(x, y, 1, 1));
    }
  std::vector<cv::Rect> out = box;
  if (pairs) {
    const auto adj = adjacency(labels, n);
    for (int r = 0; r < n; ++r)
      for (int s : adj[r])
        if (s > r) out.push_back(box[r] | box[s]);
  }
  return out;
}

}  // namespace

void CcsParams::validate() const {
  require(work_long_side >= 32 && work_long_side <= 2048, "ccs.work_long_side",
          "must be in [32, 2048] px");
  require(l0_long_side >= 16 && l0_long_side <= work_long_side, "ccs.l0_long_side",
          "must be in [16, work_long_side] px");
  require(l0_lambda > 0, "ccs.l0_lambda", "must be > 0");
  require(l0_kappa > 1, "ccs.l0_kappa", "must be > 1");
  require(h_min >= 0 && h_min < 255, "ccs.h_min", "must be in [0, 255)");
  require(!fcm_clusters.empty(), "ccs.fcm_clusters", "needs at least one cluster count");
  for (int c : fcm_clusters) require(c >= 2 && c <= 64, "ccs.fcm_clusters", "each in [2, 64]");
  require(fcm_m > 1, "ccs.fcm_m", "must be > 1");
  require(fcm_iterations >= 1, "ccs.fcm_iterations", "must be >= 1");
  require(small_region_frac >= 0 && small_region_frac < 1, "ccs.small_region_frac",
          "must be in [0, 1)");
  for (double l : saliency_levels) require(l > 0 && l < 1, "ccs.saliency_levels", "each in (0, 1)");
}

cv::Mat centreSurroundSaliency(const cv::Mat& bgr) {
  cv::Mat f, lab;
  bgr.convertTo(f, CV_32F, 1.0 / 255.0);
  cv::cvtColor(f, lab, cv::COLOR_BGR2Lab);
  cv::Mat centre;
  cv::GaussianBlur(lab, centre, cv::Size(0, 0), 1.0);
  cv::Mat sal(bgr.size(), CV_32F, cv::Scalar(0));
  // Surrounds: the image averaged at 1/4, 1/8, 1/16 of its size, interpolated back (cheap
  // large-kernel blurs); saliency = Σ ‖centre − surround‖ in Lab.
  for (int div : {4, 8, 16}) {
    cv::Mat small, surround;
    const cv::Size s(std::max(1, bgr.cols / div), std::max(1, bgr.rows / div));
    cv::resize(lab, small, s, 0, 0, cv::INTER_AREA);
    cv::resize(small, surround, bgr.size(), 0, 0, cv::INTER_LINEAR);
    cv::Mat d = centre - surround, d2;
    cv::multiply(d, d, d2);
    std::vector<cv::Mat> ch;
    cv::split(d2, ch);
    cv::Mat m;
    cv::sqrt(ch[0] + ch[1] + ch[2], m);
    sal += m;
  }
  double mx = 0;
  cv::minMaxLoc(sal, nullptr, &mx);
  if (mx > 0) sal /= mx;
  return sal;
}

cv::Mat ccsSegment(const cv::Mat& bgr, const CcsParams& p, int clusters) {
  return fcmMerge(overSegment(bgr, p), clusters, p).second;
}

std::vector<ScoredBox> proposeCcs(const cv::Mat& bgr_in, const CcsParams& p) {
  std::vector<ScoredBox> out;
  if (bgr_in.empty() || bgr_in.cols < 2 || bgr_in.rows < 2) return out;
  // l0Smooth works in the Fourier domain: a side with a large prime factor (a 103-px side)
  // costs several times a 2·3·5-smooth one, so the working size is rounded up to one.
  const double s0 =
      std::min(1.0, static_cast<double>(p.work_long_side) / std::max(bgr_in.cols, bgr_in.rows));
  const cv::Size ws(cv::getOptimalDFTSize(std::max(2, cvRound(bgr_in.cols * s0))),
                    cv::getOptimalDFTSize(std::max(2, cvRound(bgr_in.rows * s0))));
  const double sx = static_cast<double>(ws.width) / bgr_in.cols,
               sy = static_cast<double>(ws.height) / bgr_in.rows;
  cv::Mat bgr;
  cv::resize(bgr_in, bgr, ws, 0, 0,
             ws.area() < bgr_in.size().area() ? cv::INTER_AREA : cv::INTER_LINEAR);
  const Oversegmentation o = overSegment(bgr, p);
  const int64 t0 = cv::getTickCount();
  std::vector<cv::Rect> cand;
  for (int c : p.fcm_clusters) {
    const auto [fine, coarse] = fcmMerge(o, c, p);
    for (const auto& r : segmentBoxes(fine, false)) cand.push_back(r);
    for (const auto& r : segmentBoxes(coarse, true)) cand.push_back(r);
  }
  log::debug("ccs", "fcm segmentations", {{"ms", std::to_string(msSince(t0))}});
  const cv::Mat sal = centreSurroundSaliency(bgr);
  for (double level : p.saliency_levels) {
    cv::Mat comp, stats, cent;
    const int n = cv::connectedComponentsWithStats(sal > level, comp, stats, cent, 8, CV_32S);
    for (int i = 1; i < n; ++i)
      cand.emplace_back(stats.at<int>(i, cv::CC_STAT_LEFT), stats.at<int>(i, cv::CC_STAT_TOP),
                        stats.at<int>(i, cv::CC_STAT_WIDTH), stats.at<int>(i, cv::CC_STAT_HEIGHT));
  }
  // Score: mean saliency inside minus mean saliency in the ring around (window grown by 1/4).
  cv::Mat I;
  cv::integral(sal, I, CV_64F);
  const cv::Rect img(0, 0, bgr.cols, bgr.rows);
  auto sum = [&](const cv::Rect& r) {
    return I.at<double>(r.y + r.height, r.x + r.width) - I.at<double>(r.y, r.x + r.width) -
           I.at<double>(r.y + r.height, r.x) + I.at<double>(r.y, r.x);
  };
  std::sort(cand.begin(), cand.end(), [](const cv::Rect& a, const cv::Rect& b) {
    return std::tie(a.x, a.y, a.width, a.height) < std::tie(b.x, b.y, b.width, b.height);
  });
  cand.erase(std::unique(cand.begin(), cand.end()), cand.end());
  for (const cv::Rect& r0 : cand) {
    const cv::Rect r = r0 & img;
    if (r.width < 2 || r.height < 2) continue;
    const int gx = std::max(1, r.width / 8), gy = std::max(1, r.height / 8);
    const cv::Rect outer = cv::Rect(r.x - gx, r.y - gy, r.width + 2 * gx, r.height + 2 * gy) & img;
    const double in = sum(r) / r.area();
    const double ring_area = outer.area() - r.area();
    const double ring = ring_area > 0 ? (sum(outer) - sum(r)) / ring_area : 0.0;
    const float score = static_cast<float>(in - ring);
    const cv::Rect back(cvRound(r.x / sx), cvRound(r.y / sy), cvRound(r.width / sx),
                        cvRound(r.height / sy));
    out.push_back({back & cv::Rect(0, 0, bgr_in.cols, bgr_in.rows), score});
  }
  return out;
}

}  // namespace sketchnav::landmarks
