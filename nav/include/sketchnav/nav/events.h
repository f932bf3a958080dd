#pragma once
// What the executive reports while it runs: typed events (NavEvent, one struct per kind), the
// driving mode of a tick (Mode) and why a run failed (FailureCode, with the reason text beside
// it). NavEvent::toJson() is the one place events become JSON: it writes the `events.jsonl`
// lines the run page (share/web/run.js), old run folders and offline tools read, so a field's
// name, type and presence are part of that format (doc/navigation.md, "Events").
//
// Frames: "*_odom" points are in the odometry frame [m] (x, y), "pose_odom" is (x, y, theta
// [rad]); bearings are robot-frame [deg], positive to the left.
#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <array>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "sketchnav/hw/types.h"
#include "sketchnav/nav/avoidance.h"

namespace sketchnav::nav {

/// What drove the robot in one control tick (TelemetryRow::mode), by precedence: the last one
/// that applies wins, in the order the executive applies them.
enum class Mode {
  Follow,   // along the route (lookahead point)
  Look,     // heading held towards an expected landmark, or turning on the spot to look for one
            // (to the side on the way, or at the goal)
  Servo,    // visual servo on a tracked landmark (servo::TurnLaw)
  Dock,     // the last metres to the goal, straight or on a short planned path
  Recover,  // stuck: driving clear towards the most open direction
  Avoid,    // reactive obstacle dodge (ObstacleAvoider)
  Detour,   // following a path planned round an obstacle (LocalPlanner)
  Yield,    // keeping out of a walking person's lane (MoverTracker)
};
/// "follow", "look", "servo", "dock", "recover", "avoid", "detour", "yield".
const char* toString(Mode m);

/// Why a run ended Failed (ExecutiveSummary::failure); None while running or after success.
enum class FailureCode {
  None,
  SafetyStop,  // a device fault (stale sensor, base not ok) or an exception in the tick
  Timeout,     // ExecutiveParams::max_time_s exceeded
  NoProgress,  // a section took longer than its time budget
  Lost,        // more than max_missed_in_row landmarks in a row not found
  Stopped,     // Executive::stop() (e.g. the user pressed Stop)
};
/// "", "safety_stop", "timeout", "no_progress", "lost", "stopped".
const char* toString(FailureCode c);

namespace event {

struct Start {
  int sections = 0;
  double route_length_m = 0;
};
struct Arrived {
  std::string reason;
};
/// The run failed. `code` is not written to events.jsonl (the line's format predates it);
/// it reaches summary.json through ExecutiveSummary::failure.
struct Failed {
  FailureCode code = FailureCode::None;
  std::string reason;
};
struct Fault {
  std::string fault;  // toString(safety Fault), or "exception"
  std::string reason;
};
struct LandmarkSeen {  // first recognised (again) after pending
  std::string id, class_name;
  int section = 0;
  int inliers = 0;
  double bearing_deg = 0, range_m = 0;  // range 0 = none usable
  double predicted_bearing_deg = 0, predicted_range_m = 0;
  bool range_dropped = false;  // measured range disagreed with the expected one
  std::size_t candidates = 0;  // detections of its class that could have been it
  bool attended_first = false;
};
struct LandmarkLost {  // tracked, unseen for lost_after_s, not at it: pending again
  std::string id;
  int section = 0;
};
struct LandmarkMissed {
  std::string id, class_name;
  int section = 0;
  bool seen_before = false;
};
/// A landmark passed, with the fix it gave and what the route did with it (when located).
// The parts of a LandmarkPassed event's fix. They are declared outside LandmarkPassed so that
// they are complete types where std::optional asks whether they are default-constructible
// (clang rejects optional<Nested>::emplace() for a nested struct with member initialisers).
struct PassedRefit {  // least-squares refit of the route (SectionTracker::fitSimilarity*)
  double rotation_deg = 0, scale = 1, rms_m = 0;
  std::size_t fixes = 0;
  int dropped = 0;
};
struct PassedRealign {  // before enough fixes: rotate about the previous fix, then shift
  double realign_deg = 0, reanchor_m = 0;
};
struct PassedFix {
  std::string method;  // "ranges", "bearings", "bearing only"
  int rays = 0, ranges_used = 0, height_ranges = 0, ranges_dropped = 0;
  double height_sigma_m = 0;  // written only when height_ranges > 0
  int gated_ranges = 0;       // laser ranges the sketch's gate refused, taken back
  // Sightings (origin x, y [m], direction [rad], range [m]), odometry frame, unrounded.
  std::vector<std::array<double, 4>> sightings;
  std::optional<PassedRefit> fit;  // one of fit / realign
  std::optional<PassedRealign> realign;
  double disagreement_m = 0;                // route's landmark to the fix, before correcting
  Eigen::Vector2d route{0, 0}, odom{0, 0};  // the sketch's point and the located one
};
struct LandmarkPassed {
  using Refit = PassedRefit;
  using Realign = PassedRealign;
  using Fix = PassedFix;
  std::string id, class_name;
  int section = 0;
  double range_m = 0;  // last measured range
  int frames_seen = 0;
  bool in_view = false;  // passed while servoed in view (else: slid out of view, or behind)
  std::optional<std::string> fix_rejected;  // why the fix was not used
  std::optional<Fix> fix;
};
struct SectionDone {
  int section = 0, of = 0;
  Eigen::Vector2d end_odom{0, 0};  // where the (re-anchored) route put the section's end
  hw::Pose2D pose_odom;
};
struct AvoidStart {
  DodgeSide side = DodgeSide::None;
  double original_heading_deg = 0, front_free_m = 0;
  int section = 0;
};
struct AvoidEnd {
  DodgeSide side = DodgeSide::None;
  bool docking = false;  // ended because docking took over (written only when true)
};
struct WalkerLane {
  Eigen::Vector2d walker_odom{0, 0}, walker_velocity{0, 0};  // [m], [m/s]
  int section = 0;
};
struct DetourStart {
  double length_m = 0;
  Eigen::Vector2d goal_odom{0, 0};
  bool goal_moved = false;
  int section = 0;
};
struct DetourEnd {
  std::string reason;  // route clear | no way found | coming towards the robot | servoing |
                       // docking | recovering | avoid ended | no range data
};
struct RecoverStart {
  double direction_deg = 0;  // robot frame
  // Only turning to face the direction: its floor is out of the laser's view (the blind back
  // sector), to be seen before it is driven over.
  bool look = false;
  // Backing out along the robot's trail (Recovery::startBack; direction_deg: where to, ~180).
  bool back = false;
};
struct RecoverEnd {};
struct GoalSettled {
  double to_end_m = 0;
};
struct EndBlocked {
  int section = 0;
  double to_end_m = 0;
};
/// A section ended where the robot came closest to its end point (SectionSettleChecker).
struct SectionSettled {
  int section = 0;
  double to_end_m = 0;  // [m] when it ended
};
struct YieldStart {
  bool in_lane = false;
  double clearance_m = 0;
  Eigen::Vector2d mover_odom{0, 0}, mover_velocity{0, 0};
  hw::Pose2D pose_odom;
};
struct YieldEnd {};
struct GoalDoor {
  Eigen::Vector2d centre_odom{0, 0};
  double width_m = 0;
  Eigen::Vector2d goal_odom{0, 0};
  double moved_m = 0, standoff_m = 0;
  int sightings = 0;
};
struct FinalLookStart {
  std::string id;
  double range_m = 0;
};
struct FinalLookEnd {
  std::string id;
  bool seen = false;
};
/// Turning on the spot to look for the attended landmark, never seen, that the sketch puts
/// outside the camera's view (SideLookParams, behaviours.h).
struct SideLookStart {
  std::string id;
  int section = 0;
  double bearing_deg = 0, range_m = 0;  // where the sketch puts it when the look starts
};
struct SideLookEnd {
  std::string id;
  bool seen = false;      // recognised during the look
  double duration_s = 0;  // [s]
};

}  // namespace event

using EventData =
    std::variant<event::Start, event::Arrived, event::Failed, event::Fault, event::LandmarkSeen,
                 event::LandmarkLost, event::LandmarkMissed, event::LandmarkPassed,
                 event::SectionDone, event::AvoidStart, event::AvoidEnd, event::WalkerLane,
                 event::DetourStart, event::DetourEnd, event::RecoverStart, event::RecoverEnd,
                 event::GoalSettled, event::EndBlocked, event::SectionSettled, event::YieldStart,
                 event::YieldEnd, event::GoalDoor, event::FinalLookStart, event::FinalLookEnd,
                 event::SideLookStart, event::SideLookEnd>;

/// One event: when [s, run clock, from start()] and what.
struct NavEvent {
  double t = 0;
  EventData data;

  /// The `type` string of the JSON line ("start", "landmark_seen", ...).
  const char* type() const;
  /// The events.jsonl object: {"type": type(), "t": t, ...fields} (keys sorted).
  nlohmann::json toJson() const;
  template <class T>
  const T* as() const {
    return std::get_if<T>(&data);
  }
  template <class T>
  bool is() const {
    return std::holds_alternative<T>(data);
  }
};

}  // namespace sketchnav::nav
