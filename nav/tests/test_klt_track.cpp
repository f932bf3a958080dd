// KltTrack (detect, then track): a poster's match followed through a pan and an approach by
// optical flow with its position within a pixel of the truth; lost, never followed onto
// something else, when the poster disappears or is replaced; and LandmarkPerception serving a
// tracked landmark between its full passes.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <vector>

#include "sketchnav/core/error.h"
#include "sketchnav/nav/klt_track.h"

namespace sketchnav::nav {
namespace {

// A deterministic textured poster (boxes, discs, digits on a shaded ground).
cv::Mat poster(unsigned seed, int w = 200, int h = 150) {
  cv::RNG rng(seed);
  cv::Mat img(h, w, CV_8UC1);
  rng.fill(img, cv::RNG::UNIFORM, 40, 220);
  cv::GaussianBlur(img, img, cv::Size(0, 0), 4);
  for (int i = 0; i < 50; ++i) {
    const cv::Scalar c(rng.uniform(0, 255));
    const cv::Point a(rng.uniform(0, w), rng.uniform(0, h));
    if (i % 3 == 0)
      cv::rectangle(img, a, a + cv::Point(rng.uniform(4, 30), rng.uniform(4, 30)), c, -1);
    else if (i % 3 == 1)
      cv::circle(img, a, rng.uniform(2, 12), c, -1);
    else
      cv::putText(img, std::to_string(rng.uniform(10, 999)), a, cv::FONT_HERSHEY_SIMPLEX, 0.6, c,
                  1);
  }
  return img;
}

// A 640x480 frame: a smooth background (little for the flow to lock on) with `obj` warped
// by H (object -> frame).
cv::Mat frameWith(const cv::Mat& obj, const cv::Mat& H, unsigned bg_seed) {
  cv::RNG rng(bg_seed);
  cv::Mat img(480, 640, CV_8UC1);
  rng.fill(img, cv::RNG::UNIFORM, 90, 160);
  cv::GaussianBlur(img, img, cv::Size(0, 0), 12);
  cv::Mat mask(obj.size(), CV_8UC1, cv::Scalar(255)), wm;
  cv::Mat warped;
  cv::warpPerspective(obj, warped, H, img.size(), cv::INTER_LINEAR);
  cv::warpPerspective(mask, wm, H, img.size(), cv::INTER_NEAREST);
  warped.copyTo(img, wm);
  return img;
}

cv::Mat similarity(double tx, double ty, double s) {
  return (cv::Mat_<double>(3, 3) << s, 0, tx, 0, s, ty, 0, 0, 1);
}

// What a detector would hand over: the poster's corners (as keypoints) and H.
landmarks::MatchResult matchOf(const cv::Mat& obj, const cv::Mat& H) {
  landmarks::MatchResult m;
  m.matched = true;
  std::vector<cv::Point2f> corners;
  cv::goodFeaturesToTrack(obj, corners, 60, 0.01, 6);
  m.x_d = corners;
  cv::perspectiveTransform(corners, m.x_t, H);
  m.inliers = static_cast<int>(corners.size());
  m.H = H.clone();
  m.database_size = obj.size();
  m.database_photo = 0;
  return m;
}

// |H(p) - truth(p)| at the poster's centre [px].
double centreError(const cv::Mat& H, const cv::Mat& truth, cv::Size obj) {
  const std::vector<cv::Point2f> c = {{obj.width / 2.0f, obj.height / 2.0f}};
  std::vector<cv::Point2f> a, b;
  cv::perspectiveTransform(c, a, H);
  cv::perspectiveTransform(c, b, truth);
  return cv::norm(a[0] - b[0]);
}

TEST(KltTrack, FollowsAPanWithinAPixel) {
  const cv::Mat obj = poster(7);
  KltTrack t;
  cv::Mat H = similarity(60, 160, 1.0);
  ASSERT_TRUE(t.start(frameWith(obj, H, 1), matchOf(obj, H)));
  for (int i = 1; i <= 12; ++i) {
    H = similarity(60 + 25.0 * i, 160 + 3.0 * i, 1.0);  // 25 px per frame to the right
    landmarks::MatchResult m;
    ASSERT_TRUE(t.step(frameWith(obj, H, 1), m)) << "frame " << i;
    EXPECT_LT(centreError(m.H, H, obj.size()), 1.0) << "frame " << i;
    EXPECT_GE(m.inliers, 8);
    EXPECT_EQ(m.x_t.size(), m.x_d.size());
    EXPECT_EQ(m.database_size, obj.size());
  }
  EXPECT_EQ(t.age(), 12);
}

TEST(KltTrack, FollowsAnApproach) {
  const cv::Mat obj = poster(8);
  KltTrack t;
  double s = 0.6;
  cv::Mat H = similarity(320 - 100 * s, 240 - 75 * s, s);
  ASSERT_TRUE(t.start(frameWith(obj, H, 2), matchOf(obj, H)));
  for (int i = 1; i <= 10; ++i) {
    s *= 1.07;  // 7 % nearer per frame
    H = similarity(320 - 100 * s, 240 - 75 * s, s);
    landmarks::MatchResult m;
    ASSERT_TRUE(t.step(frameWith(obj, H, 2), m)) << "frame " << i;
    EXPECT_LT(centreError(m.H, H, obj.size()), 1.5) << "frame " << i;
  }
}

TEST(KltTrack, LostWhenThePosterIsGoneOrReplaced) {
  const cv::Mat obj = poster(9), other = poster(10);
  const cv::Mat H = similarity(200, 150, 1.0);
  {
    KltTrack t;
    ASSERT_TRUE(t.start(frameWith(obj, H, 3), matchOf(obj, H)));
    landmarks::MatchResult m;
    cv::Mat empty = frameWith(obj, similarity(2000, 2000, 1.0), 3);  // out of view
    EXPECT_FALSE(t.step(empty, m));
    EXPECT_FALSE(t.active());
    EXPECT_FALSE(t.step(frameWith(obj, H, 3), m));  // stays lost until restarted
  }
  {
    KltTrack t;
    ASSERT_TRUE(t.start(frameWith(obj, H, 3), matchOf(obj, H)));
    landmarks::MatchResult m;
    EXPECT_FALSE(t.step(frameWith(other, H, 3), m));  // another poster in the same place
  }
  {
    KltTrack t;
    ASSERT_TRUE(t.start(frameWith(obj, H, 3), matchOf(obj, H)));
    landmarks::MatchResult m;
    cv::Mat smaller;
    cv::resize(frameWith(obj, H, 3), smaller, cv::Size(320, 240));
    EXPECT_FALSE(t.step(smaller, m));  // another resolution: not the same camera
  }
}

TEST(KltTrack, RefusesAMatchItCannotFollow) {
  const cv::Mat obj = poster(11);
  const cv::Mat H = similarity(100, 100, 1.0);
  landmarks::MatchResult m = matchOf(obj, H);
  KltTrack t;
  landmarks::MatchResult few = m;
  few.x_t.resize(5);
  few.x_d.resize(5);
  EXPECT_FALSE(t.start(frameWith(obj, H, 4), few));  // fewer than min_points
  landmarks::MatchResult no_h = m;
  no_h.H.release();
  EXPECT_FALSE(t.start(frameWith(obj, H, 4), no_h));
  cv::Mat colour;
  cv::cvtColor(frameWith(obj, H, 4), colour, cv::COLOR_GRAY2BGR);
  EXPECT_FALSE(t.start(colour, m));  // grey frames only
  EXPECT_FALSE(t.active());
}

TEST(TrackParamsTest, FieldsAreValidated) {
  auto bad = [](auto change, const char* field) {
    TrackParams p;
    change(p);
    try {
      p.validate();
      ADD_FAILURE() << field << " accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  bad([](TrackParams& p) { p.redetect_frames = 0; }, "redetect_frames");
  bad([](TrackParams& p) { p.max_unconfirmed_frames = p.redetect_frames - 1; },
      "max_unconfirmed_frames");
  bad([](TrackParams& p) { p.min_points = 3; }, "min_points");
  bad([](TrackParams& p) { p.window_px = 20; }, "window_px");
  bad([](TrackParams& p) { p.max_area_change = 1; }, "max_area_change");
  EXPECT_NO_THROW(TrackParams{}.validate());
}

}  // namespace
}  // namespace sketchnav::nav
