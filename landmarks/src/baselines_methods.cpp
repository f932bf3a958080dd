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

class SelectiveSearchFast : public ProposalMethod {
 public:
  std::string name() const override { return "selective-search"; }
  std::vector<cv::Rect> propose(const cv::Mat& bgr, int max_windows) override {
    auto ss = cv::ximgproc::segmentation::createSelectiveSearchSegmentation();
    ss->setBaseImage(bgr);
    ss->switchToSelectiveSearchFast();
    std::vector<cv::Rect> rects;
    ss->process(rects);
    if (static_cast<int>(rects.size()) > max_windows) rects.resize(max_windows);
    return rects;
  }
};

class EdgeBoxesSobel : public ProposalMethod {
 public:
  std::string name() const override { return "edgeboxes"; }
  std::vector<cv::Rect> propose(const cv::Mat& bgr, int max_windows) override {
    cv::Mat gray, f, gx, gy, mag, orient;
    cv::cvtColor(bgr, gray, cv::COLOR_BGR2GRAY);
    gray.convertTo(f, CV_32F, 1.0 / 255.0);
    cv::GaussianBlur(f, f, cv::Size(5, 5), 1.0);
    cv::Sobel(f, gx, CV_32F, 1, 0, 3);
    cv::Sobel(f, gy, CV_32F, 0, 1, 3);
    cv::magnitude(gx, gy, mag);
    double mx = 0;
    cv::minMaxLoc(mag, nullptr, &mx);
    if (mx > 0) mag /= mx;
    // Edge orientation in [0, π): the gradient direction folded, as EdgeBoxes expects.
    orient.create(f.size(), CV_32F);
    for (int y = 0; y < f.rows; ++y)
      for (int x = 0; x < f.cols; ++x) {
        float a = std::atan2(gy.at<float>(y, x), gx.at<float>(y, x));
        if (a < 0) a += static_cast<float>(CV_PI);
        orient.at<float>(y, x) = a;
      }
    // Thin the edges (non-maximum suppression across the edge, as structured edges are
    // before EdgeBoxes) and drop the weakest responses: dense Sobel maps make EdgeBoxes both
    // slow and blind to object contours.
    cv::Mat thin(mag.size(), CV_32F, cv::Scalar(0));
    for (int y = 1; y + 1 < mag.rows; ++y)
      for (int x = 1; x + 1 < mag.cols; ++x) {
        const float m = mag.at<float>(y, x);
        if (m < 0.05f) continue;
        const float a = orient.at<float>(y, x);
        const int dx = static_cast<int>(std::lround(std::cos(a))),
                  dy = static_cast<int>(std::lround(std::sin(a)));
        if (m >= mag.at<float>(y + dy, x + dx) && m >= mag.at<float>(y - dy, x - dx))
          thin.at<float>(y, x) = m;
      }
    mag = thin;
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
std::unique_ptr<ProposalMethod> makeSelectiveSearchFast() {
  return std::make_unique<SelectiveSearchFast>();
}
std::unique_ptr<ProposalMethod> makeEdgeBoxesSobel() {
  return std::make_unique<EdgeBoxesSobel>();
}
std::unique_ptr<ProposalMethod> makeSlidingWindow() {
  return std::make_unique<SlidingWindow>();
}

}  // namespace sketchnav::landmarks
