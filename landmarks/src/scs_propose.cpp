// SCS proposals (scs.h): SLIC → DBSCAN → graph segmentation → hierarchical grouping → SS.
#include <opencv2/imgproc.hpp>
#include <opencv2/ximgproc.hpp>

#include <algorithm>
#include <map>
#include <numeric>
#include <set>

#include "sketchnav/core/config.h"
#include "sketchnav/landmarks/baselines.h"
#include "sketchnav/landmarks/scs.h"

namespace sketchnav::landmarks {
namespace {

constexpr int kBins = 8;          // per Lab channel
constexpr int kHist = 3 * kBins;  // concatenated L, a, b histograms

struct Region {
  double area = 0;
  cv::Vec3d lab_sum{0, 0, 0};
  std::array<float, kHist> hist{};  // unnormalised counts
  cv::Rect box;
  std::set<int> nb;
  bool alive = true;
  cv::Vec3d mean() const { return area > 0 ? lab_sum / area : cv::Vec3d(0, 0, 0); }
};

Region mergeRegions(const Region& a, const Region& b) {
  Region r;
  r.area = a.area + b.area;
  r.lab_sum = a.lab_sum + b.lab_sum;
  for (int i = 0; i < kHist; ++i) r.hist[i] = a.hist[i] + b.hist[i];
  r.box = a.box | b.box;
  return r;
}

double histIntersection(const Region& a, const Region& b) {
  double s = 0;
  for (int i = 0; i < kHist; ++i) s += std::min(a.hist[i] / a.area, b.hist[i] / b.area);
  return s / 3.0;  // three channel histograms, each summing to 1
}

// Selective-search style similarity: colour + small-first + fill, each in [0, 1].
double similarity(const Region& a, const Region& b, double img_area) {
  const double size = 1.0 - (a.area + b.area) / img_area;
  const double fill = 1.0 - ((a.box | b.box).area() - a.area - b.area) / img_area;
  return histIntersection(a, b) + size + fill;
}

// Hierarchical grouping from `init`; appends the box of every region that ever exists.
void hierarchicalGrouping(std::vector<Region> regs, double img_area, std::vector<cv::Rect>& out) {
  struct Pair {
    int a, b;
    double s;
  };
  std::vector<Pair> pairs;
  for (int i = 0; i < static_cast<int>(regs.size()); ++i) {
    out.push_back(regs[i].box);
    for (int j : regs[i].nb)
      if (j > i) pairs.push_back({i, j, similarity(regs[i], regs[j], img_area)});
  }
  while (!pairs.empty()) {
    const auto best = std::max_element(pairs.begin(), pairs.end(),
                                       [](const Pair& x, const Pair& y) { return x.s < y.s; });
    const int a = best->a, b = best->b;
    Region m = mergeRegions(regs[a], regs[b]);
    const int id = static_cast<int>(regs.size());
    regs[a].alive = regs[b].alive = false;
    for (int k : regs[a].nb)
      if (k != b) m.nb.insert(k);
    for (int k : regs[b].nb)
      if (k != a) m.nb.insert(k);
    pairs.erase(
        std::remove_if(pairs.begin(), pairs.end(),
                       [&](const Pair& p) { return p.a == a || p.b == a || p.a == b || p.b == b; }),
        pairs.end());
    for (int k : m.nb) {
      regs[k].nb.erase(a);
      regs[k].nb.erase(b);
      regs[k].nb.insert(id);
    }
    out.push_back(m.box);
    regs.push_back(std::move(m));
    for (int k : regs[id].nb) pairs.push_back({k, id, similarity(regs[k], regs[id], img_area)});
  }
}

bool rectLess(const cv::Rect& a, const cv::Rect& b) {
  return std::tie(a.x, a.y, a.width, a.height) < std::tie(b.x, b.y, b.width, b.height);
}

struct UnionFind {
  std::vector<int> p;
  explicit UnionFind(int n) : p(n) { std::iota(p.begin(), p.end(), 0); }
  int find(int x) {
    while (p[x] != x) x = p[x] = p[p[x]];
    return x;
  }
};

}  // namespace

void ScsParams::validate() const {
  require(slic_region_size >= 3, "scs.slic_region_size", "must be >= 3 px");
  require(slic_iterations >= 1, "scs.slic_iterations", "must be >= 1");
  require(dbscan_eps >= 0, "scs.dbscan_eps", "must be >= 0");
  require(dbscan_min_pts >= 1, "scs.dbscan_min_pts", "must be >= 1");
  require(dbscan_pos_weight >= 0, "scs.dbscan_pos_weight", "must be >= 0");
  require(!graph_k.empty(), "scs.graph_k", "needs at least one threshold");
  for (double k : graph_k) require(k > 0, "scs.graph_k", "thresholds must be > 0");
  require(min_area_frac >= 0 && min_area_frac < 1, "scs.min_area_frac", "must be in [0, 1)");
  require(max_area_frac > min_area_frac && max_area_frac <= 1, "scs.max_area_frac",
          "must be in (min_area_frac, 1]");
  require(grid_scales >= 1 && grid_scales <= 30, "scs.grid_scales", "must be in [1, 30]");
}

cv::Mat slicLabels(const cv::Mat& bgr, const ScsParams& p) {
  cv::Mat lab, labels;
  const int rs = p.slic_region_size;
  if (bgr.cols < 2 * rs || bgr.rows < 2 * rs) {
    // OpenCV's SLIC crashes on images smaller than two superpixels: use square blocks.
    labels.create(bgr.size(), CV_32S);
    const int nx = (bgr.cols + rs - 1) / rs;
    for (int y = 0; y < bgr.rows; ++y)
      for (int x = 0; x < bgr.cols; ++x) labels.at<int>(y, x) = (y / rs) * nx + x / rs;
    return labels;
  }
  cv::cvtColor(bgr, lab, cv::COLOR_BGR2Lab);
  auto slic = cv::ximgproc::createSuperpixelSLIC(lab, cv::ximgproc::SLICO, p.slic_region_size);
  slic->iterate(p.slic_iterations);
  slic->enforceLabelConnectivity(25);
  slic->getLabels(labels);
  return labels;
}

std::vector<ScoredBox> proposeScs(const cv::Mat& bgr, const cv::Mat& labels, const ScsParams& p,
                                  const StraddlingScorer& scorer) {
  std::vector<ScoredBox> out;
  if (bgr.empty()) return out;
  cv::Mat lab;
  cv::cvtColor(bgr, lab, cv::COLOR_BGR2Lab);
  int n = 0;
  for (int y = 0; y < labels.rows; ++y)
    for (int x = 0; x < labels.cols; ++x) n = std::max(n, labels.at<int>(y, x) + 1);
  // Per-superpixel statistics and adjacency.
  std::vector<Region> sp(n);
  std::vector<cv::Vec2d> centroid(n, cv::Vec2d(0, 0));
  std::vector<std::set<int>> adj(n);
  for (int y = 0; y < labels.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    const cv::Vec3b* c = lab.ptr<cv::Vec3b>(y);
    for (int x = 0; x < labels.cols; ++x) {
      Region& r = sp[l[x]];
      if (r.area == 0)
        r.box = cv::Rect(x, y, 1, 1);
      else
        r.box |= cv::Rect(x, y, 1, 1);
      r.area += 1;
      r.lab_sum += cv::Vec3d(c[x][0], c[x][1], c[x][2]);
      r.hist[c[x][0] * kBins / 256] += 1;
      r.hist[kBins + c[x][1] * kBins / 256] += 1;
      r.hist[2 * kBins + c[x][2] * kBins / 256] += 1;
      centroid[l[x]] += cv::Vec2d(x, y);
      if (x + 1 < labels.cols && l[x + 1] != l[x]) {
        adj[l[x]].insert(l[x + 1]);
        adj[l[x + 1]].insert(l[x]);
      }
      if (y + 1 < labels.rows) {
        const int d = labels.at<int>(y + 1, x);
        if (d != l[x]) {
          adj[l[x]].insert(d);
          adj[d].insert(l[x]);
        }
      }
    }
  }
  // 1. DBSCAN over superpixels (Lab mean + weighted centroid), adjacency-restricted.
  cv::Mat feat(n, 5, CV_32F, cv::Scalar(0));
  std::vector<std::vector<int>> adjv(n);
  for (int i = 0; i < n; ++i) {
    adjv[i].assign(adj[i].begin(), adj[i].end());
    if (sp[i].area == 0) continue;
    const cv::Vec3d m = sp[i].mean();
    const cv::Vec2d c = centroid[i] / sp[i].area;
    float* f = feat.ptr<float>(i);
    f[0] = static_cast<float>(m[0] * 100.0 / 255.0);  // L back to 0..100
    f[1] = static_cast<float>(m[1] - 128.0);
    f[2] = static_cast<float>(m[2] - 128.0);
    f[3] = static_cast<float>(c[0] * p.dbscan_pos_weight);
    f[4] = static_cast<float>(c[1] * p.dbscan_pos_weight);
  }
  const std::vector<int> cl = dbscan(feat, adjv, p.dbscan_eps, p.dbscan_min_pts);
  const int nc = cl.empty() ? 0 : *std::max_element(cl.begin(), cl.end()) + 1;
  std::vector<Region> clusters(nc);
  for (int i = 0; i < n; ++i) {
    if (sp[i].area == 0) continue;
    Region& c = clusters[cl[i]];
    c.box = c.area == 0 ? sp[i].box : (c.box | sp[i].box);
    c.area += sp[i].area;
    c.lab_sum += sp[i].lab_sum;
    for (int k = 0; k < kHist; ++k) c.hist[k] += sp[i].hist[k];
  }
  for (int i = 0; i < n; ++i)
    for (int j : adj[i])
      if (cl[i] != cl[j]) clusters[cl[i]].nb.insert(cl[j]);

  const double img_area = static_cast<double>(bgr.rows) * bgr.cols;
  std::vector<cv::Rect> cand;
  // 2. Graph-based segmentation of the cluster graph (FH criterion), several granularities;
  // 3. hierarchical grouping from each.
  struct Edge {
    int a, b;
    double w;
  };
  std::vector<Edge> edges;
  for (int i = 0; i < nc; ++i)
    for (int j : clusters[i].nb)
      if (j > i) edges.push_back({i, j, cv::norm(clusters[i].mean() - clusters[j].mean())});
  std::sort(edges.begin(), edges.end(), [](const Edge& x, const Edge& y) { return x.w < y.w; });
  const double sp_area = static_cast<double>(p.slic_region_size) * p.slic_region_size;
  for (double k : p.graph_k) {
    UnionFind uf(nc);
    std::vector<double> internal(nc, 0.0), size(nc);
    for (int i = 0; i < nc; ++i) size[i] = std::max(1.0, clusters[i].area / sp_area);
    for (const Edge& e : edges) {
      const int a = uf.find(e.a), b = uf.find(e.b);
      if (a == b) continue;
      if (e.w <= std::min(internal[a] + k / size[a], internal[b] + k / size[b])) {
        uf.p[b] = a;
        size[a] += size[b];
        internal[a] = std::max({internal[a], internal[b], e.w});
      }
    }
    std::map<int, int> root_id;
    std::vector<Region> regs;
    std::vector<int> of(nc);
    for (int i = 0; i < nc; ++i) {
      const int r = uf.find(i);
      auto it = root_id.find(r);
      if (it == root_id.end()) {
        it = root_id.emplace(r, static_cast<int>(regs.size())).first;
        regs.push_back(clusters[i]);
        regs.back().nb.clear();
      } else {
        regs[it->second] = mergeRegions(regs[it->second], clusters[i]);
      }
      of[i] = it->second;
    }
    for (int i = 0; i < nc; ++i)
      for (int j : clusters[i].nb)
        if (of[i] != of[j]) regs[of[i]].nb.insert(of[j]);
    hierarchicalGrouping(std::move(regs), img_area, cand);
  }
  for (const Region& c : clusters) cand.push_back(c.box);
  std::vector<cv::Rect> grid;
  if (p.add_grid) {
    grid = slidingWindowGrid(bgr.size(), 100000, p.grid_scales, p.grid_dense);
    std::sort(grid.begin(), grid.end(), rectLess);
  }
  // Screen by area, drop exact duplicates, score by straddling.
  std::sort(cand.begin(), cand.end(), rectLess);
  cand.erase(std::unique(cand.begin(), cand.end()), cand.end());
  auto add = [&](const cv::Rect& r, double penalty) {
    const double f = r.area() / img_area;
    if (f < p.min_area_frac || f > p.max_area_frac) return;
    out.push_back({r, static_cast<float>(scorer.score(r) - penalty)});
  };
  for (const cv::Rect& r : cand) add(r, 0.0);
  for (const cv::Rect& r : grid)
    if (!std::binary_search(cand.begin(), cand.end(), r, rectLess)) add(r, p.grid_penalty);
  return out;
}

}  // namespace sketchnav::landmarks
