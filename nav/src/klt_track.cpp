#include "sketchnav/nav/klt_track.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include <cmath>

#include "sketchnav/core/error.h"

namespace sketchnav::nav {

void TrackParams::validate() const {
  require(redetect_frames >= 1, "nav.perception.track.redetect_frames", "must be >= 1");
  require(max_unconfirmed_frames >= redetect_frames, "nav.perception.track.max_unconfirmed_frames",
          "must be >= redetect_frames");
  require(min_points >= 4, "nav.perception.track.min_points", "must be >= 4 (a homography)");
  require(min_inlier_share > 0 && min_inlier_share <= 1, "nav.perception.track.min_inlier_share",
          "must be in (0, 1]");
  require(fb_max_px > 0, "nav.perception.track.fb_max_px", "must be > 0 px");
  require(ransac_px > 0, "nav.perception.track.ransac_px", "must be > 0 px");
  require(window_px >= 5 && window_px % 2 == 1, "nav.perception.track.window_px",
          "must be odd and >= 5 px");
  require(pyramid_levels >= 0 && pyramid_levels <= 6, "nav.perception.track.pyramid_levels",
          "must be in [0, 6]");
  require(max_area_change > 1, "nav.perception.track.max_area_change", "must be > 1");
}

namespace {
// Area [px^2] of the database photo's outline through H (the tracked quadrilateral); 0 when it
// does not project to a convex quad in front of the camera.
double quadArea(const cv::Mat& H, cv::Size photo) {
  if (H.empty()) return 0;
  const std::vector<cv::Point2f> c = {
      {0, 0},
      {static_cast<float>(photo.width), 0},
      {static_cast<float>(photo.width), static_cast<float>(photo.height)},
      {0, static_cast<float>(photo.height)}};
  for (const auto& p : c) {
    const double w = H.at<double>(2, 0) * p.x + H.at<double>(2, 1) * p.y + H.at<double>(2, 2);
    if (!(w > 1e-9)) return 0;  // a corner behind the camera / at infinity
  }
  std::vector<cv::Point2f> q;
  cv::perspectiveTransform(c, q, H);
  if (!cv::isContourConvex(q)) return 0;
  return std::abs(cv::contourArea(q));
}
}  // namespace

KltTrack::KltTrack(TrackParams p) : p_(p) {
  p_.validate();
}

bool KltTrack::start(const cv::Mat& grey, const landmarks::MatchResult& m) {
  active_ = false;
  if (grey.empty() || grey.type() != CV_8UC1 || m.H.empty() ||
      static_cast<int>(m.x_t.size()) < p_.min_points || m.x_t.size() != m.x_d.size())
    return false;
  prev_ = grey;  // frames are not written after they are handed over (hw::Frame)
  pts_ = m.x_t;
  db_ = m.x_d;
  match_ = m;
  age_ = 0;
  active_ = true;
  return true;
}

bool KltTrack::step(const cv::Mat& grey, landmarks::MatchResult& out) {
  if (!active_) return false;
  if (grey.size() != prev_.size() || grey.type() != CV_8UC1) return active_ = false;
  const cv::Size win(p_.window_px, p_.window_px);
  const cv::TermCriteria term(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 20, 0.03);
  std::vector<cv::Point2f> next, back;
  std::vector<unsigned char> st, st_back;
  std::vector<float> err;
  cv::calcOpticalFlowPyrLK(prev_, grey, pts_, next, st, err, win, p_.pyramid_levels, term);
  cv::calcOpticalFlowPyrLK(grey, prev_, next, back, st_back, err, win, p_.pyramid_levels, term);
  std::vector<cv::Point2f> src, dst;  // database -> this frame
  const float fb2 = static_cast<float>(p_.fb_max_px * p_.fb_max_px);
  const cv::Rect2f inside(0, 0, static_cast<float>(grey.cols), static_cast<float>(grey.rows));
  for (size_t i = 0; i < pts_.size(); ++i) {
    if (!st[i] || !st_back[i]) continue;
    const cv::Point2f d = back[i] - pts_[i];
    if (d.dot(d) > fb2 || !inside.contains(next[i])) continue;
    src.push_back(db_[i]);
    dst.push_back(next[i]);
  }
  if (static_cast<int>(dst.size()) < p_.min_points) return active_ = false;
  std::vector<unsigned char> mask;
  cv::Mat H = cv::findHomography(src, dst, cv::RANSAC, p_.ransac_px, mask, 500, 0.995);
  if (H.empty()) return active_ = false;
  int inl = 0;
  for (unsigned char k : mask) inl += k ? 1 : 0;
  if (inl < p_.min_points || inl < p_.min_inlier_share * static_cast<double>(dst.size()))
    return active_ = false;
  const double a0 = quadArea(match_.H, match_.database_size),
               a1 = quadArea(H, match_.database_size);
  if (!(a0 > 0 && a1 > 0) || a1 > a0 * p_.max_area_change || a1 * p_.max_area_change < a0)
    return active_ = false;
  landmarks::MatchResult m = match_;
  m.H = H;
  m.x_t.clear();
  m.x_d.clear();
  for (size_t i = 0; i < mask.size(); ++i)
    if (mask[i]) {
      m.x_d.push_back(src[i]);
      m.x_t.push_back(dst[i]);
    }
  m.inliers = inl;
  m.window = cv::boundingRect(m.x_t) & cv::Rect(0, 0, grey.cols, grey.rows);
  prev_ = grey;
  pts_ = m.x_t;
  db_ = m.x_d;
  match_ = m;
  ++age_;
  out = m;
  return true;
}

}  // namespace sketchnav::nav
