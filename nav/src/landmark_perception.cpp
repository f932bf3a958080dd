// The real perception: objectness windows -> RootSIFT matching of each window against the
// expected classes' database photos (ratio test + RANSAC homography) -> servo feature.
#include <algorithm>
#include <chrono>
#include <cmath>

#include "sketchnav/core/config.h"
#include "sketchnav/landmarks/matcher.h"
#include "sketchnav/landmarks/model.h"
#include "sketchnav/landmarks/objectness.h"
#include "sketchnav/nav/perception.h"

namespace sketchnav::nav {

void PerceptionParams::validate() const {
  require(max_windows >= 1 && max_windows <= 1000, "nav.perception.max_windows",
          "must be in [1, 1000]");
  require(min_inliers >= 4, "nav.perception.min_inliers", "must be >= 4 (a homography)");
  require(ratio > 0 && ratio < 1, "nav.perception.ratio", "must be in (0, 1)");
  require(max_photos >= 1, "nav.perception.max_photos", "must be >= 1");
  require(merge_iou > 0 && merge_iou <= 1, "nav.perception.merge_iou", "must be in (0, 1]");
  require(frame_max_side >= 64, "nav.perception.frame_max_side", "must be >= 64 px");
  require(frame_max_features >= 0, "nav.perception.frame_max_features", "must be >= 0");
}

struct LandmarkPerception::Impl {
  std::shared_ptr<const landmarks::LandmarkModel> model;
  PerceptionParams p;
  landmarks::Objectness objectness{landmarks::ObjectnessParams{}};
};

LandmarkPerception::LandmarkPerception(std::shared_ptr<const landmarks::LandmarkModel> model,
                                       PerceptionParams params)
    : impl_(std::make_unique<Impl>()) {
  params.validate();
  impl_->model = std::move(model);
  impl_->p = params;
}
LandmarkPerception::~LandmarkPerception() = default;

namespace {
double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}
double iou(const cv::Rect& a, const cv::Rect& b) {
  const double i = (a & b).area();
  const double u = a.area() + b.area() - i;
  return u > 0 ? i / u : 0;
}
}  // namespace

Observation LandmarkPerception::observe(const hw::Frame& frame, const hw::Intrinsics& K,
                                        const std::vector<std::string>& classes) {
  using clk = std::chrono::steady_clock;
  const auto& P = impl_->p;
  const auto& model = *impl_->model;
  Observation ob;
  const auto t0 = clk::now();
  if (frame.image.empty() || classes.empty()) return ob;

  auto t = clk::now();
  const auto windows = impl_->objectness.propose(frame.image, P.max_windows);
  ob.timing.objectness_ms = msSince(t);
  ob.timing.windows = static_cast<int>(windows.size());

  t = clk::now();
  landmarks::FeatureParams fp = model.params().features;
  fp.max_image_side = P.frame_max_side;
  fp.max_features = P.frame_max_features;
  const auto feats = landmarks::computeFrameFeatures(model, frame.image, fp);
  ob.timing.features_ms = msSince(t);

  t = clk::now();
  landmarks::MatchParams mp;
  mp.ratio = P.ratio;
  mp.min_inliers = P.min_inliers;
  mp.max_photos = P.max_photos;
  std::vector<cv::Rect> boxes;
  for (const auto& w : windows) boxes.push_back(w.box);
  if (P.whole_frame) boxes.push_back(cv::Rect());  // empty = the whole frame
  for (const auto& cls : classes) {
    if (model.classId(cls) < 0) continue;  // not in the model: nothing to look for
    std::vector<Detection> found;
    for (const auto& box : boxes) {
      const auto m = landmarks::match(model, feats, box, cls, mp);
      if (!m.matched) continue;
      const auto off = landmarks::servoOffset(m, frame.image.cols);
      if (!off.valid) continue;
      Detection d;
      d.class_name = cls;
      d.window = box.area() > 0 ? box : cv::Rect(0, 0, frame.image.cols, frame.image.rows);
      d.inliers = m.inliers;
      d.confidence = m.confidence;
      // Servo feature in normalised coordinates (doc/conventions.md). x_t: where the object
      // is; x_d such that x_t - x_d is the chosen offset measure.
      d.x_t = K.normalisedX(off.object_u);
      const double err_px = P.paper_offset ? off.paper_offset_px : off.offset_px;
      d.x_d = d.x_t - err_px / K.fx;
      d.bearing = P.camera_yaw - std::atan(d.x_t);
      // The same landmark seen through overlapping windows is one detection (most inliers).
      bool merged = false;
      for (auto& f : found)
        if (iou(f.window, d.window) > P.merge_iou || std::abs(f.x_t - d.x_t) < 0.03) {
          if (d.inliers > f.inliers) f = d;
          merged = true;
          break;
        }
      if (!merged) found.push_back(d);
    }
    ob.detections.insert(ob.detections.end(), found.begin(), found.end());
  }
  std::sort(ob.detections.begin(), ob.detections.end(),
            [](const Detection& a, const Detection& b) { return a.inliers > b.inliers; });
  ob.timing.match_ms = msSince(t);
  ob.timing.total_ms = msSince(t0);
  return ob;
}

}  // namespace sketchnav::nav
