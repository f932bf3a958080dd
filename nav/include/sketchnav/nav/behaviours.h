#pragma once
// The executive's behaviours: following the route (and looking towards an expected landmark
// on the way), looking to the side, the final look at the goal, docking, the stuck recovery,
// detours planned round what stands in the way, and giving way to walking people. Each has its own
// Params (keys directly under "nav.": ExecutiveParams derives from them) and reports what it did as
// an outcome — the command it proposes (CommandArbiter decides), the event to report — and never
// touches the devices, the run's status or the route.
#include <Eigen/Core>

#include <functional>
#include <map>
#include <optional>
#include <utility>
#include <vector>

#include "sketchnav/hw/types.h"
#include "sketchnav/nav/avoidance.h"
#include "sketchnav/nav/command_arbiter.h"
#include "sketchnav/nav/events.h"
#include "sketchnav/nav/landmark_tracker.h"
#include "sketchnav/nav/local_planner.h"
#include "sketchnav/nav/movers.h"
#include "sketchnav/nav/sections.h"

namespace sketchnav::nav {

/// How the robot heads for a bearing (following, looking, docking, detouring).
struct DriveParams {
  double v_cruise = 0.30;         // [m/s] forward speed along the route
  double k_heading = 1.2;         // [1/s] path following: yaw rate per rad of bearing error
  double max_w = 0.8;             // [rad/s]
  double turn_in_place_deg = 60;  // [deg] bearing error above which the robot turns on the spot
  template <class B>
  void bind(B& b) {
    b("v_cruise", v_cruise);
    b("k_heading", k_heading);
    b("max_w", max_w);
    b("turn_in_place_deg", turn_in_place_deg);
  }
  void validate() const;  // InputError "nav.<field> = ...: ..."
};

/// The turn a signed bearing or yaw rate stands for (|x| < 0.05: Straight).
servo::Turn turnOf(double x);
/// Heading for a robot-frame bearing [rad]: yaw rate proportional to it (clamped to max_w);
/// forward speed slowed by its cosine (times `scale`), and zero above turn_in_place_deg (turn
/// on the spot first). The command's turn is left Straight: callers say what it stands for.
Command headFor(double bearing, double scale, const DriveParams& p);

/// Looking for a landmark on the way: the camera sees +-30 deg and a 0.4 m sign is recognised
/// out to ~3 m, so a landmark sketched beside the path is only in view for a moment. While one
/// is expected within look_range_m and not yet seen, the heading is kept within
/// look_bearing_deg of where the sketch puts it (the robot turns towards it, as the paper's
/// robot does). It never turns back for one: beyond look_max_bearing_deg the landmark is left
/// to the miss test (a robot turning round for a landmark behind it livelocks against
/// obstacles).
struct LookParams {
  double look_range_m = 5.0;         // [m]
  double look_bearing_deg = 10;      // [deg]
  double look_max_bearing_deg = 60;  // [deg]
  template <class B>
  void bind(B& b) {
    b("look_range_m", look_range_m);
    b("look_bearing_deg", look_bearing_deg);
    b("look_max_bearing_deg", look_max_bearing_deg);
  }
  void validate() const;  // InputError "nav.<field> = ...: ..."
};

/// Following the route (pure pursuit on the look-ahead point), or looking (the same, with the
/// heading held towards an expected landmark not yet seen).
class FollowBehaviour {
 public:
  FollowBehaviour(DriveParams drive, LookParams look, double approach_m)
      : drive_(drive), look_(look), approach_m_(approach_m) {}
  struct Proposal {
    Behaviour behaviour = Behaviour::Follow;  // Follow, or Look when the heading was held
    double target_bearing = 0;                // [rad] robot frame: what it steers to
    Command command;
  };
  /// `lookahead_bearing` [rad]: the route's look-ahead point; `unseen`: where the sketch puts
  /// the attended landmark when it is pending (not being tracked), else null. A landmark
  /// within approach_m [m] is not looked for (it is being passed).
  Proposal propose(double lookahead_bearing, const Polar* unseen) const;

 private:
  DriveParams drive_;
  LookParams look_;
  double approach_m_;
};

/// Looking to the side: a landmark the look above cannot keep in view (the sketch puts it
/// beyond look_max_bearing_deg, or the robot is already abreast of it, or dodging turned it
/// away) would pass unseen. When the attended landmark has never been seen, its predicted
/// bearing (odometry + sketch) is outside the camera's field of view minus
/// side_look_margin_deg, and it is between side_look_min_range_m and side_look_range_m away,
/// the robot stops and turns on the spot towards it (events side_look_start / _end) until it
/// is recognised (the servo then takes over) or for at most side_look_s, then resumes
/// following. Once per landmark; none beyond side_look_max_bearing_deg (a landmark behind is
/// left to the miss test, as above). side_look_s = 0: off.
struct SideLookParams {
  double side_look_s = 4.0;                // [s] time budget per landmark
  double side_look_range_m = 4.0;          // [m] predicted range within which it is tried
  double side_look_min_range_m = 0.5;      // [m] closer than this its bearing means little
  double side_look_margin_deg = 5;         // [deg] inside the half field of view
  double side_look_max_bearing_deg = 110;  // [deg] angle budget: furthest the robot turns
  // Looks per landmark: a further one (while it is still never seen) only from a new viewpoint,
  // once the line of sight to it has turned side_look_rebearing_deg [deg] (odometry frame, so
  // turning on the spot does not count) since the last one started: a poster on a side wall is
  // seen at a grazing angle from afar and nearly face-on when the robot is abreast of it.
  // Evidence for the default: doc/experiments.md "Three side looks, the foveal look off".
  int side_look_max_looks = 3;
  double side_look_rebearing_deg = 25;
  // A look stands the robot still for up to side_look_s: none starts, and one under way gives
  // way, while a walking person (MoverTracker::walkers) is within side_look_walker_m [m] or the
  // robot is in a walker's lane (a person who keeps walking walks into a robot standing there;
  // at 0.5 m/s one covers 2 m in a look).
  double side_look_walker_m = 3.0;
  template <class B>
  void bind(B& b) {
    b("side_look_s", side_look_s);
    b("side_look_range_m", side_look_range_m);
    b("side_look_min_range_m", side_look_min_range_m);
    b("side_look_margin_deg", side_look_margin_deg);
    b("side_look_max_bearing_deg", side_look_max_bearing_deg);
    b("side_look_max_looks", side_look_max_looks);
    b("side_look_rebearing_deg", side_look_rebearing_deg);
    b("side_look_walker_m", side_look_walker_m);
  }
  void validate() const;  // InputError "nav.<field> = ...: ..."
};

class SideLook {
 public:
  /// `half_fov_rad`: the camera's half horizontal field of view (0 without a camera: then no
  /// look ever starts, see update()); `k_heading` [1/s], `max_w` [rad/s]: the turn.
  SideLook(SideLookParams p, double half_fov_rad, double k_heading, double max_w)
      : p_(p), half_fov_(half_fov_rad), k_heading_(k_heading), max_w_(max_w) {}

  struct Outcome {
    std::optional<event::SideLookStart> started;
    std::optional<event::SideLookEnd> ended;  // the stuck clock restarts (standing still to look
                                              // is not being stuck)
    std::optional<Command> command;           // a turn on the spot towards the landmark
  };
  /// One tick at `now` [s]. `a`: the first attended landmark (null when none). A look starts
  /// (when `can_look`: a camera) for a never-seen pending landmark predicted out of view, and
  /// ends when it is seen, is no longer the attended one, the final look runs, the budget is
  /// spent or it is beyond the angle budget. No look starts while `busy` (docking,
  /// recovering); while `give_way` (dodging something that comes towards the robot) the dodge
  /// drives, the clock still runs. `heading` [rad]: the robot's, odometry frame (the line of
  /// sight's direction there is heading + the predicted bearing).
  Outcome update(const LandmarkTracker& landmarks, const AttendedLandmark* a, double now,
                 bool can_look, bool busy, bool final_looking, bool give_way, double heading);
  bool active() const { return active_; }

 private:
  SideLookParams p_;
  double half_fov_, k_heading_, max_w_;
  bool active_ = false;
  int k_ = -1, i_ = -1;  // the landmark looked for
  double t0_ = 0;        // [s] since when
  struct Looked {
    int looks = 0;
    double sight = 0;  // [rad] line of sight (odometry frame) when the last look started
  };
  std::map<std::pair<int, int>, Looked> looked_;  // per landmark
};

/// At the goal, a landmark never seen (too far on the way, or out of view) that the sketch puts
/// within final_look_range_m: turn to it and look for up to final_look_s before arriving;
/// seen, it is passed and the refit moves the goal. The goal is often extrapolated metres past
/// the last landmark seen, and a missed last landmark was the commonest way to stop 0.5-0.8 m
/// short. 0 = off.
struct FinalLookParams {
  double final_look_range_m = 4.0;  // [m]
  double final_look_s = 5.0;        // [s]
  bool final_look_fovea = true;     // hand the expected bearing to perception (foveal look)
  template <class B>
  void bind(B& b) {
    b("final_look_range_m", final_look_range_m);
    b("final_look_s", final_look_s);
    b("final_look_fovea", final_look_fovea);
  }
  void validate() const;  // InputError "nav.<field> = ...: ..."
};

class FinalLook {
 public:
  /// `k_heading` [1/s]: the turn towards the landmark.
  FinalLook(FinalLookParams p, double k_heading) : p_(p), k_heading_(k_heading) {}

  /// Whether a look was started and is not over (the landmark it looks for: target()).
  bool underWay() const { return k_ >= 0 && !done_; }
  /// Over (ended, or nothing to look for): no look is started again.
  bool done() const { return done_; }
  /// Whether (k, i) is the landmark of a look under way (kept out of the normal attention).
  bool isTarget(int k, int i) const { return !done_ && k == k_ && i == i_; }
  std::pair<int, int> target() const { return {k_, i_}; }

  /// How a look ended, for the landmark looked for.
  enum class Verdict {
    None,  // not ended this call
    Pass,  // it was seen: pass it (the fix moves the goal)
    Miss,  // never seen: miss it (counts towards "lost")
    Kept,  // never seen, and it had been missed on the way: missed as it was (counted then;
           // this call has restored its state)
  };
  struct Outcome {
    bool looking = false;  // the look goes on: hold the route open and turn
    std::optional<event::FinalLookStart> started;
    std::optional<event::FinalLookEnd> ended;
    Verdict verdict = Verdict::None;
  };
  /// One tick at `now` [s], at the goal (or with a look under way). The first call chooses the
  /// landmark (LandmarkTracker::finalLookCandidate: never seen, nearest within
  /// final_look_range_m, `route` as placed now) and sets a missed one pending again; the look
  /// ends when it has been seen on 3 frames (or passed) or after final_look_s. Nothing once
  /// done(), after the route is finished, or with final_look_range_m = 0.
  Outcome step(LandmarkTracker& landmarks, const SectionTracker& route, const hw::Pose2D& pose,
               double now);
  /// The turn on the spot towards robot-frame bearing `bearing` [rad] of the landmark (none
  /// within 0.1 rad of it); the arbiter's result is clamped to max_w by the executive.
  Command command(double bearing) const;

 private:
  FinalLookParams p_;
  double k_heading_;
  int k_ = -1, i_ = -1;
  double t0_ = 0;
  bool was_missed_ = false, done_ = false;
};

/// Stuck recovery: the reactive layers can livelock (boxed in between furniture, the route
/// behind an obstacle the dodge went round the wrong way), turning on the spot. Not having moved
/// stuck_m in stuck_s (ProgressChecker), the robot drives recover_m towards the most open
/// direction (ties to the route side), then resumes.
struct RecoverParams {
  double stuck_s = 10;     // [s] not having moved stuck_m in this long (not docking): stuck
  double stuck_m = 0.3;    // [m]
  double recover_m = 1.0;  // [m] then drive this far towards the most open direction
  double recover_s = 8;    // [s] (at most this long) and resume
  // With no direction known free but one only unseen (the laser's blind back sector), turn on
  // the spot to face it first, then choose again. Off by default: turning round towards a
  // person waiting at the robot's back is what makes them walk on into it (doc/navigation.md
  // "Evidence for the defaults").
  bool recover_look = false;
  // With no direction known free at all (wedged: the laser sees no way forward or to the sides
  // and nothing behind), back out this far [m] along the robot's own trail (the floor its body
  // just crossed, Trail below), straight back, at recover_back_speed [m/s]; then choose again
  // with room to turn. 0 = never back out (the robot stands until the run ends).
  double recover_back_m = 0.5;
  double recover_back_speed = 0.1;  // [m/s] slow: the laser does not see behind the robot
  template <class B>
  void bind(B& b) {
    b("stuck_s", stuck_s);
    b("stuck_m", stuck_m);
    b("recover_m", recover_m);
    b("recover_s", recover_s);
    b("recover_look", recover_look);
    b("recover_back_m", recover_back_m);
    b("recover_back_speed", recover_back_speed);
  }
  void validate() const;  // InputError "nav.<field> = ...: ..."
};

/// Docking: close to the goal with a free straight line to it, the robot drives there
/// directly. The goal is a place, often near a wall or in a doorway, where the avoider would
/// keep dodging the wall behind it. Without a free straight line (a goal in a doorway: the line
/// grazes the door frame), a short way round planned on the grid leads there, or as near as the
/// robot fits; a long one means the goal estimate sits behind a wall, and there is no docking.
struct DockParams {
  double dock_m = 1.5;  // [m] this close to the goal, with a free line to it, drive straight there
  template <class B>
  void bind(B& b) {
    b("dock_m", dock_m);
  }
  void validate() const;  // InputError "nav.dock_m = ...: ..."
};

class Docking {
 public:
  explicit Docking(DockParams p) : p_(p) {}
  /// Within dock_m [m] of the goal along the route (`to_end_m`, on the last section).
  bool near(double to_end_m) const { return to_end_m <= p_.dock_m; }

  /// A way round to the goal planned on the grid: the bearing [rad, robot frame] to steer to,
  /// its whole length [m] and what is left of it from the robot [m].
  struct WayRound {
    double bearing = 0, length_m = 0, left_m = 0;
  };
  struct Proposal {
    double bearing = 0;  // [rad] robot frame: what it steers to
    Command command;     // slowed in the last 0.6 m; turn = the bearing's side
  };
  /// `goal`: the goal from the robot; `free_m` [m]: how far the corridor towards it is free;
  /// `plan`: plans a way round when the line is not free (null: no planning; it is called only
  /// then). None: no docking this tick.
  std::optional<Proposal> propose(const Polar& goal, double free_m,
                                  const std::function<std::optional<WayRound>()>& plan,
                                  const DriveParams& drive) const;

 private:
  DockParams p_;
};

class Recovery {
 public:
  /// `k_heading` [1/s] (the avoider's), `max_w` [rad/s]: the turn to the escape heading.
  Recovery(RecoverParams p, double k_heading, double max_w)
      : p_(p), k_heading_(k_heading), max_w_(max_w) {}

  /// The most open direction [rad, robot frame] from the range points `pts` (robot frame): of
  /// 36 directions, the one whose corridor of half-width `half_width_m` is free furthest (up to
  /// recover_m + 0.5, at least 0.5 m; `max_range_m`: the corridor test's reach; only points
  /// ahead of the robot's centre along it count), less 0.3 per rad away from `route_bearing`.
  /// None when no direction is free for 0.5 m.
  /// `known_free` (when given): whether the robot's disc swept a length [m] along a
  /// direction [rad, robot frame] lies on floor a laser scan saw free; directions where it does
  /// not for 0.5 m are not taken. The laser does not see behind the robot, where a direction
  /// without range points is not free, only unknown (a person waiting at the robot's back).
  std::optional<double> openDirection(
      const std::vector<std::pair<double, double>>& pts, double half_width_m, double max_range_m,
      double route_bearing,
      const std::function<bool(double direction, double len)>& known_free = {}) const;
  /// Starts driving towards robot-frame `direction` [rad] from `pose` at `now` [s]; with
  /// `look`, only turns to face it (the direction's floor unseen: openDirection found none
  /// known free, but one that is only unknown), and ends facing it, for the next stuck test to
  /// choose again with the laser's view of it.
  event::RecoverStart start(double direction, const hw::Pose2D& pose, double now,
                            bool look = false);
  /// Starts backing out from `pose` to `to` (odometry frame; a point of the robot's trail,
  /// Trail::backOut) at recover_back_speed, keeping the heading that points away from it; over
  /// when there (within 5 cm), after recover_s, or when the point is no longer behind.
  event::RecoverStart startBack(const Eigen::Vector2d& to, const hw::Pose2D& pose, double now);
  /// Whether the recovery under way (or the last one) backs out.
  bool backing() const { return back_; }
  /// Whether the recovery under way (or the last one) only turns to look.
  bool looking() const { return look_; }
  bool active() const { return active_; }
  int count() const { return count_; }
  /// Ends the recovery under way (it gives way: a walker's lane covers the robot).
  void stop() { active_ = false; }

  struct Step {
    Command command;
    bool ended = false;  // driven recover_m, out of time, or blocked: over (report RecoverEnd)
  };
  /// One tick while active(): turn to the escape heading, then drive at `v_capped` [m/s] (the
  /// recovery speed already capped by the clearance ahead). Ends it when over.
  Step step(const hw::Pose2D& pose, double now, double v_capped);

 private:
  RecoverParams p_;
  double k_heading_, max_w_;
  bool active_ = false;
  bool look_ = false;
  bool back_ = false;
  int count_ = 0;
  double dir_ = 0, t0_ = 0;  // escape heading (odometry frame), start time
  hw::Pose2D from_;
  Eigen::Vector2d to_ = Eigen::Vector2d::Zero();  // backing out: where to (odometry frame)
};

/// The robot's own recent path: odometry positions at least spacing_m apart, the last keep_m
/// [m] of it. The floor the robot's body has just crossed held nothing that stands still, and
/// it is where the laser, blind behind the robot, cannot look: backing out along it is the way
/// out of a spot with no way forward (Recovery::startBack).
class Trail {
 public:
  explicit Trail(double keep_m = 3.0, double spacing_m = 0.05)
      : keep_m_(keep_m), spacing_m_(spacing_m) {}
  /// The robot is at `p` [m, odometry frame].
  void add(const Eigen::Vector2d& p);
  void clear() { pts_.clear(); }
  /// The robot backed out to `p`: the trail after the point nearest to it is dropped.
  void backTo(const Eigen::Vector2d& p);
  /// The trail point `len_m` [m] back along the path from the robot at `from`, when every
  /// trail point up to it lies within `tolerance_m` [m] of the straight line from `from` to it
  /// (the robot backing straight there stays on the floor it came over). None when the trail
  /// is shorter than `len_m` or bends away.
  std::optional<Eigen::Vector2d> backOut(const Eigen::Vector2d& from, double len_m,
                                         double tolerance_m) const;

 private:
  double keep_m_, spacing_m_;
  std::vector<Eigen::Vector2d> pts_;  // oldest first
};

/// Detours (local_planner.h): while the avoider dodges something that is not coming towards
/// the robot, the robot follows a path planned on the laser's occupancy grid to the route
/// point detour_ahead_m on, instead of the reactive dodge; and near the goal, with no free
/// straight line to it, a path to the goal (Docking). Replanned every replan_s.
struct DetourParams {
  bool detour = true;
  double detour_ahead_m = 3.0;  // [m]
  // A detour once started is followed until the straight line to that route point is clear
  // on the grid (or no way is found, someone comes towards the robot, or the servo takes
  // over), not only while the reactive avoider is dodging: the avoider lets go when the
  // corridor towards the route is free avoid.release_m ahead, which round a box or a door
  // frame comes before the robot is past it. false = ends with the avoider's manoeuvre.
  // Off by default: doc/navigation.md "Evidence for the defaults".
  bool detour_hold = false;
  double replan_s = 0.5;  // [s]
  template <class B>
  void bind(B& b) {
    b("detour", detour);
    b("detour_ahead_m", detour_ahead_m);
    b("detour_hold", detour_hold);
    b("replan_s", replan_s);
  }
  void validate() const;  // InputError "nav.<field> = ...: ..."
};

class Detour {
 public:
  /// `drive`: how the path's carrot is headed for.
  Detour(DetourParams p, DriveParams drive) : p_(p), drive_(drive) {}

  /// Bearing [rad, robot frame] of the carrot on a path planned on `planner`'s grid from
  /// `pose` to `goal` (odometry frame), replanned every replan_s or when the goal moved by
  /// more than 0.3 m since the last plan (`now` [s]); NaN when there is no way there.
  double planTowards(const LocalPlanner& planner, const hw::Pose2D& pose,
                     const Eigen::Vector2d& goal, double now);
  /// The path planned last (a detour's or docking's way round).
  const PlannedPath& path() const { return path_; }
  /// A detour is being followed.
  bool active() const { return active_; }
  /// The current avoidance manoeuvre has seen something come towards the robot (then it is
  /// left to the reactive dodge until the manoeuvre ends).
  bool movingSeen() const { return moving_seen_; }
  int count() const { return count_; }  // detours started
  /// Ends the detour under way, for `reason` (event::DetourEnd); none when none is.
  std::optional<event::DetourEnd> end(const char* reason);

  struct Outcome {
    std::optional<Command> command;  // the detour drives (Behaviour::Detour); none: it does not
    std::optional<event::DetourStart> started;
    std::optional<event::DetourEnd> ended;
  };
  /// One tick while the avoider dodges (`av`: its step this tick). Something standing still
  /// is gone round on a path planned to `route_point` (the route point detour_ahead_m on);
  /// once something has come towards the robot in the manoeuvre (approach_speed >= 0.25 m/s,
  /// or a walker's lane: a path planned through the grid's picture of a person led a robot
  /// into them) the reactive dodge drives until the manoeuvre ends. `section`: for the event;
  /// `cap`: the forward speed allowed by the clearance ahead (ObstacleAvoider::capSpeed).
  Outcome whileDodging(const AvoidOutput& av, const LocalPlanner& planner, const hw::Pose2D& pose,
                       const Eigen::Vector2d& route_point, double now, int section,
                       const std::function<double(double)>& cap);
  /// One tick while the avoider does not dodge. With detour_hold a detour under way is
  /// followed (command) until the straight line from the robot to `route_point` keeps
  /// `half_width_m` [m] clear on the grid, no way is found, or `servoing`; without it,
  /// servoing ends it.
  Outcome afterDodge(const LocalPlanner& planner, const hw::Pose2D& pose,
                     const Eigen::Vector2d& route_point, double now, bool servoing,
                     double half_width_m, const std::function<double(double)>& cap);

 private:
  Command follow(double bearing, const std::function<double(double)>& cap) const;
  DetourParams p_;
  DriveParams drive_;
  PlannedPath path_;
  double planned_t_ = -1e300;                 // [s] when path_ was planned
  Eigen::Vector2d planned_to_{1e300, 1e300};  // and to where (odometry frame)
  bool active_ = false, moving_seen_ = false;
  int count_ = 0;
};

/// Giving way to walking people (MoverTracker::advise, or holdShortOfWalkerLanes with lane
/// keeping off): about to enter a walker's lane, the robot waits (the command's turn kept);
/// in one, it steps out as advised, backing only with room behind it.
class YieldBehaviour {
 public:
  /// `reverse_speed` [m/s]: backing out of a lane.
  explicit YieldBehaviour(double reverse_speed) : reverse_speed_(reverse_speed) {}
  struct Outcome {
    std::optional<Command> command;  // replaces the one that would drive (Behaviour::Yield)
    std::optional<event::YieldStart> started;
    std::optional<event::YieldEnd> ended;
  };
  /// One tick: `adv` the advice for `cur` (the command that would drive otherwise) at `pose`;
  /// `cap`: the forward speed allowed by the clearance ahead; `rear_free_m`: the free length
  /// [m] of the corridor behind the robot (asked only when the advice is to back; it backs
  /// only with more than kRearRoomM of it).
  Outcome update(const YieldAdvice& adv, const Command& cur, const hw::Pose2D& pose,
                 const std::function<double(double)>& cap,
                 const std::function<double()>& rear_free_m);
  bool active() const { return active_; }
  int count() const { return count_; }
  static constexpr double kRearRoomM = 0.5;  // [m]

 private:
  double reverse_speed_;
  bool active_ = false;
  int count_ = 0;
};

}  // namespace sketchnav::nav
