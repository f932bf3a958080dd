#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

#include "appearance_internal.h"

namespace sketchnav::landmarks::detail {

namespace {

// Normalised cross-correlation of two CV_32F images over the non-zero pixels of `mask`.
double ncc(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask) {
  const cv::Scalar ma = cv::mean(a, mask), mb = cv::mean(b, mask);
  double ab = 0, aa = 0, bb = 0;
  for (int y = 0; y < a.rows; ++y) {
    const float* pa = a.ptr<float>(y);
    const float* pb = b.ptr<float>(y);
    const uchar* pm = mask.ptr<uchar>(y);
    for (int x = 0; x < a.cols; ++x) {
      if (!pm[x]) continue;
      const double da = pa[x] - ma[0], db = pb[x] - mb[0];
      ab += da * db;
      aa += da * da;
      bb += db * db;
    }
  }
  // The small constant keeps a flat cell (no texture, one colour) near 0 instead of noise.
  return ab / (std::sqrt(aa * bb) + 1e-3);
}

// The square-resampled region of a BGR thumbnail, as three CV_32F L*, a*, b* planes.
std::vector<cv::Mat> labGrid(const cv::Mat& bgr, const cv::Rect& box) {
  cv::Mat small, lab;
  cv::resize(bgr(box), small, cv::Size(kAppearanceGrid, kAppearanceGrid), 0, 0, cv::INTER_AREA);
  cv::cvtColor(small, lab, cv::COLOR_BGR2Lab);
  std::vector<cv::Mat> planes;
  cv::split(lab, planes);
  for (auto& p : planes) p.convertTo(p, CV_32F);
  return planes;
}

}  // namespace

std::vector<double> appearanceSimilarities(const LandmarkModel& model, const FrameFeatures& frame,
                                           const std::vector<const MatchResult*>& matches,
                                           size_t region_matches) {
  std::vector<double> out(matches.size(), std::numeric_limits<double>::quiet_NaN());
  const cv::Mat& ft = frame.colour_thumbnail;
  const cv::Size fs = frame.features.image_size;
  region_matches = std::min(region_matches, matches.size());
  if (ft.empty() || ft.type() != CV_8UC3 || fs.area() <= 0 || region_matches == 0) return out;
  const double sx = static_cast<double>(ft.cols) / fs.width;
  const double sy = static_cast<double>(ft.rows) / fs.height;
  const cv::Mat frame_scale = (cv::Mat_<double>(3, 3) << sx, 0, 0, 0, sy, 0, 0, 0, 1);

  // Each photo's thumbnail warped into the frame thumbnail, and where it is valid.
  std::vector<cv::Mat> warped(matches.size()), valid(matches.size());
  for (size_t i = 0; i < matches.size(); ++i) {
    const MatchResult* m = matches[i];
    if (!m || !m->matched || m->H.empty() || m->database_photo < 0 ||
        m->database_photo >= static_cast<int>(model.photos().size()) || m->x_t.size() < 3) {
      if (i < region_matches) return out;
      continue;
    }
    const DatabasePhoto& ph = model.photos()[m->database_photo];
    if (ph.thumbnail.empty() || ph.size.area() <= 0) {
      if (i < region_matches) return out;
      continue;
    }
    // Thumbnail pixels -> photo pixels -> frame pixels -> frame thumbnail pixels.
    const cv::Mat photo_scale =
        (cv::Mat_<double>(3, 3) << static_cast<double>(ph.size.width) / ph.thumbnail.cols, 0, 0, 0,
         static_cast<double>(ph.size.height) / ph.thumbnail.rows, 0, 0, 0, 1);
    cv::Mat H;
    m->H.convertTo(H, CV_64F);
    const cv::Mat Ht = frame_scale * H * photo_scale;
    cv::warpPerspective(ph.thumbnail, warped[i], Ht, ft.size(), cv::INTER_LINEAR,
                        cv::BORDER_CONSTANT);
    cv::warpPerspective(cv::Mat(ph.thumbnail.size(), CV_8U, cv::Scalar(255)), valid[i], Ht,
                        ft.size(), cv::INTER_NEAREST, cv::BORDER_CONSTANT, cv::Scalar(0));
  }
  // The region: the union of the region matches' inlier hulls where all of them are valid.
  cv::Mat common(ft.size(), CV_8U, cv::Scalar(255));
  cv::Mat hulls(ft.size(), CV_8U, cv::Scalar(0));
  for (size_t i = 0; i < region_matches; ++i) {
    cv::bitwise_and(common, valid[i], common);
    std::vector<cv::Point> pts, hull;
    pts.reserve(matches[i]->x_t.size());
    for (const auto& p : matches[i]->x_t)
      pts.emplace_back(static_cast<int>(std::lround(p.x * sx)),
                       static_cast<int>(std::lround(p.y * sy)));
    cv::convexHull(pts, hull);
    cv::fillConvexPoly(hulls, hull, cv::Scalar(255));
  }
  cv::bitwise_and(common, hulls, common);

  constexpr int cell = kAppearanceGrid / kAppearanceCells;
  for (size_t i = 0; i < matches.size(); ++i) {
    if (warped[i].empty()) continue;
    cv::Mat region;
    cv::bitwise_and(common, valid[i], region);
    if (cv::countNonZero(region) < 16) {
      if (i < region_matches) return std::vector<double>(matches.size(), out[0]);  // all NaN
      continue;
    }
    const cv::Rect box = cv::boundingRect(region);
    // Grid pixels fully inside the region.
    cv::Mat mask_f;
    region(box).convertTo(mask_f, CV_32F, 1.0 / 255);
    cv::resize(mask_f, mask_f, cv::Size(kAppearanceGrid, kAppearanceGrid), 0, 0, cv::INTER_AREA);
    const cv::Mat mask = mask_f > 0.99f;
    if (cv::countNonZero(mask) < 30) {
      if (i < region_matches) return std::vector<double>(matches.size(), out[0]);
      continue;
    }
    const std::vector<cv::Mat> f = labGrid(ft, box), w = labGrid(warped[i], box);
    double sum = 0;
    int n = 0;
    for (int cy = 0; cy < kAppearanceCells; ++cy)
      for (int cx = 0; cx < kAppearanceCells; ++cx) {
        const cv::Rect r(cx * cell, cy * cell, cell, cell);
        const cv::Mat mk = mask(r);
        if (cv::countNonZero(mk) < 8) continue;  // too little of the region in this cell
        double s = 0;
        for (int c = 0; c < 3; ++c) s += ncc(f[c](r), w[c](r), mk);
        sum += s / 3;
        ++n;
      }
    if (n > 0) out[i] = sum / n;
  }
  return out;
}

}  // namespace sketchnav::landmarks::detail
