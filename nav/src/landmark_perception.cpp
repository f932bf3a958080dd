// The real perception: objectness windows -> RootSIFT matching of each window against the
// expected classes' database photos (ratio test + RANSAC homography) -> servo feature; with
// LookFor hints, a foveal second look at a hinted class the normal pass missed.
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <exception>
#include <functional>
#include <future>
#include <limits>
#include <map>
#include <mutex>

#include "sketchnav/core/config.h"
#include "sketchnav/landmarks/matcher.h"
#include "sketchnav/landmarks/model.h"
#include "sketchnav/landmarks/objectness.h"
#include "sketchnav/nav/perception.h"

namespace sketchnav::nav {

void PerceptionParams::validate() const {
  require(max_windows >= 1 && max_windows <= 1000, "nav.perception.max_windows",
          "must be in [1, 1000]");
  require(merge_iou > 0 && merge_iou <= 1, "nav.perception.merge_iou", "must be in (0, 1]");
  require(frame_max_side >= 64, "nav.perception.frame_max_side", "must be >= 64 px");
  require(frame_max_features >= 0, "nav.perception.frame_max_features", "must be >= 0");
  require(fovea_min_range_m >= 0, "nav.perception.fovea_min_range_m", "must be >= 0 m");
  require(fovea_max_range_m > fovea_min_range_m, "nav.perception.fovea_max_range_m",
          "must be > fovea_min_range_m");
  require(fovea_width > 0 && fovea_width <= 1, "nav.perception.fovea_width", "must be in (0, 1]");
  require(fovea_height > 0 && fovea_height <= 1, "nav.perception.fovea_height",
          "must be in (0, 1]");
  require(fovea_ref_range_m > 0, "nav.perception.fovea_ref_range_m", "must be > 0 m");
  require(fovea_max_upscale >= 1 && fovea_max_upscale <= 8, "nav.perception.fovea_max_upscale",
          "must be in [1, 8]");
  require(fovea_max_side >= 64, "nav.perception.fovea_max_side", "must be >= 64 px");
  require(fovea_max_features >= 0, "nav.perception.fovea_max_features", "must be >= 0");
  require(fovea_max_looks >= 0, "nav.perception.fovea_max_looks", "must be >= 0");
  require(recognise_windows >= 0 && recognise_windows <= max_windows,
          "nav.perception.recognise_windows", "must be in [0, max_windows]");
  require(position_min_inliers >= 4 && position_min_inliers <= match.min_inliers,
          "nav.perception.position_min_inliers",
          "must be in [4, landmarks.match.min_inliers] (a homography)");
  require(window_side >= 64 && window_side <= 1024, "nav.perception.window_side",
          "must be in [64, 1024] px");
  require(window_margin >= 0 && window_margin <= 1, "nav.perception.window_margin",
          "must be in [0, 1]");
  require(window_max_features >= 0, "nav.perception.window_max_features", "must be >= 0");
  require(window_tilts >= 0 && window_tilts <= 4, "nav.perception.window_tilts",
          "must be in [0, 4] (tilted views per recognised window)");
  require(tilt_confirm_frames >= 0 && tilt_confirm_frames <= 100,
          "nav.perception.tilt_confirm_frames", "must be in [0, 100] (observe() calls)");
  require(threads >= 1 && threads <= 2, "nav.perception.threads",
          "must be 1 or 2 (the stages that run side by side)");
  match.validate();
  track.validate();
  recognition.validate();
  objectness.validate();
}

PerceptionParams perceptionParamsFrom(const Config& config) {
  PerceptionParams p;
  applyConfig(p, config, "nav.perception");
  p.setCamera(cameraMountFrom(config));
  for (const char* k : {"ratio", "min_inliers", "max_photos", "distinct_min_fraction"})
    rejectRenamed(config, std::string("nav.perception.") + k, std::string("landmarks.match.") + k,
                  "the navigation's matching rule is the one recognise --match uses");
  applyConfig(p.match, config, "landmarks.match");
  applyConfig(p.track, config, "nav.perception.track");
  applyConfig(p.recognition, config, "landmarks.recognition");
  p.objectness = landmarks::objectnessParamsFrom(config);
  p.validate();
  return p;
}

namespace {
// The hinted classes, each once, in hint order.
std::vector<std::string> classesOf(const std::vector<LookFor>& look_for) {
  std::vector<std::string> classes;
  for (const auto& l : look_for)
    if (std::find(classes.begin(), classes.end(), l.class_name) == classes.end())
      classes.push_back(l.class_name);
  return classes;
}
}  // namespace

Observation Perception::observe(const hw::Frame& frame, const hw::Intrinsics& k,
                                const std::vector<LookFor>& look_for) {
  return observe(frame, k, classesOf(look_for));
}

struct LandmarkPerception::Impl {
  std::shared_ptr<const landmarks::LandmarkModel> model;
  PerceptionParams p;
  explicit Impl(const landmarks::ObjectnessParams& op) : objectness(op) {}
  landmarks::Objectness objectness;
  // Detect, then track: per looked-for class, the landmark last detected and followed since.
  struct Track {
    KltTrack klt;
    Detection detected;   // the detection it started from (recognised_only, confidence)
    int unconfirmed = 0;  // observe() calls since a full pass last detected it
  };
  std::map<std::string, Track> tracks;
  int since_full = std::numeric_limits<int>::max() / 2;  // observe() calls since the full pass
  cv::Size frame_size;
  // The last full-pass detection of each class (reported or held back) and the observe() call
  // it came in: what confirms a tilted detection (tilt_confirm_frames).
  struct Seen {
    cv::Rect window;
    long call = 0;
  };
  std::map<std::string, Seen> last_seen;
  long calls = 0;  // observe() calls since construction or reset()
};

LandmarkPerception::LandmarkPerception(std::shared_ptr<const landmarks::LandmarkModel> model,
                                       PerceptionParams params)
    : impl_(std::make_unique<Impl>(params.objectness)) {
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

// Elevation [rad] above the camera's horizontal plane of the matched object's centre (the
// database photo's centre through H, servoOffset()), the camera tilted up by `pitch`; NaN
// without a usable H.
double elevationOf(const landmarks::ServoOffset& off, const hw::Intrinsics& K, double pitch) {
  const double u = off.centre_u, v = off.centre_v;
  if (!std::isfinite(u) || !std::isfinite(v) || v < -K.height || v > 2.0 * K.height) return NAN;
  // The ray (x, y, 1) in the optical frame (y down), in the robot's frame (x ahead, z up).
  const double x = (u - K.cx) / K.fx, y = (v - K.cy) / K.fy;
  const double ahead = std::cos(pitch) + y * std::sin(pitch);
  const double up = std::sin(pitch) - y * std::cos(pitch);
  return std::atan2(up, std::hypot(ahead, x));
}

// A match (in frame pixels) as a Detection; false when it gives no servo offset.
bool toDetection(const landmarks::MatchResult& m, const std::string& cls, const cv::Rect& window,
                 int frame_cols, const hw::Intrinsics& K, const PerceptionParams& P, Detection& d) {
  const auto off = landmarks::servoOffset(m, frame_cols);
  if (!off.valid) return false;
  d.class_name = cls;
  d.window = window;
  d.inliers = m.inliers;
  d.confidence = m.confidence;
  // Servo feature in normalised coordinates (doc/conventions.md). x_t: where the object
  // is; x_d the desired position: the image centre, or with paper_offset such that x_t - x_d
  // is the paper's median offset.
  d.x_t = K.normalisedX(off.object_u);
  d.x_d = P.paper_offset ? d.x_t - off.paper_offset_px / K.fx : 0.0;
  d.bearing = P.camera_yaw - std::atan(d.x_t);
  d.photo = m.database_photo;
  d.elevation = elevationOf(off, K, P.camera_pitch);
  d.match = std::make_shared<const landmarks::MatchResult>(m);
  return true;
}
// A match made on `crop` of the frame resized to `patch` pixels, in frame pixels (inliers and
// homography; per axis, since resize rounds the scaled size).
void toFramePixels(landmarks::MatchResult& m, const cv::Rect& crop, cv::Size patch) {
  const double sx = static_cast<double>(patch.width) / crop.width,
               sy = static_cast<double>(patch.height) / crop.height;
  for (auto& p : m.x_t)
    p = {static_cast<float>(crop.x + p.x / sx), static_cast<float>(crop.y + p.y / sy)};
  if (!m.H.empty()) {
    const cv::Mat A = (cv::Mat_<double>(3, 3) << 1 / sx, 0, crop.x, 0, 1 / sy, crop.y, 0, 0, 1);
    m.H = A * m.H;
  }
  m.window = crop;
}

// Indices of the frame keypoints inside `box` (empty box = the whole frame).
std::vector<int> keypointsIn(const landmarks::FrameFeatures& f, const cv::Rect& box) {
  std::vector<int> out;
  const auto& kp = f.features.keypoints;
  for (int i = 0; i < static_cast<int>(kp.size()); ++i)
    if (box.area() == 0 || box.contains(cv::Point(cvRound(kp[i].pt.x), cvRound(kp[i].pt.y))))
      out.push_back(i);
  return out;
}

// The best BoW decision value among `class_ids` for the words of the keypoints `in` (a window's).
float bowScore(const landmarks::LandmarkModel& model, const landmarks::FrameFeatures& f,
               const std::vector<int>& in, const std::vector<int>& class_ids) {
  std::vector<int> words;
  for (int i : in)
    if (i < static_cast<int>(f.words.size())) words.push_back(f.words[i]);
  if (words.empty()) return -1e9f;
  const auto d =
      model.classifier().decision(landmarks::bowHistogram(words, model.vocabulary().idf()));
  float best = -1e9f;
  for (int c : class_ids)
    if (c >= 0 && c < static_cast<int>(d.size())) best = std::max(best, d[c]);
  return best;
}

// A crop of the full-resolution frame, stretched horizontally by `tilt` (1 = as seen) and scaled
// so its longer side is `side` px, recognised on its own features (a landmark a few dozen pixels
// wide in the frame gets the pixels SIFT needs); when the answer is one of `classes`, matched for
// its position (min_inliers, else position_min_inliers) and mapped back to frame pixels. False
// when it gives no detection (not recognised as a looked-for class, or no match to place it).
bool examineView(const landmarks::LandmarkModel& model, const cv::Mat& img, const cv::Rect& crop,
                 int side, double tilt, const std::vector<std::string>& classes,
                 const hw::Intrinsics& K, const PerceptionParams& P, Detection& d) {
  const double scale = static_cast<double>(side) / std::max(tilt * crop.width, 1.0 * crop.height);
  cv::Mat patch;
  cv::resize(img(crop), patch, cv::Size(), tilt * scale, scale,
             tilt * scale > 1 || scale > 1 ? cv::INTER_LINEAR : cv::INTER_AREA);
  landmarks::FeatureParams fp = model.params().features;
  fp.max_image_side = std::max({64, patch.cols, patch.rows});  // already at the chosen size
  fp.max_features = P.window_max_features;
  const auto feats = landmarks::computeFrameFeatures(model, patch, fp);
  const auto recs = landmarks::recogniseWindows(model, feats, {cv::Rect()}, 1, P.recognition);
  if (recs.empty() || recs[0].empty() || recs[0][0].rejected) return false;
  const auto& r = recs[0][0];
  if (std::find(classes.begin(), classes.end(), r.class_name) == classes.end()) return false;
  landmarks::MatchParams mp = P.match;
  auto m = landmarks::match(model, feats, cv::Rect(), r.class_name, mp);
  if (!m.matched) {
    mp.min_inliers = P.position_min_inliers;
    m = landmarks::match(model, feats, cv::Rect(), r.class_name, mp);
  }
  bool placed = false;
  if (m.matched) {
    toFramePixels(m, crop, patch.size());  // per axis: undoes the stretch too
    placed = toDetection(m, r.class_name, crop, img.cols, K, P, d);
  }
  // Without geometry there is no position: a window's centre is not the landmark's (a window
  // may hold much more than the landmark), and a wrong bearing misleads the route refit.
  if (!placed) return false;
  d.inliers = std::max(d.inliers, r.inliers);
  d.recognised_only = d.inliers < P.match.min_inliers;
  // A homography from fewer than min_inliers inliers places the landmark's column but not
  // the photo's centre well enough to range it by its elevation.
  if (d.recognised_only) d.elevation = NAN;
  if (d.confidence <= 0) d.confidence = 0.5f * r.colour_probability;
  return true;
}

// The crop as seen, then, while nothing is found, its tilted views (window_tilts of them, tilt
// sqrt(2)^k): a landmark turned by a yaw about the vertical axis is foreshortened horizontally
// by ~cos(yaw), which SIFT tolerates to ~30 degrees; stretching the crop back by 1/cos (1.41:
// 45 degrees, 2: 60 degrees) undoes most of it (ASIFT's tilts, applied to the frame instead of
// the database, so the model stays as it is and views are paid for only where nothing was
// found).
bool examineCrop(const landmarks::LandmarkModel& model, const cv::Mat& img, const cv::Rect& crop,
                 int side, const std::vector<std::string>& classes, const hw::Intrinsics& K,
                 const PerceptionParams& P, Detection& d) {
  double tilt = 1;
  for (int k = 0; k <= P.window_tilts; ++k, tilt *= std::sqrt(2.0))
    if (examineView(model, img, crop, side, tilt, classes, K, P, d)) {
      d.tilted = k > 0;
      return true;
    }
  return false;
}

// The recognition stage's choice: the `windows` ranked by the looked-for classes' keypoint votes
// (rank_by_votes) then their BoW score on the frame's words (objectness order among equal
// scores), the best recognise_windows of them with a margin: the crops examineCrop() looks at
// in rank order.
std::vector<cv::Rect> rankedCrops(const landmarks::LandmarkModel& model, const cv::Mat& img,
                                  const landmarks::FrameFeatures& feats,
                                  const std::vector<cv::Rect>& windows,
                                  const std::vector<std::string>& classes,
                                  const PerceptionParams& P) {
  std::vector<cv::Rect> crops;
  if (P.recognise_windows <= 0 || windows.empty()) return crops;
  // The looked-for classes the model knows (a class it was not trained on has no votes, and
  // its id -1 is what a keypoint voting for no class holds).
  std::vector<int> ids;
  for (const auto& c : classes)
    if (const int id = model.classId(c); id >= 0) ids.push_back(id);
  // Per window: the looked-for classes' nearest-neighbour votes among its keypoints, weighed by
  // how much of the window votes for them (votes / sqrt(keypoints)), then the BoW score.
  std::vector<int> voted;
  if (P.rank_by_votes) voted = landmarks::keypointVotes(model, feats, P.recognition);
  std::vector<std::pair<std::pair<float, float>, int>> ranked;
  for (int i = 0; i < static_cast<int>(windows.size()); ++i) {
    const auto in = keypointsIn(feats, windows[i]);
    float vote_score = 0;
    if (P.rank_by_votes && !in.empty()) {
      int v = 0;
      for (int k : in)
        if (std::find(ids.begin(), ids.end(), voted[k]) != ids.end()) ++v;
      vote_score = static_cast<float>(v / std::sqrt(static_cast<double>(in.size())));
    }
    ranked.push_back({{vote_score, bowScore(model, feats, in, ids)}, i});
  }
  std::stable_sort(ranked.begin(), ranked.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  const cv::Rect frame_rect(0, 0, img.cols, img.rows);
  for (int i = 0; i < std::min<int>(P.recognise_windows, ranked.size()); ++i) {
    const cv::Rect& w = windows[ranked[i].second];
    // A margin round the window: objectness windows often clip the object's border.
    const int mx = static_cast<int>(P.window_margin * w.width),
              my = static_cast<int>(P.window_margin * w.height);
    const cv::Rect crop =
        cv::Rect(w.x - mx, w.y - my, w.width + 2 * mx, w.height + 2 * my) & frame_rect;
    if (crop.width < 8 || crop.height < 8) continue;
    crops.push_back(crop);
  }
  return crops;
}

// Runs a full pass's matching work on `threads` threads: first `rank()` (which decides how many
// crops there are; one thread runs it while the other starts on the windows), then each crop
// (the longest items: a recognition, perhaps tilted views) before the windows still left, every
// item on whichever thread is free. The items do not depend on each other (the model and the
// frame's caches are only read, or filled under their own lock), so the results are the same on
// any thread count; the caller merges them in a fixed order. The first exception stops the
// remaining items and is rethrown here.
void runMatchingWork(int threads, size_t n_windows, const std::function<size_t()>& rank,
                     const std::function<void(size_t)>& examine_crop,
                     const std::function<void(size_t)>& match_window) {
  if (threads < 2) {
    for (size_t i = 0; i < n_windows; ++i) match_window(i);
    const size_t n_crops = rank();
    for (size_t i = 0; i < n_crops; ++i) examine_crop(i);
    return;
  }
  std::mutex m;
  std::condition_variable changed;
  bool rank_taken = false, ranked = false;
  size_t n_crops = 0, next_crop = 0, next_window = 0;
  std::exception_ptr failure;
  const auto worker = [&] {
    for (;;) {
      enum { kNone, kRank, kCrop, kWindow } what = kNone;
      size_t i = 0;
      {
        std::unique_lock<std::mutex> lock(m);
        for (;;) {
          if (failure) break;
          if (!rank_taken) {
            rank_taken = true, what = kRank;
            break;
          }
          if (ranked && next_crop < n_crops) {
            what = kCrop, i = next_crop++;
            break;
          }
          if (next_window < n_windows) {
            what = kWindow, i = next_window++;
            break;
          }
          if (ranked) break;   // nothing left
          changed.wait(lock);  // the crops are not known yet
        }
      }
      if (what == kNone) return;
      try {
        if (what == kRank) {
          const size_t n = rank();
          std::lock_guard<std::mutex> lock(m);
          n_crops = n, ranked = true;
        } else if (what == kCrop) {
          examine_crop(i);
        } else {
          match_window(i);
        }
      } catch (...) {
        std::lock_guard<std::mutex> lock(m);
        if (!failure) failure = std::current_exception();
      }
      if (what == kRank || failure) changed.notify_all();
    }
  };
  auto other = std::async(std::launch::async, worker);
  worker();
  other.get();
  if (failure) std::rethrow_exception(failure);
}

// Adds `d` to `found` unless it is the same landmark as one there (overlapping windows or the
// same column): then the one with more inliers stays.
void mergeDetection(std::vector<Detection>& found, const Detection& d, double merge_iou) {
  for (auto& f : found)
    if (f.class_name == d.class_name &&
        (iou(f.window, d.window) > merge_iou || std::abs(f.x_t - d.x_t) < 0.03)) {
      // A detection as seen outranks one found only in a tilted view of the same place: the
      // tilted one may be held back for confirmation (tilt_confirm_frames), and it must not
      // take an as-seen detection down with it.
      if (f.tilted != d.tilted ? f.tilted : d.inliers > f.inliers) f = d;
      return;
    }
  found.push_back(d);
}
}  // namespace

Observation LandmarkPerception::fullPass(const hw::Frame& frame, const hw::Intrinsics& K,
                                         const std::vector<std::string>& classes) {
  using clk = std::chrono::steady_clock;
  const auto& P = impl_->p;
  const auto& model = *impl_->model;
  Observation ob;
  const auto t0 = clk::now();
  if (frame.image.empty() || classes.empty()) return ob;
  ob.timing.full_pass = true;

  // The objectness windows and the frame's features do not depend on each other: with two
  // threads the windows are proposed beside the features.
  const auto proposeWindows = [&] {
    const auto t = clk::now();
    auto w = impl_->objectness.propose(frame.image, P.max_windows);
    ob.timing.objectness_ms = msSince(t);
    return w;
  };
  std::future<std::vector<landmarks::Window>> proposing;
  if (P.threads >= 2) proposing = std::async(std::launch::async, proposeWindows);

  auto t = clk::now();
  landmarks::FeatureParams fp = model.params().features;
  fp.max_image_side = P.frame_max_side;
  fp.max_features = P.frame_max_features;
  const auto feats = landmarks::computeFrameFeatures(model, frame.image, fp);
  ob.timing.features_ms = msSince(t);

  const auto windows = proposing.valid() ? proposing.get() : proposeWindows();
  ob.timing.windows = static_cast<int>(windows.size());
  for (const auto& w : windows) ob.windows.push_back(w.box);

  t = clk::now();
  const landmarks::MatchParams& mp = P.match;
  std::vector<cv::Rect> boxes = ob.windows;        // the objectness windows' boxes
  if (P.whole_frame) boxes.push_back(cv::Rect());  // empty = the whole frame
  // The work: every window (and the whole frame) matched against each looked-for class, and the
  // best-ranked windows recognised (rankedCrops, examineCrop); spread over the threads, merged
  // below in this order whatever ran first.
  std::vector<std::pair<std::string, cv::Rect>> pairs;
  for (const auto& cls : classes) {
    if (model.classId(cls) < 0) continue;  // not in the model: nothing to look for
    for (const auto& box : boxes) pairs.emplace_back(cls, box);
  }
  std::vector<Detection> window_found(pairs.size());
  std::vector<char> window_ok(pairs.size(), 0);
  const auto matchWindow = [&](size_t i) {
    const auto& [cls, box] = pairs[i];
    const auto m = landmarks::match(model, feats, box, cls, mp);
    if (!m.matched) return;
    const cv::Rect window =
        box.area() > 0 ? box : cv::Rect(0, 0, frame.image.cols, frame.image.rows);
    window_ok[i] = toDetection(m, cls, window, frame.image.cols, K, P, window_found[i]);
  };
  std::vector<cv::Rect> crops;
  std::vector<Detection> crop_found;
  std::vector<char> crop_ok;
  std::vector<double> recognise_ms;  // per item, summed below
  const auto rank = [&] {
    const auto tr = clk::now();
    crops = rankedCrops(model, frame.image, feats, ob.windows, classes, P);
    crop_found.resize(crops.size());
    crop_ok.assign(crops.size(), 0);
    recognise_ms.assign(crops.size() + 1, 0.0);
    recognise_ms.back() = msSince(tr);
    return crops.size();
  };
  const auto examine = [&](size_t i) {
    const auto tr = clk::now();
    crop_ok[i] =
        examineCrop(model, frame.image, crops[i], P.window_side, classes, K, P, crop_found[i]);
    recognise_ms[i] = msSince(tr);
  };
  runMatchingWork(P.threads, pairs.size(), rank, examine, matchWindow);
  for (size_t c = 0; c < pairs.size(); c += boxes.size()) {
    // The same landmark seen through overlapping windows is one detection (most inliers).
    std::vector<Detection> found;
    for (size_t i = c; i < c + boxes.size(); ++i)
      if (window_ok[i]) mergeDetection(found, window_found[i], P.merge_iou);
    ob.detections.insert(ob.detections.end(), found.begin(), found.end());
  }
  ob.timing.recognised += static_cast<int>(crops.size());
  for (size_t i = 0; i < crops.size(); ++i)
    if (crop_ok[i]) mergeDetection(ob.detections, crop_found[i], P.merge_iou);
  for (const double ms : recognise_ms) ob.timing.recognise_ms += ms;
  std::sort(ob.detections.begin(), ob.detections.end(),
            [](const Detection& a, const Detection& b) { return a.inliers > b.inliers; });
  ob.timing.match_ms = msSince(t);
  ob.timing.total_ms = msSince(t0);
  return ob;
}

void LandmarkPerception::foveaPass(const hw::Frame& frame, const hw::Intrinsics& K,
                                   const std::vector<LookFor>& look_for, Observation& ob) {
  using clk = std::chrono::steady_clock;
  const auto& P = impl_->p;
  const auto& model = *impl_->model;
  if (!P.fovea || frame.image.empty()) return;

  const auto tf = clk::now();
  const cv::Mat& img = frame.image;
  const landmarks::MatchParams& mp = P.match;
  std::vector<std::string> looked;  // one second look per class
  for (const auto& l : look_for) {
    if (!std::isfinite(l.bearing) || model.classId(l.class_name) < 0) continue;
    if (std::isfinite(l.range) && (l.range < P.fovea_min_range_m || l.range > P.fovea_max_range_m))
      continue;
    const auto seen = [&](const Detection& d) { return d.class_name == l.class_name; };
    if (std::any_of(ob.detections.begin(), ob.detections.end(), seen)) continue;
    if (std::find(looked.begin(), looked.end(), l.class_name) != looked.end()) continue;
    // Predicted image column (bearing = camera_yaw - atan(x)); behind the camera or outside
    // the image: nothing to look at.
    const double off_axis = std::remainder(P.camera_yaw - l.bearing, 2 * M_PI);
    if (std::abs(off_axis) >= M_PI / 2) continue;
    const double u = K.cx + K.fx * std::tan(off_axis);
    if (!(u >= 0 && u < img.cols)) continue;
    if (ob.timing.fovea_looks >= P.fovea_max_looks) break;  // the per-frame time budget
    looked.push_back(l.class_name);

    // Upscale distant landmarks to the pixel size they have at fovea_ref_range_m.
    double scale = 1;
    if (std::isfinite(l.range) && l.range > 0)
      scale = std::clamp(l.range / P.fovea_ref_range_m, 1.0, P.fovea_max_upscale);
    // The crop: centred on the predicted column (shifted to stay inside the image) and
    // vertically (the landmark's height above the floor is not predicted). A nearer landmark
    // can be further above or below the image centre, so the crop is taller: the frame's
    // height / upscale, at least fovea_height of the frame.
    const int cw = std::clamp(static_cast<int>(std::lround(P.fovea_width * img.cols)), 1, img.cols);
    const double tall = std::max(P.fovea_height, 1 / scale) * img.rows;
    const int ch = std::clamp(static_cast<int>(std::lround(tall)), 1, img.rows);
    const int x0 = std::clamp(static_cast<int>(std::lround(u - 0.5 * cw)), 0, img.cols - cw);
    const cv::Rect crop(x0, (img.rows - ch) / 2, cw, ch);
    scale = std::min(scale, static_cast<double>(P.fovea_max_side) / std::max(cw, ch));
    cv::Mat patch = img(crop);
    // Resized to a whole-pixel size, so the pixels depend on that size alone: cv::resize given a
    // factor interpolates with the factor itself, which follows the predicted range
    // continuously (a replay's pose, 1e-7 m off the run's, gave other keypoints).
    const cv::Size to(std::max(1, static_cast<int>(std::lround(cw * scale))),
                      std::max(1, static_cast<int>(std::lround(ch * scale))));
    if (to != crop.size()) {
      cv::Mat resized;
      cv::resize(patch, resized, to, 0, 0, scale > 1 ? cv::INTER_LINEAR : cv::INTER_AREA);
      patch = resized;
    }
    ++ob.timing.fovea_looks;

    landmarks::FeatureParams fp = model.params().features;
    fp.max_image_side = std::max({64, patch.cols, patch.rows});  // already at the chosen size
    fp.max_features = P.fovea_max_features;
    const auto feats = landmarks::computeFrameFeatures(model, patch, fp);
    auto m = landmarks::match(model, feats, cv::Rect(), l.class_name, mp);
    if (!m.matched && P.recognise_windows > 0) {
      // The crop recognised as the looked-for class: positioned by a looser match.
      const auto recs = landmarks::recogniseWindows(model, feats, {cv::Rect()}, 1, P.recognition);
      ++ob.timing.recognised;
      if (!recs.empty() && !recs[0].empty() && !recs[0][0].rejected &&
          recs[0][0].class_name == l.class_name) {
        landmarks::MatchParams loose = mp;
        loose.min_inliers = P.position_min_inliers;
        m = landmarks::match(model, feats, cv::Rect(), l.class_name, loose);
      }
    }
    if (!m.matched) continue;

    toFramePixels(m, crop, patch.size());
    Detection d;
    // The window drawn for it: the matched keypoints' extent, inside the crop.
    const cv::Rect box = cv::boundingRect(m.x_t) & crop;
    if (!toDetection(m, l.class_name, box.area() > 0 ? box : crop, img.cols, K, P, d)) continue;
    d.recognised_only = d.inliers < P.match.min_inliers;
    if (d.recognised_only) d.elevation = NAN;  // as in examineCrop()
    ob.detections.push_back(d);
  }
  std::sort(ob.detections.begin(), ob.detections.end(),
            [](const Detection& a, const Detection& b) { return a.inliers > b.inliers; });
  ob.timing.fovea_ms = msSince(tf);  // observeFrame() sets total_ms over all of it
}

void LandmarkPerception::confirmTilted(Observation& ob) {
  auto& I = *impl_;
  const auto consistent = [](const cv::Rect& a, const cv::Rect& b) {
    const double dx = (a.x + 0.5 * a.width) - (b.x + 0.5 * b.width);
    const double dy = (a.y + 0.5 * a.height) - (b.y + 0.5 * b.height);
    return std::hypot(dx, dy) < std::max(a.width, b.width);
  };
  std::vector<Detection> kept;
  std::map<std::string, Impl::Seen> now;
  for (auto& d : ob.detections) {
    bool report = true;
    if (d.tilted) {
      const auto it = I.last_seen.find(d.class_name);
      report = it != I.last_seen.end() && I.calls - it->second.call <= I.p.tilt_confirm_frames &&
               consistent(it->second.window, d.window);
    }
    if (!now.count(d.class_name)) now[d.class_name] = {d.window, I.calls};  // the best of each
    if (report) kept.push_back(std::move(d));
  }
  for (auto& [cls, seen] : now) I.last_seen[cls] = seen;
  ob.detections = std::move(kept);
}

Observation LandmarkPerception::observe(const hw::Frame& frame, const hw::Intrinsics& K,
                                        const std::vector<std::string>& classes) {
  return observeFrame(frame, K, classes, nullptr);
}

Observation LandmarkPerception::observe(const hw::Frame& frame, const hw::Intrinsics& K,
                                        const std::vector<LookFor>& look_for) {
  return observeFrame(frame, K, classesOf(look_for), &look_for);
}

void LandmarkPerception::reset() {
  impl_->tracks.clear();
  impl_->last_seen.clear();
  impl_->calls = 0;
  impl_->since_full = std::numeric_limits<int>::max() / 2;
}

// Detect, then track (TrackParams): the looked-for classes being tracked are followed into this
// frame; the full pass runs when none is tracked or every track.redetect_frames calls, and its
// detections (re)start the tracks. A tracked landmark the full pass missed keeps its tracked
// position until track.max_unconfirmed_frames calls pass without a detection.
Observation LandmarkPerception::observeFrame(const hw::Frame& frame, const hw::Intrinsics& K,
                                             const std::vector<std::string>& classes,
                                             const std::vector<LookFor>* look_for) {
  using clk = std::chrono::steady_clock;
  auto& I = *impl_;
  const auto& P = I.p;
  const auto t0 = clk::now();
  if (frame.image.empty() || classes.empty()) return {};
  const bool track = P.track.enabled;
  if (frame.image.size() != I.frame_size) reset();  // another camera or resolution
  I.frame_size = frame.image.size();
  cv::Mat grey;
  std::vector<Detection> followed;
  double track_ms = 0;
  int track_steps = 0;
  if (track) {
    const auto tt = clk::now();
    if (frame.image.channels() == 3)
      cv::cvtColor(frame.image, grey, cv::COLOR_BGR2GRAY);
    else if (frame.image.channels() == 4)
      cv::cvtColor(frame.image, grey, cv::COLOR_BGRA2GRAY);
    else
      grey = frame.image.clone();
    if (grey.type() != CV_8UC1) grey.convertTo(grey, CV_8U);
    for (auto it = I.tracks.begin(); it != I.tracks.end();) {
      auto& tr = it->second;
      landmarks::MatchResult m;
      const bool looked = std::find(classes.begin(), classes.end(), it->first) != classes.end();
      if (!looked || ++tr.unconfirmed > P.track.max_unconfirmed_frames) {
        it = I.tracks.erase(it);
        continue;
      }
      ++track_steps;
      if (!tr.klt.step(grey, m)) {
        it = I.tracks.erase(it);
        continue;
      }
      Detection d;
      if (toDetection(m, it->first, m.window, frame.image.cols, K, P, d)) {
        d.tracked = true;
        d.recognised_only = tr.detected.recognised_only;
        d.confidence = tr.detected.confidence;
        if (d.recognised_only) d.elevation = NAN;  // as the detection it follows
        followed.push_back(d);
      }
      ++it;
    }
    track_ms = msSince(tt);
  }
  const bool full = !track || followed.empty() || ++I.since_full >= P.track.redetect_frames;
  Observation ob;
  ++I.calls;
  if (full) {
    ob = fullPass(frame, K, classes);
    if (look_for) foveaPass(frame, K, *look_for, ob);
    I.since_full = 0;
    if (P.tilt_confirm_frames > 0) confirmTilted(ob);
  }
  if (track) {
    // The full pass's detections restart their class's track (the detector is the authority);
    // a followed landmark it missed stays, as tracked.
    std::vector<std::string> detected;
    for (const auto& d : ob.detections) {
      if (std::find(detected.begin(), detected.end(), d.class_name) != detected.end()) continue;
      detected.push_back(d.class_name);  // the best (first after sorting) of each class
      if (!d.match) continue;
      auto& tr = I.tracks[d.class_name];
      tr = Impl::Track{KltTrack(P.track), d, 0};
      if (!tr.klt.start(grey, *d.match)) I.tracks.erase(d.class_name);
    }
    for (const auto& d : followed)
      if (std::find(detected.begin(), detected.end(), d.class_name) == detected.end()) {
        ob.detections.push_back(d);
        ++ob.timing.tracked;
      }
    std::sort(ob.detections.begin(), ob.detections.end(),
              [](const Detection& a, const Detection& b) { return a.inliers > b.inliers; });
    ob.timing.track_ms = track_ms;
    ob.timing.track_steps = track_steps;
  }
  ob.timing.total_ms = msSince(t0);
  return ob;
}

}  // namespace sketchnav::nav
