// Baseline proposal methods (baselines.h).
#include <opencv2/imgproc.hpp>
#include <opencv2/saliency.hpp>
#include <opencv2/ximgproc.hpp>
#include <opencv2/ximgproc/segmentation.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include <fcntl.h>
#include <unistd.h>

#include "sketchnav/core/error.h"
#include "sketchnav/landmarks/baselines.h"

namespace sketchnav::landmarks {
namespace {

class StdoutSilencer {
 public:
  StdoutSilencer() {
    std::cout.flush();
    std::fflush(stdout);
    saved_ = ::dup(STDOUT_FILENO);
    const int null = ::open("/dev/null", O_WRONLY);
    if (saved_ >= 0 && null >= 0) ::dup2(null, STDOUT_FILENO);
    if (null >= 0) ::close(null);
  }
  ~StdoutSilencer() {
    std::cout.flush();
    std::fflush(stdout);
    if (saved_ >= 0) {
      ::dup2(saved_, STDOUT_FILENO);
      ::close(saved_);
    }
  }
  StdoutSilencer(const StdoutSilencer&) = delete;
  StdoutSilencer& operator=(const StdoutSilencer&) = delete;

 private:
  int saved_ = -1;
};

class Bing : public ProposalMethod {
 public:
  Bing(const std::string& model_dir, const std::string& scratch_dir) {
    if (!std::filesystem::exists(model_dir + "/ObjNessB2W8MAXBGR.idx.yml.gz"))
      throw InputError(model_dir + ": BING model files (ObjNessB2W8*.yml.gz) not found");
    std::filesystem::create_directories(scratch_dir);
    bing_ = cv::makePtr<cv::saliency::ObjectnessBING>();
    bing_->setTrainingPath(model_dir);
    bing_->setBBResDir(scratch_dir);
  }
  std::string name() const override { return "bing"; }
  std::vector<cv::Rect> propose(const cv::Mat& bgr, int max_windows) override {
    std::vector<cv::Vec4i> boxes;
    {
      // BING prints timing lines on stdout, which would corrupt `--json` output: stdout is
      // pointed at /dev/null for the call.
      const StdoutSilencer quiet;
      bing_->computeSaliency(bgr, boxes);
    }
    std::vector<cv::Rect> out;
    const cv::Rect img(0, 0, bgr.cols, bgr.rows);
    // BING's boxes are ranked by objectness, corners 1-based inclusive (minX,minY,maxX,maxY).
    for (const auto& b : boxes) {
      if (static_cast<int>(out.size()) >= max_windows) break;
      const cv::Rect r = cv::Rect(cv::Point(b[0] - 1, b[1] - 1), cv::Point(b[2], b[3])) & img;
      if (r.area() > 0) out.push_back(r);
    }
    return out;
  }

 private:
  cv::Ptr<cv::saliency::ObjectnessBING> bing_;
};

// One Selective Search run per image shared by the orderings: the benchmark passes the same
// image to every method in turn, so the variants are compared on identical boxes and SS's
// ~1–2 s per image is paid once. Keyed by the pixel buffer's address, size and a checksum.
struct SsCache {
  const void* data = nullptr;
  cv::Size size;
  double checksum = 0;
  std::vector<cv::Rect> rects;
};

std::vector<cv::Rect> runSelectiveSearch(const cv::Mat& bgr, SsCache& cache) {
  const double sum = cv::sum(bgr)[0] + 3.0 * cv::sum(bgr)[1] + 7.0 * cv::sum(bgr)[2];
  if (cache.data == bgr.data && cache.size == bgr.size() && cache.checksum == sum)
    return cache.rects;
  auto ss = cv::ximgproc::segmentation::createSelectiveSearchSegmentation();
  ss->setBaseImage(bgr);
  ss->switchToSelectiveSearchFast();
  std::vector<cv::Rect> rects;
  ss->process(rects);
  cache.data = bgr.data;
  cache.size = bgr.size();
  cache.checksum = sum;
  cache.rects = rects;
  return rects;
}

class SelectiveSearchFast : public ProposalMethod {
 public:
  SelectiveSearchFast(SsOrder order, std::shared_ptr<SsCache> cache, std::string name)
      : order_(order), cache_(std::move(cache)), name_(std::move(name)) {}
  std::string name() const override { return name_; }
  std::vector<cv::Rect> propose(const cv::Mat& bgr, int max_windows) override {
    std::vector<cv::Rect> rects = orderSelectiveSearch(runSelectiveSearch(bgr, *cache_), order_);
    if (static_cast<int>(rects.size()) > max_windows) rects.resize(max_windows);
    return rects;
  }

 private:
  SsOrder order_;
  std::shared_ptr<SsCache> cache_;
  std::string name_;
};

class EdgeBoxesSobel : public ProposalMethod {
 public:
  std::string name() const override { return "edgeboxes"; }
  std::vector<cv::Rect> propose(const cv::Mat& bgr, int max_windows) override {
    cv::Mat mag, orient;
    sobelEdges(bgr, mag, orient);
    auto eb = cv::ximgproc::createEdgeBoxes();
    eb->setMaxBoxes(max_windows);
    std::vector<cv::Rect> boxes;
    std::vector<float> scores;
    eb->getBoundingBoxes(mag, orient, boxes, scores);
    if (static_cast<int>(boxes.size()) > max_windows) boxes.resize(max_windows);
    return boxes;
  }
};

class SlidingWindow : public ProposalMethod {
 public:
  std::string name() const override { return "sliding-window"; }
  std::vector<cv::Rect> propose(const cv::Mat& bgr, int max_windows) override {
    return slidingWindowGrid(bgr.size(), max_windows);
  }
};

}  // namespace

std::vector<cv::Rect> orderSelectiveSearch(std::vector<cv::Rect> rects, SsOrder order) {
  switch (order) {
    case SsOrder::AsReturned:
      break;
    case SsOrder::Reversed:
      // OpenCV sorts its regions by rank = level × U(0,1) *ascending*, where the level is 1 for
      // the initial Felzenszwalb segments and grows with each merge: as returned, the list
      // starts with the smallest fragments. Uijlings et al. rank the other way (the regions
      // merged last, i.e. whole objects, first), which is what reversing restores.
      std::reverse(rects.begin(), rects.end());
      break;
    case SsOrder::Random: {
      // Hosang et al.'s "random" control: a uniform shuffle, seeded so runs repeat.
      cv::RNG rng(0x5e1ec7);
      for (int i = static_cast<int>(rects.size()) - 1; i > 0; --i)
        std::swap(rects[i], rects[rng.uniform(0, i + 1)]);
      break;
    }
  }
  return rects;
}

void sobelEdges(const cv::Mat& bgr, cv::Mat& magnitude, cv::Mat& orientation) {
  cv::Mat gray, f, gx, gy, mag, orient;
  if (bgr.channels() == 3)
    cv::cvtColor(bgr, gray, cv::COLOR_BGR2GRAY);
  else
    gray = bgr;
  gray.convertTo(f, CV_32F, 1.0 / 255.0);
  cv::GaussianBlur(f, f, cv::Size(5, 5), 1.0);
  cv::Sobel(f, gx, CV_32F, 1, 0, 3);
  cv::Sobel(f, gy, CV_32F, 0, 1, 3);
  cv::magnitude(gx, gy, mag);
  double mx = 0;
  cv::minMaxLoc(mag, nullptr, &mx);
  if (mx > 0) mag /= mx;
  // Gradient direction in [0, 2π) folded to [0, π): EdgeBoxes wants the edge orientation mod π.
  cv::phase(gx, gy, orient);
  const float pi = static_cast<float>(CV_PI);
  orient.forEach<float>([pi](float& a, const int*) {
    if (a >= pi) a -= pi;
    if (a >= pi) a = 0.f;
  });
  // Thin the edges (non-maximum suppression across the edge, as structured edges are before
  // EdgeBoxes) and drop the weakest responses: dense Sobel maps make EdgeBoxes both slow and
  // blind to object contours.
  cv::Mat thin(mag.size(), CV_32F, cv::Scalar(0));
  for (int y = 1; y + 1 < mag.rows; ++y) {
    const float* m0 = mag.ptr<float>(y);
    const float* o0 = orient.ptr<float>(y);
    float* t0 = thin.ptr<float>(y);
    for (int x = 1; x + 1 < mag.cols; ++x) {
      const float m = m0[x];
      if (m < 0.05f) continue;
      const float a = o0[x];
      const int dx = static_cast<int>(std::lround(std::cos(a))),
                dy = static_cast<int>(std::lround(std::sin(a)));
      if (m >= mag.at<float>(y + dy, x + dx) && m > mag.at<float>(y - dy, x - dx)) t0[x] = m;
    }
  }
  magnitude = thin;
  orientation = orient;
}

std::vector<cv::Rect> slidingWindowGrid(const cv::Size& size, int max_windows, int scales,
                                        bool dense) {
  std::vector<cv::Rect> out;
  if (size.width <= 0 || size.height <= 0 || max_windows <= 0) return out;
  static const std::vector<std::pair<double, double>> plain = {{1.0, 1.0}, {1.0, 0.5}, {0.5, 1.0}};
  static const std::vector<std::pair<double, double>> rich = {
      {1.0, 1.0}, {1.0, 0.7}, {0.7, 1.0}, {1.0, 0.5}, {0.5, 1.0}};
  const auto& aspects = dense ? rich : plain;  // (w, h) factors
  const double steps = dense ? 3.0 : 2.0;      // positions per window side
  double s = 1.0;
  for (int k = 0; k < scales && static_cast<int>(out.size()) < max_windows; ++k, s *= 0.8) {
    for (const auto& a : aspects) {
      const double fw = s * a.first, fh = s * a.second;
      const int w = std::max(1, static_cast<int>(std::lround(fw * size.width)));
      const int h = std::max(1, static_cast<int>(std::lround(fh * size.height)));
      // Positions at most 1/steps of a window apart, first and last flush with the border.
      const int nx = static_cast<int>(std::ceil(steps * (1.0 - fw) / fw - 1e-9)) + 1;
      const int ny = static_cast<int>(std::ceil(steps * (1.0 - fh) / fh - 1e-9)) + 1;
      for (int iy = 0; iy < ny; ++iy)
        for (int ix = 0; ix < nx; ++ix) {
          const int x = nx == 1
                            ? (size.width - w) / 2
                            : static_cast<int>(std::lround(ix * double(size.width - w) / (nx - 1)));
          const int y =
              ny == 1 ? (size.height - h) / 2
                      : static_cast<int>(std::lround(iy * double(size.height - h) / (ny - 1)));
          out.emplace_back(x, y, w, h);
          if (static_cast<int>(out.size()) >= max_windows) return out;
        }
    }
  }
  return out;
}

std::unique_ptr<ProposalMethod> makeBing(const std::string& model_dir,
                                         const std::string& scratch_dir) {
  return std::make_unique<Bing>(model_dir, scratch_dir);
}
std::unique_ptr<ProposalMethod> makeSelectiveSearchFast(SsOrder order,
                                                        std::shared_ptr<void> shared_run) {
  std::shared_ptr<SsCache> cache =
      shared_run ? std::static_pointer_cast<SsCache>(shared_run) : std::make_shared<SsCache>();
  const char* name = order == SsOrder::Reversed ? "selective-search"
                     : order == SsOrder::Random ? "selective-search-random"
                                                : "selective-search-as-returned";
  return std::make_unique<SelectiveSearchFast>(order, cache, name);
}
std::shared_ptr<void> makeSelectiveSearchRun() {
  return std::make_shared<SsCache>();
}
std::unique_ptr<ProposalMethod> makeEdgeBoxesSobel() {
  return std::make_unique<EdgeBoxesSobel>();
}
std::unique_ptr<ProposalMethod> makeSlidingWindow() {
  return std::make_unique<SlidingWindow>();
}

}  // namespace sketchnav::landmarks
