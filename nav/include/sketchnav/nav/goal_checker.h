#pragma once
// Whether the robot has reached its goal by its own estimate (the role of Nav2's
// nav2_core::GoalChecker), consulted before the failure rules that judge the way there: a run
// that stands at its goal is not failed for how it got there.
#include <deque>
#include <utility>

#include "sketchnav/hw/types.h"
#include "sketchnav/nav/events.h"
#include "sketchnav/nav/sections.h"

namespace sketchnav::nav {

class GoalChecker {
 public:
  /// `radius_m` [m]: how close to the route's end counts as there (SectionParams::goal_radius_m).
  explicit GoalChecker(double radius_m) : radius_m_(radius_m) {}

  /// The route is finished, or `odom` is on its last section within radius_m of the end (the
  /// end as the tracker has it now: refitted, or moved to a goal doorway).
  bool reached(const SectionTracker& route, const hw::Pose2D& odom) const;

  /// Whether reaching the goal overrules a failure rule with this code: Lost ("N landmarks in a
  /// row not found", e.g. the final look's landmark not found at the goal) does; a safety stop,
  /// the run's timeout, a stop by the user and NoProgress (a robot at the goal that no longer
  /// gets closer ends by goal_settled first) do not.
  static bool overrules(FailureCode code);

 private:
  double radius_m_;
};

/// Near the goal but no longer getting closer (the estimate sits where the robot cannot stand,
/// e.g. against a door frame): arrived as close as it can get. Settled when, within near_m
/// [m] of the goal on the last section, the distance has not dropped by min_gain_m [m] below
/// the closest so far for settle_s [s] (ExecutiveParams::goal_settle_m, goal_settle_s).
class SettleChecker {
 public:
  SettleChecker(double near_m, double settle_s, double min_gain_m = 0.05)
      : near_m_(near_m), settle_s_(settle_s), min_gain_m_(min_gain_m) {}
  /// One tick at `now` [s]: whether the robot is on the last section, its distance to the
  /// goal [m], and `restart` (closeness is not being judged now: the final look turns on the
  /// spot by design, and the landmark it finds moves the goal; the clock starts again).
  /// Returns whether it has settled.
  bool update(bool last_section, double to_end_m, double now, bool restart);

 private:
  double near_m_, settle_s_, min_gain_m_;
  double best_m_ = 1e300, best_t_ = 0;  // closest to the goal so far, and when
};

/// An intermediate section's end that the robot cannot get near: the sketch drew the corner
/// beyond a wall (a corridor's turn drawn too early or too late, a drawing rotated by a few
/// degrees puts a corner metres off after ten metres of route). The avoider then keeps the
/// robot off the wall and, with nothing else to aim for, drives it back and forth along the
/// corridor until the section's time runs out ("no progress"). Settled, i.e. as close as it
/// gets, when the robot is within near_m of the end point (the larger of min_near_m and
/// near_frac x the section's length), has not come min_gain_m closer than its closest since
/// the section began for settle_s, and is not closing in now (not min_gain_m closer than
/// closing_s ago). Leaving and coming back does not restart the clock (that is the
/// back-and-forth); a hold does (servoing on a landmark, looking to the side, waiting for a
/// person: not being stuck). Never within min_near_m of the end, and never on a section whose
/// end the robot has been within min_near_m of: there the end is in the range sensors' view
/// (the end_blocked_m rule judges it) and reachable. Lab trials of a first version without
/// these limits ended sections the robot was about to reach: one a servo had led away and that
/// was driving back, one 0.6 m from the end while dodging round something there, one 1.0 m
/// from an end it had been 0.4 m from before its landmark's servo led it off (exp2-redrawn-c,
/// which then lost room B's landmarks). ExecutiveParams::section_settle_frac,
/// section_settle_s, end_blocked_m.
class SectionSettleChecker {
 public:
  SectionSettleChecker(double near_frac, double min_near_m, double settle_s,
                       double min_gain_m = 0.05, double closing_s = 3.0)
      : near_frac_(near_frac),
        min_near_m_(min_near_m),
        settle_s_(settle_s),
        min_gain_m_(min_gain_m),
        closing_s_(closing_s) {}
  /// A new section begins at `now` [s].
  void restart(double now);
  /// One tick at `now` [s] on a section of `length_m` [m], `to_end_m` [m] from its end point;
  /// `hold`: the clock starts again. Returns whether the robot is as close as it gets.
  /// Never settles when near_frac is 0 (off).
  bool update(double length_m, double to_end_m, double now, bool hold);
  /// The radius [m] within which (and beyond min_near_m) a section of `length_m` can settle.
  double nearM(double length_m) const;

 private:
  double near_frac_, min_near_m_, settle_s_, min_gain_m_, closing_s_;
  double best_m_ = 1e300, best_t_ = 0;  // closest to the end since the section began, and when
  std::deque<std::pair<double, double>> recent_;  // (t [s], to_end [m]) over the last closing_s
};

}  // namespace sketchnav::nav
