#pragma once
// The perception benchmark of the real task (issue 23 item 4, doc/perception-benchmark.md):
// a seeded generator of image sequences in which a product photo the model was not trained on
// is a planar poster in a real background photo, seen through a pinhole camera that pans
// across it or approaches it; the truth CSV `frame,expected` and the sidecar sequence.json it
// writes; the truth-CSV parser `replay --truth` uses; and the per-frame scoring and
// aggregation (agreement, found rate per yaw / width bin, false reports, bearing error, time)
// that `replay --truth` and `replay --eval` report.
#include <opencv2/core.hpp>

#include <array>
#include <map>
#include <string>
#include <vector>

#include "sketchnav/core/config.h"
#include "sketchnav/servo/turn_law.h"

namespace sketchnav::app::bench {

// ---- geometry ---------------------------------------------------------------------------

/// Pinhole camera in the generator's world (x right, y down, z ahead; metres): centre `pos`,
/// panned by `pan` [rad] about the vertical axis (pan > 0 looks to the right, +x).
struct PinholeCamera {
  double f = 554.0;               // [px] focal length (fx = fy)
  double cx = 320.0, cy = 240.0;  // [px] principal point
  cv::Point3d pos{0, 0, 0};
  double pan = 0;
  /// World point -> pixel; false when it is behind the camera (z <= 1 cm).
  bool project(const cv::Point3d& X, cv::Point2d& uv) const;
};

/// A planar rectangular poster: centre, size [m], and its yaw [rad] about the vertical axis
/// (yaw 0: its face looks down -z, towards a camera at the origin).
struct Poster {
  cv::Point3d centre{0, 0, 2};
  double width_m = 0.3, height_m = 0.3;
  double yaw = 0;
  /// Corners in the photo's order: top-left, top-right, bottom-right, bottom-left (world).
  std::array<cv::Point3d, 4> corners() const;
  /// Outward unit normal (towards the side the photo is seen from).
  cv::Point3d normal() const;
};

/// What one camera sees of one poster.
struct PosterView {
  bool valid = false;                 // all four corners in front of the camera
  std::array<cv::Point2d, 4> quad{};  // corners in the frame [px]
  cv::Mat H;                          // 3x3 CV_64F: photo pixel -> frame pixel
  cv::Point2d centre{NAN, NAN};       // the poster's centre in the frame [px] (= H * photo centre)
  double width_px = 0;                // horizontal extent of the quad [px]
  double yaw_deg = 0;  // angle between the poster's normal and the line to the camera
};

/// Projects `poster` (showing a photo of `photo` pixels) into `cam`.
PosterView viewPoster(const PinholeCamera& cam, const Poster& poster, cv::Size photo);

/// Pastes `img` warped by H (img pixel -> frame pixel) over `frame` (bilinear; the warped
/// image's coverage is the alpha, so the poster's edges are anti-aliased).
void pasteWarped(cv::Mat& frame, const cv::Mat& img, const cv::Mat& H);

// ---- generator ---------------------------------------------------------------------------

/// The two disjoint halves of the benchmark (doc/perception-benchmark.md "Held-out rule").
enum class Split { Dev, HeldOut };
Split parseSplit(const std::string& s);  // "dev" | "heldout"; InputError otherwise
const char* toString(Split s);

struct GeneratorOptions {
  std::string data_dir;  // the shared data folder (grocery-packages/, raccoon/, voc07-mini/)
  std::string out_dir;   // one sub-folder per sequence is written here
  Split split = Split::Dev;
  int seed = 1;                      // first sequence's seed; sequence i uses seed + i
  int present = 12;                  // sequences with the target (half panning, half approaching)
  int absent = 4;                    // sequences with another product instead (often a sibling)
  int frames = 20;                   // frames per sequence
  std::vector<std::string> classes;  // restrict targets to these classes (empty: all)
  int width = 640, height = 480;     // frame size [px]
  double hfov_deg = 60;              // horizontal field of view (replay's default)
  servo::TurnLawParams servo;        // the servo law (and dead band) that turns truth into L/S/R
};

/// Writes the sequences; returns their folder names. Each folder holds frameNNN.jpg,
/// truth.csv ("frame,expected", expected L/S/R or '-') and sequence.json (per-frame truth).
std::vector<std::string> makeSequences(const GeneratorOptions& opt);

// ---- truth --------------------------------------------------------------------------------

/// One row of a truth CSV. expected: "Left", "Straight", "Right", "None" (no landmark may be
/// reported: scored) or "" for '-' (unscored).
struct TruthRow {
  std::string frame;
  std::string expected;
};

/// Reads "frame,expected" (frame = index from 0 or file name; expected L/S/R, Left/Straight/
/// Right, None, or '-' = unscored). A header line "frame,expected" and '#' comments are allowed.
/// Throws InputError "FILE:LINE: reason" for a malformed row, a duplicate frame or no rows.
std::map<std::string, std::string> readTruthCsv(const std::string& path);

/// Per-frame truth from a sequence.json sidecar, by frame file name.
struct FrameTruth {
  bool target_present = false;  // the target's photo is in the frame at all
  double visible = 0;           // share of the poster inside the frame and not occluded
  double u = NAN;               // true centre column [px]
  double yaw_deg = NAN, width_px = NAN;
  bool scored = false;
};
struct SequenceTruth {
  std::string target;   // the class replay must look for
  std::string shown;    // the class whose photo is pasted (== target unless absent)
  bool absent = false;  // a target-absent sequence
  std::string motion;   // "pan" | "approach"
  std::string photo;    // the pasted photo, relative to the data folder ("" when not recorded)
  std::map<std::string, FrameTruth> frames;
};
SequenceTruth readSequenceJson(const std::string& path);

// ---- scoring ------------------------------------------------------------------------------

/// What replay did on one frame, and the truth for it.
struct FrameScore {
  std::string expected;  // "" unscored
  std::string got;       // Left / Straight / Right / None
  bool found = false;    // the target class was reported
  double u_found = NAN;  // reported object centre column [px]
  double ms = 0;
  // The full pass's stages [ms, wall] (nav::PerceptionTiming); full_pass false: the frame was
  // served by the tracker alone and the stages are 0.
  bool full_pass = false;
  double objectness_ms = 0, features_ms = 0, match_ms = 0, recognise_ms = 0, fovea_ms = 0;
  bool has_truth_json = false;
  FrameTruth truth;
  bool absent_sequence = false;
};

/// Yaw bins [deg] and width bins [px] of the report.
extern const std::vector<double> kYawBins;    // edges 0,15,30,45,60
extern const std::vector<double> kWidthBins;  // edges 60,100,150,300

/// The report over any set of frames: agreement on scored frames, found rate (overall and per
/// bin, on scored frames), false reports (target reported on frames of target-absent
/// sequences, or on '-' frames without a sidecar), bearing error |u_found - u| [px] on scored
/// frames where the target was found, time per frame, and (`full_pass_ms`) the full passes'
/// time with the median and p95 of each stage (the tracked frames' time beside it).
Json summarise(const std::vector<FrameScore>& frames);

/// PNG: found rate and agreement against yaw and against width (two panels side by side).
void writeBinPlot(const Json& summary, const std::string& title, const std::string& path);

}  // namespace sketchnav::app::bench
