#pragma once
// What the executive asks of vision: "in this frame, where are landmarks of these classes?".
// The real implementation (LandmarkPerception) runs objectness windows, RootSIFT matching of
// each window against the expected classes' database photos (ratio test + RANSAC) and turns
// the inliers into the servo feature. Tests may substitute their own Perception; `sketchnav
// run` always uses the real one.
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core/types.hpp>

#include "sketchnav/core/camera_mount.h"
#include "sketchnav/core/config.h"
#include "sketchnav/hw/types.h"
#include "sketchnav/landmarks/objectness.h"
#include "sketchnav/landmarks/recognition.h"
#include "sketchnav/nav/klt_track.h"

namespace sketchnav::landmarks {
class LandmarkModel;
}

namespace sketchnav::nav {

struct Detection {
  std::string class_name;
  cv::Rect window;       // [px] the objectness window that matched
  int inliers = 0;       // RANSAC inliers against the best database photo
  float confidence = 0;  // in [0, 1)
  double x_t = 0;        // [normalised] current horizontal coordinate of the landmark
  double x_d = 0;        // [normalised] its desired value (database position)
  double bearing = 0;    // [rad] robot frame, CCW positive (from x_t and the camera mount)
  // [rad] angle of the object's centre (the database photo's centre through the homography)
  // above the camera's horizontal plane (camera_pitch removed); NaN when unknown. The
  // landmark's height does not change, so how this grows as the robot approaches ranges it
  // where the laser cannot (locateLandmark: an elevated carton, the laser passing under it).
  double elevation = NAN;
  int photo = -1;  // database photo matched: elevations compare within one photo (its framing)
  // true: found by recognition (votes, BoW, colour) with fewer than min_inliers inliers; its
  // column is from a looser match, and it has no elevation (NaN).
  bool recognised_only = false;
  // true: followed by the tracker (KltTrack) from an earlier frame's detection, not detected
  // in this frame.
  bool tracked = false;
  // true: found in a tilted view of its window (PerceptionParams::window_tilts), not as seen.
  bool tilted = false;
  // The verified match behind it, in frame pixels (inliers, homography, database photo): what
  // a tracker starts from and an overlay draws. Null for a Perception that does not match.
  std::shared_ptr<const landmarks::MatchResult> match;
};

struct PerceptionTiming {
  double objectness_ms = 0, features_ms = 0, match_ms = 0, total_ms = 0;  // wall time
  double fovea_ms = 0;  // wall time of the foveal second looks (part of total_ms)
  // Time spent recognising the ranked windows (ranking them, examining each crop), summed over
  // the threads: part of match_ms's work, run beside the window matching with two threads.
  double recognise_ms = 0;
  int recognised = 0;      // windows recognised (recognise_windows at most)
  int windows = 0;         // objectness windows examined
  int fovea_looks = 0;     // foveal crops examined (a hinted class missed by the normal pass)
  bool full_pass = false;  // the full pass (objectness, features, matching) ran on this frame
  double track_ms = 0;     // wall time of the tracker's steps (part of total_ms)
  int tracked = 0;         // detections that come from the tracker
  int track_steps = 0;     // tracks the tracker stepped into this frame (found or lost)
};

/// A class to look for, with where the executive expects it (from the sketch). Without a
/// finite bearing it is looked for like a bare class name.
struct LookFor {
  std::string class_name;
  double bearing = NAN;  // [rad] robot frame, CCW positive, predicted
  double range = NAN;    // [m] predicted (NaN: unknown, no upscaling)
};

struct Observation {
  std::vector<Detection> detections;  // at most one per landmark-sized region, best first
  // The objectness windows the full pass examined (frame pixels; what a view of perception
  // draws besides the detections); empty when no full pass ran (a tracked frame).
  std::vector<cv::Rect> windows;
  PerceptionTiming timing;
};

class Perception {
 public:
  virtual ~Perception() = default;
  /// Looks for `classes` in `frame`. Never throws for an unrecognisable frame (empty result).
  virtual Observation observe(const hw::Frame& frame, const hw::Intrinsics& k,
                              const std::vector<std::string>& classes) = 0;
  /// Same, with where each class is expected. The default ignores the hints (looks for the
  /// classes, in order, once each); LandmarkPerception takes a foveal second look at a hinted
  /// class the normal pass missed. Detections are in full-frame coordinates either way.
  virtual Observation observe(const hw::Frame& frame, const hw::Intrinsics& k,
                              const std::vector<LookFor>& look_for);
  /// Forgets what earlier frames showed (tracks): the next frame does not follow the last one
  /// (another sequence, a camera restarted). The default has nothing to forget.
  virtual void reset() {}
};

struct PerceptionParams {
  int max_windows = 30;      // objectness windows examined per frame
  bool whole_frame = false;  // also match the whole frame (when objectness misses)
  // The servo error x_t - x_d a detection gives. true: the paper's median over inliers of
  // (x_t - x_d), each measured from its own image's centre, which places the database photo's
  // centre: the object only when the photo shows it centred. false: the matched object's
  // offset from the image centre (x_d = 0; x_t is the centre of the matched part of the
  // database photo through the homography, the column the bearing is read at): more frames
  // of the real-photo benchmark agree with the truth, but the generated worlds' closed loop did
  // not gain from it. Evidence: doc/perception-benchmark.md "The servo error: the object's
  // offset, not the photo's".
  bool paper_offset = true;
  // The camera's pan and tilt, from the camera mount (the "robot.camera.*" settings,
  // CameraMount in core/camera_mount.h): not settings of their own.
  double camera_yaw = 0;    // [rad] camera pan on the robot (bearing = yaw - atan(x))
  double camera_pitch = 0;  // [rad] camera tilt, up positive (for Detection::elevation)
  double merge_iou = 0.3;   // detections of a class overlapping more are one landmark
  // SIFT settings for camera frames (the model's photo settings are 400 px / 500 keypoints).
  // Larger frames find small, distant landmarks more often but bring back false reports of
  // sibling products and cost time; raise both for small or distant landmarks. The evidence:
  // doc/perception-benchmark.md "View synthesis and frame resolution".
  int frame_max_side = 400;      // [px] longer frame side above this is downscaled for SIFT
  int frame_max_features = 500;  // strongest keypoints kept per frame (0 = all)
  // Foveal second look (observe() with LookFor hints only): for a hinted class the normal pass
  // did not detect, whose predicted bearing is in the field of view, a crop of the
  // full-resolution frame centred on the predicted column is matched on its own, upscaled by
  // range / fovea_ref_range_m so a distant landmark has as many pixels as a near one. Same
  // min_inliers rule: never a guess. Costs time only when a hinted landmark was missed. The
  // crop is narrowish (less clutter competes with the landmark for the keypoint budget) but
  // wide enough to hold a landmark whose predicted bearing is some degrees off. It is centred
  // vertically, fovea_height of the frame tall, taller for a landmark nearer than
  // 2 x fovea_ref_range_m (frame height / upscale), which may be seen well above or below the
  // centre. doc/landmark-model.md "Foveal second look"; the evidence for the defaults:
  // doc/perception-benchmark.md "Evidence for the foveal second-look defaults". Off by default:
  // on photos the model was not trained on, upscaling a distant landmark's crop adds pixels but
  // not the detail the matcher needs, so the look rarely finds one and costs a fifth of the
  // perception time per frame.
  bool fovea = false;              // take the second look at all
  double fovea_min_range_m = 0;    // [m] no second look at landmarks predicted nearer
  double fovea_max_range_m = 6;    // [m] nor further (too few pixels even upscaled)
  double fovea_width = 0.4;        // crop width, fraction of the frame width, (0, 1]
  double fovea_height = 0.5;       // least crop height, fraction of the frame height, (0, 1]
  double fovea_ref_range_m = 2.0;  // [m] crop upscale = predicted range / this (at least 1)
  double fovea_max_upscale = 3.0;  // upscale at most this, in [1, 8]
  int fovea_max_side = 640;        // [px] the upscaled crop's longer side at most this
  int fovea_max_features = 1000;   // strongest keypoints kept in the crop (0 = all)
  int fovea_max_looks = 1;         // second looks per frame at most, in hint order (the
                                   // executive lists the landmark it servos on first)
  // Recognition in the loop (the paper's pipeline): windows are ranked for the looked-for
  // classes (rank_by_votes, below), and the best recognise_windows of them are recognised
  // (landmarks::recogniseWindows: votes, BoW, colour layout and verification) on a crop of the
  // full-resolution frame scaled to window_side px. A window whose answer is a looked-for class is
  // a detection even when no database photo reaches min_inliers (a view the photos do not show
  // closely): its position then comes from a match needing only position_min_inliers; without one
  // it gives no detection (a window's centre is no position). The foveal second look is recognised
  // the same way. 0 = matching alone.
  int recognise_windows = 4;
  // How the windows are ranked. true: by the frame keypoints inside a window that vote for a
  // looked-for class (landmarks::keypointVotes: nearest database neighbour, ratio test between
  // classes), divided by the square root of the window's keypoints (a window mostly made of the
  // landmark outranks a larger one that also holds it), then by the BoW score. false: by the
  // BoW score alone (the SVM decision on the window's visual words), which a window of a few
  // dozen keypoints leaves close to chance. Evidence: doc/perception-benchmark.md "Ranking the
  // windows by votes".
  bool rank_by_votes = true;
  int position_min_inliers = 6;   // RANSAC inliers for the servo position of a recognised window
  int window_side = 256;          // [px] a recognised window is cropped and scaled to this side
  double window_margin = 0.15;    // crop margin round the window, fraction of its size per side
  int window_max_features = 500;  // strongest keypoints kept in the crop (0 = all)
  // Tilted views of a recognised window where the view as seen finds nothing: the crop
  // stretched horizontally by sqrt(2)^k, k = 1..window_tilts (a landmark turned ~45 and ~60
  // degrees away, foreshortened by cos(yaw), seen at its face's proportions). Each view costs
  // one more recognition of the window. 0 = the window as seen only. Alone it also lets a
  // look-alike sibling through now and then; with tilt_confirm_frames (below) it does not.
  // Evidence for the default: doc/perception-benchmark.md, 'Tilted views with confirmation'.
  int window_tilts = 1;
  // A detection found only in a tilted view is reported when the same class was also detected
  // (as seen or tilted) in one of the previous tilt_confirm_frames observe() calls at a
  // consistent place (the two windows' centres less than the wider window's width apart);
  // else it is held back and only remembered. A stretched view lets a look-alike sibling
  // verify now and then; a landmark turned away verifies again frame after frame. 0 = a
  // tilted detection is reported at once.
  int tilt_confirm_frames = 2;
  // Threads a full pass uses for its independent stages: the objectness windows beside the
  // frame's features, then the windows' matching and the ranked windows' recognition taken item
  // by item by whichever thread is free. 1 = everything on the calling thread. The detections are
  // the same for any count (only the wall time changes); evidence: doc/perception-benchmark.md "Two
  // cores".
  int threads = 2;
  // The matching stage's rule ("landmarks.match.*", the same settings `recognise --match`
  // reads): Lowe's ratio, RANSAC, min_inliers for a detection (never a guess below), database
  // photos tried per window, the colour and distinct-inlier checks.
  landmarks::MatchParams match;
  TrackParams track;                         // "nav.perception.track.*" (detect, then track)
  landmarks::RecognitionParams recognition;  // "landmarks.recognition.*"
  landmarks::ObjectnessParams objectness;    // "objectness.*" (the windows proposed per frame)
  template <class B>
  void bind(B& b) {
    b("max_windows", max_windows);
    b("whole_frame", whole_frame);
    b("paper_offset", paper_offset);
    b("merge_iou", merge_iou);
    b("frame_max_side", frame_max_side);
    b("frame_max_features", frame_max_features);
    b("fovea", fovea);
    b("fovea_min_range_m", fovea_min_range_m);
    b("fovea_max_range_m", fovea_max_range_m);
    b("fovea_width", fovea_width);
    b("fovea_height", fovea_height);
    b("fovea_ref_range_m", fovea_ref_range_m);
    b("fovea_max_upscale", fovea_max_upscale);
    b("fovea_max_side", fovea_max_side);
    b("fovea_max_features", fovea_max_features);
    b("fovea_max_looks", fovea_max_looks);
    b("recognise_windows", recognise_windows);
    b("rank_by_votes", rank_by_votes);
    b("position_min_inliers", position_min_inliers);
    b("window_side", window_side);
    b("window_margin", window_margin);
    b("window_max_features", window_max_features);
    b("window_tilts", window_tilts);
    b("tilt_confirm_frames", tilt_confirm_frames);
    b("threads", threads);
  }
  void validate() const;  // InputError "nav.perception.<field> = ...: ..."
  /// Takes the camera's pan and tilt from the mount.
  void setCamera(const CameraMount& m) {
    camera_yaw = m.yaw;
    camera_pitch = m.pitch;
  }
};

/// The perception settings of a run or replay from `config`: "nav.perception.*", with its
/// matching rule from "landmarks.match.*", its recognition settings from "landmarks.recognition.*",
/// its tracking from "nav.perception.track.*" and its objectness from "objectness.*"; validated.
/// One assembly for `run`, `replay` and `replay --eval`.
PerceptionParams perceptionParamsFrom(const Config& config);

/// Objectness + RootSIFT matching on the landmark model; between full passes (every
/// track.redetect_frames calls) a detected landmark is followed by a KltTrack. Keeps a
/// reference to the model (shared ownership). Thread-compatible (one observe() at a time).
/// Stateful: consecutive observe() calls are taken as consecutive frames of one camera;
/// reset() between unrelated frames.
class LandmarkPerception final : public Perception {
 public:
  LandmarkPerception(std::shared_ptr<const landmarks::LandmarkModel> model,
                     PerceptionParams params = {});
  ~LandmarkPerception() override;
  Observation observe(const hw::Frame& frame, const hw::Intrinsics& k,
                      const std::vector<std::string>& classes) override;
  /// The normal pass for the hinted classes, then a foveal second look (PerceptionParams
  /// fovea_*) at each hinted class it missed.
  Observation observe(const hw::Frame& frame, const hw::Intrinsics& k,
                      const std::vector<LookFor>& look_for) override;
  void reset() override;

 private:
  Observation observeFrame(const hw::Frame& frame, const hw::Intrinsics& k,
                           const std::vector<std::string>& classes,
                           const std::vector<LookFor>* look_for);
  Observation fullPass(const hw::Frame& frame, const hw::Intrinsics& k,
                       const std::vector<std::string>& classes);
  void foveaPass(const hw::Frame& frame, const hw::Intrinsics& k,
                 const std::vector<LookFor>& look_for, Observation& ob);
  // Holds back the tilted detections of a full pass that no recent detection confirms
  // (PerceptionParams::tilt_confirm_frames) and remembers this pass's detections.
  void confirmTilted(Observation& ob);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sketchnav::nav
