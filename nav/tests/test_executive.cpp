// The executive in closed loop on fake devices (a unicycle on a SimClock, a laser over
// discs, a geometric test-only perception): reaches the end with landmarks, without one,
// fails "lost" when landmarks keep missing, avoids a disc on the path, turns to look for a
// landmark the sketch puts to the side (within its budget), and stops within 200 ms on a
// dropped camera, a lost link or an exception.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "fake_world.h"
#include "route_util.h"
#include "sketchnav/nav/executive.h"
#include "sketchnav/nav/goal_checker.h"

using namespace sketchnav;
using namespace sketchnav::nav;
using namespace sketchnav::nav::test;

namespace {

struct Recorder : ExecutiveObserver {
  std::vector<NavEvent> events;
  double min_clearance = 1e9;
  FakeWorld* w = nullptr;
  void onEvent(const NavEvent& e) override {
    events.push_back(e);
    if (std::getenv("NAV_TEST_TRACE")) std::printf("%s\n", e.toJson().dump().c_str());
  }
  void onTick(const TelemetryRow& r) override {
    min_clearance = std::min(min_clearance, w->clearance());
    if (std::getenv("NAV_TEST_TRACE") && static_cast<int>(r.t * 20) % 10 == 0)
      std::printf("t=%.1f x=%.2f y=%.2f th=%.2f v=%.2f w=%.2f %s sec=%d lm=%s free=%.2f\n", r.t,
                  r.odom.x, r.odom.y, r.odom.theta, r.v_cmd, r.w_cmd, toString(r.mode), r.section,
                  r.landmark.c_str(), r.front_free_m);
  }
  int count(const std::string& type) const {
    int n = 0;
    for (const auto& e : events) n += e.type() == type;
    return n;
  }
};

struct Scenario {
  FakeWorld world;
  FakeBase base{world};
  FakeLaser laser{world};
  std::unique_ptr<FakeCamera> camera;
  std::unique_ptr<GeometricPerception> perception;
  Recorder rec;
  mapsketch::Route route;
  NavSettings settings;

  // Sketch: (0,0) -> (6,0) -> (6,5); landmark A near the corner, B beyond the goal. The
  // real landmarks stand 0.3-0.4 m away from where the sketch put them.
  Scenario(bool see_a = true, bool see_b = true, double drop_camera = 1e9) {
    route = makeRoute({{0, 0}, {6, 0}, {6, 5}},
                      {{0, "A", "cup", {7.0, 0.3}}, {1, "B", "bin", {6.4, 6.2}}});
    world.obstacles = {{{7.3, 0.5}, 0.15}, {{6.6, 6.5}, 0.15}};
    std::vector<TrueMark> marks;
    if (see_a) marks.push_back({"cup", {7.3, 0.5}});
    if (see_b) marks.push_back({"bin", {6.6, 6.5}});
    camera = std::make_unique<FakeCamera>(world, drop_camera);
    perception = std::make_unique<GeometricPerception>(world, marks);
    rec.w = &world;
    settings.exec.max_time_s = 120;
  }
  ExecutiveSummary run() {
    Executive ex(route, {camera.get(), &base, {&laser}, world.clock.get()}, *perception, settings,
                 &rec);
    return ex.run();
  }
  double distToGoal() const { return std::hypot(world.truth.x - 6, world.truth.y - 5); }
};

}  // namespace

TEST(Executive, ReachesTheEndWithLandmarks) {
  Scenario s;
  const auto sum = s.run();
  EXPECT_EQ(sum.status, RunStatus::Succeeded) << sum.reason;
  EXPECT_LT(s.distToGoal(), 0.6);
  EXPECT_EQ(s.rec.count("landmark_passed"), 2);
  EXPECT_EQ(s.rec.count("landmark_missed"), 0);
  EXPECT_GT(s.rec.min_clearance, 0.05);
  ASSERT_EQ(sum.landmarks.size(), 2u);
  EXPECT_EQ(sum.landmarks[0].state, "passed");
  EXPECT_GT(sum.frames_processed, 10);
  EXPECT_TRUE(s.world.stopped_called);
}

TEST(Executive, ReportsItsLoopRatesAndLatencyPercentiles) {
  // Ticks at 20 Hz, the camera at 10 Hz, perception at most every 0.2 s, on a simulated clock:
  // the counts and clock rates are exact; the fake perception costs 1 ms and runs no full pass
  // and no tracker. No wall-time figure is checked beyond its order.
  Scenario s;
  const auto sum = s.run();
  ASSERT_EQ(sum.status, RunStatus::Succeeded) << sum.reason;
  const LoopTiming& t = sum.timing;
  EXPECT_NEAR(t.ticks, sum.time_s / s.settings.exec.tick_s, 2);
  EXPECT_EQ(t.frames, sum.frames);
  EXPECT_NEAR(t.frames, sum.time_s / s.settings.exec.camera_period_s, 2);
  EXPECT_EQ(t.perception_frames, sum.frames_processed);
  EXPECT_LE(t.perception_frames, t.frames);
  EXPECT_GT(t.perception_frames, 10);
  EXPECT_GT(t.servo_updates, 0);  // both landmarks were servoed on
  EXPECT_LE(t.servo_updates, t.perception_frames);
  EXPECT_EQ(t.full_passes, 0);
  EXPECT_EQ(t.tracked_frames, 0);
  EXPECT_GT(t.wall_s, 0);
  // Every frame perception looked at reached a command: the run never ended in such a tick.
  EXPECT_EQ(t.grab_to_command_ms.n, static_cast<size_t>(t.perception_frames));
  EXPECT_GE(t.grab_to_command_ms.p50, 0);  // the fake camera stamps its frame at the grab
  EXPECT_LE(t.grab_to_command_ms.p50, t.grab_to_command_ms.p95);
  EXPECT_LE(t.grab_to_command_ms.p95, t.grab_to_command_ms.p99);
  EXPECT_LE(t.grab_to_command_ms.p99, t.grab_to_command_ms.max);
  EXPECT_EQ(t.perception_ms.n, static_cast<size_t>(t.perception_frames));
  EXPECT_EQ(t.perception_ms.p50, 1);
  EXPECT_EQ(t.perception_ms.max, 1);
  EXPECT_EQ(t.objectness_ms.n, 0u);
  EXPECT_EQ(t.track_ms.n, 0u);

  const auto j = sum.toJson()["timing"];
  EXPECT_NEAR(j["rates_hz"]["control_ticks"]["clock"].get<double>(), 20, 0.5);
  EXPECT_NEAR(j["rates_hz"]["camera_frames"]["clock"].get<double>(), 10, 0.5);
  EXPECT_LE(j["rates_hz"]["perception_frames"]["clock"].get<double>(), 5 + 1e-9);
  EXPECT_EQ(j["rates_hz"]["servo_updates"]["n"], t.servo_updates);
  EXPECT_GT(j["rates_hz"]["servo_updates"]["wall"].get<double>(), 0);
  EXPECT_EQ(j["latency_ms"]["perception"]["p95"], 1.0);
  EXPECT_TRUE(j["latency_ms"]["objectness"]["p50"].is_null());  // no full pass: no figure
  EXPECT_EQ(j["latency_ms"]["grab_to_command"]["n"], t.perception_frames);
}

TEST(Executive, ReachesTheEndWithOneLandmarkMissing) {
  Scenario s(/*see_a=*/false, /*see_b=*/true);
  const auto sum = s.run();
  EXPECT_EQ(sum.status, RunStatus::Succeeded) << sum.reason;
  EXPECT_LT(s.distToGoal(), 0.6);
  EXPECT_EQ(s.rec.count("landmark_missed"), 1);
  EXPECT_EQ(sum.landmarks[0].state, "missed");
  EXPECT_EQ(sum.landmarks[1].state, "passed");
}

TEST(Executive, FailsWithAReasonWhenLandmarksKeepMissing) {
  Scenario s(false, false);
  // The route goes on 4 m past B: the second miss is on the way, not at the goal (where
  // reaching the goal overrules the lost rule, ALandmarkNotFoundAtTheGoalDoesNotFailTheRun).
  s.route = makeRoute({{0, 0}, {6, 0}, {6, 5}, {6, 9}},
                      {{0, "A", "cup", {7.0, 0.3}}, {1, "B", "bin", {6.4, 6.2}}});
  s.settings.exec.max_missed_in_row = 1;
  const auto sum = s.run();
  EXPECT_EQ(sum.status, RunStatus::Failed);
  EXPECT_NE(sum.reason.find("lost"), std::string::npos) << sum.reason;
  EXPECT_NE(sum.reason.find("A, B"), std::string::npos) << sum.reason;
  EXPECT_EQ(sum.failure, FailureCode::Lost);
  EXPECT_EQ(s.world.v, 0.0);
}

TEST(Executive, AvoidsAStaticObstacleOnThePath) {
  Scenario s;
  s.world.obstacles.push_back({{3.0, 0.05}, 0.35});
  const auto sum = s.run();
  EXPECT_EQ(sum.status, RunStatus::Succeeded) << sum.reason;
  EXPECT_GE(sum.avoidance_manoeuvres, 1);
  EXPECT_GE(sum.detours, 1);  // a standing obstacle: the way round is planned on the grid
  EXPECT_EQ(s.rec.count("detour_start"), sum.detours);
  EXPECT_GT(s.rec.min_clearance, 0.05);
  EXPECT_LT(s.distToGoal(), 0.6);
}

namespace {
// A barrier 2.9 m wide across the first section at x = 3 (a row of touching discs): the
// reactive avoider lets go as soon as the corridor towards the route is free release_m ahead,
// well before the robot is past the barrier's end.
void addBarrier(FakeWorld& w) {
  for (double y = -1.25; y <= 1.26; y += 0.25) w.obstacles.push_back({{3.0, y}, 0.15});
}
std::vector<std::string> detourEndReasons(const Recorder& r) {
  std::vector<std::string> out;
  for (const auto& e : r.events)
    if (std::string(e.type()) == "detour_end")
      out.push_back(e.toJson().value("reason", std::string()));
  return out;
}
}  // namespace

TEST(Executive, FollowsADetourPastTheObstacleNotOnlyWhileTheAvoiderDodges) {
  Scenario s;
  addBarrier(s.world);
  s.settings.exec.detour_hold = true;
  const auto sum = s.run();
  ASSERT_EQ(sum.status, RunStatus::Succeeded) << sum.reason;
  EXPECT_LT(s.distToGoal(), 0.6);
  EXPECT_GT(s.rec.min_clearance, 0.05);
  ASSERT_GE(sum.detours, 1);
  const auto reasons = detourEndReasons(s.rec);
  for (const auto& r : reasons) EXPECT_NE(r, "avoid ended");
  // The first detour ends because the way back to the route is clear: the robot is past the
  // barrier's end.
  ASSERT_FALSE(reasons.empty());
  EXPECT_EQ(reasons.front(), "route clear");

  // Ending with the avoider's manoeuvre (detour_hold off, the default), the first detour
  // ends while the robot is still in front of the barrier.
  Scenario off;
  addBarrier(off.world);
  off.settings.exec.detour_hold = false;
  const auto sum_off = off.run();
  const auto reasons_off = detourEndReasons(off.rec);
  ASSERT_FALSE(reasons_off.empty());
  EXPECT_EQ(reasons_off.front(), "avoid ended");
  EXPECT_GE(sum_off.detours, sum.detours);
}

// Landmark B drawn 4 m short of where it stands (2.5 m up the second section instead of 1.5 m
// past its end): seen about 16 deg from where the sketch puts it, at three times the predicted
// range, so its range never agrees. B's class is drawn once, so its detection is taken for its
// bearing (SelectParams::unique_class_bearing_only); with that off every one is refused and
// B is missed.
void farDrawnBin(Scenario& s) {
  s.route = makeRoute({{0, 0}, {6, 0}, {6, 5}},
                      {{0, "A", "cup", {7.0, 0.3}}, {1, "B", "bin", {6.8, 2.5}}});
}

TEST(Executive, AUniqueLandmarkDrawnFarOffIsTakenByItsBearing) {
  Scenario s;
  farDrawnBin(s);
  const auto sum = s.run();
  EXPECT_EQ(sum.status, RunStatus::Succeeded) << sum.reason;
  ASSERT_EQ(sum.landmarks.size(), 2u);
  EXPECT_EQ(sum.landmarks[1].state, "passed");
  EXPECT_EQ(s.rec.count("landmark_missed"), 0);
  bool dropped = false;
  for (const auto& e : s.rec.events)
    if (const auto* x = e.as<event::LandmarkSeen>(); x && x->id == "B") dropped = x->range_dropped;
  EXPECT_TRUE(dropped);

  Scenario off;
  farDrawnBin(off);
  off.settings.select.unique_class_bearing_only = false;
  off.run();
  ASSERT_EQ(off.rec.count("landmark_missed"), 1);
}

// A landmark of the last section out of the camera's view all the way (90 deg left of the
// goal): the robot turns to it at the goal and looks before arriving.
void lookBesideTheGoal(Scenario& s) {
  s.route = makeRoute(
      {{0, 0}, {6, 0}, {6, 5}},
      {{0, "A", "cup", {7.0, 0.3}}, {1, "B", "bin", {6.4, 6.2}}, {1, "C", "box", {3.5, 5.3}}});
  s.world.obstacles.push_back({{3.5, 5.0}, 0.15});
  s.perception = std::make_unique<GeometricPerception>(
      s.world,
      std::vector<TrueMark>{{"cup", {7.3, 0.5}}, {"bin", {6.6, 6.5}}, {"box", {3.5, 5.0}}});
}

TEST(Executive, LooksForAnUnseenLastLandmarkAtTheGoal) {
  Scenario s;
  lookBesideTheGoal(s);
  const auto sum = s.run();
  EXPECT_EQ(sum.status, RunStatus::Succeeded) << sum.reason;
  ASSERT_EQ(s.rec.count("final_look_start"), 1);
  ASSERT_EQ(s.rec.count("final_look_end"), 1);
  for (const auto& e : s.rec.events)
    if (const auto* x = e.as<event::FinalLookEnd>()) {
      EXPECT_EQ(x->id, "C");
      EXPECT_TRUE(x->seen);
    }
  ASSERT_EQ(sum.landmarks.size(), 3u);
  EXPECT_EQ(sum.landmarks[2].state, "passed");
}

TEST(Executive, TheFinalLookDoesNotCountAsNoLongerGettingCloser) {
  // Turning on the spot to look is not being stuck near the goal: with a settle time shorter
  // than the look, the robot still goes on to the goal afterwards (an exp2-redrawn-d robot
  // settled 0.21 m short of its goal estimate right after its final look).
  Scenario s;
  lookBesideTheGoal(s);
  s.settings.exec.goal_settle_s = 1.5;
  const auto sum = s.run();
  EXPECT_EQ(sum.status, RunStatus::Succeeded) << sum.reason;
  ASSERT_EQ(s.rec.count("final_look_start"), 1);
  EXPECT_EQ(s.rec.count("goal_settled"), 0);
  EXPECT_EQ(sum.reason, "reached the end of the route");
}

TEST(Executive, WithoutTheFinalLookTheLastLandmarkIsMissed) {
  Scenario s;
  lookBesideTheGoal(s);
  s.settings.exec.final_look_range_m = 0;
  const auto sum = s.run();
  EXPECT_EQ(sum.status, RunStatus::Succeeded) << sum.reason;
  EXPECT_EQ(s.rec.count("final_look_start"), 0);
  ASSERT_EQ(sum.landmarks.size(), 3u);
  EXPECT_NE(sum.landmarks[2].state, "passed");
}

TEST(Executive, ALandmarkNotFoundAtTheGoalDoesNotFailTheRun) {
  // C is never seen (not even in the final look at the goal) and no miss is allowed: the lost
  // rule fires during the final look, with the robot at its goal. Reaching the goal overrules
  // it (GoalChecker): the run arrives. (Issue 25: a run 0.16 m from its goal was reported
  // failed, "lost: 3 landmarks in a row not found", fired during the final look.)
  Scenario s;
  lookBesideTheGoal(s);
  s.perception = std::make_unique<GeometricPerception>(
      s.world, std::vector<TrueMark>{{"cup", {7.3, 0.5}}, {"bin", {6.6, 6.5}}});
  s.settings.exec.max_missed_in_row = 0;
  const auto sum = s.run();
  EXPECT_EQ(sum.status, RunStatus::Succeeded) << sum.reason;
  EXPECT_EQ(sum.failure, FailureCode::None);
  ASSERT_EQ(s.rec.count("final_look_end"), 1);
  for (const auto& e : s.rec.events)
    if (const auto* x = e.as<event::FinalLookEnd>()) EXPECT_FALSE(x->seen);
  EXPECT_EQ(s.rec.count("landmark_missed"), 1);
  EXPECT_EQ(s.rec.count("failed"), 0);
  ASSERT_EQ(sum.landmarks.size(), 3u);
  EXPECT_EQ(sum.landmarks[2].state, "missed");
  EXPECT_LT(std::hypot(s.world.truth.x - 6, s.world.truth.y - 5), 0.6);
}

TEST(Executive, TheLostRuleStillFailsARunOnTheWay) {
  // The same rule away from the goal: A is not seen, no miss allowed.
  Scenario s(/*see_a=*/false, /*see_b=*/true);
  s.settings.exec.max_missed_in_row = 0;
  const auto sum = s.run();
  EXPECT_EQ(sum.status, RunStatus::Failed);
  EXPECT_EQ(sum.failure, FailureCode::Lost);
  EXPECT_EQ(sum.reason.rfind("lost: 1 landmarks in a row not found (A)", 0), 0u) << sum.reason;
  EXPECT_EQ(s.rec.count("failed"), 1);
  for (const auto& e : s.rec.events)
    if (const auto* x = e.as<event::Failed>()) EXPECT_EQ(x->code, FailureCode::Lost);
}

// Looking to the side (ExecutiveParams::side_look_*): the route starts beside landmark A,
// which the sketch puts ~76 deg to the left, 2.1 m away: out of the camera's +-30 deg, and
// beyond what the look ahead turns for (look_max_bearing_deg). Driving on, it would pass
// unseen. `visible`: whether A stands where it is drawn (else it is not there to be found).
void landmarkBesideTheStart(Scenario& s, bool visible) {
  s.route = makeRoute({{0, 0}, {8, 0}}, {{0, "A", "cup", {0.5, 2.0}}});
  s.world.obstacles = {{{0.6, 2.2}, 0.15}};
  std::vector<TrueMark> marks;
  if (visible) marks.push_back({"cup", {0.6, 2.2}});
  s.perception = std::make_unique<GeometricPerception>(s.world, marks);
}
double distTo(const Scenario& s, double x, double y) {
  return std::hypot(s.world.truth.x - x, s.world.truth.y - y);
}
std::vector<event::SideLookStart> sideLookStarts(const Recorder& r) {
  std::vector<event::SideLookStart> v;
  for (const auto& e : r.events)
    if (const auto* x = e.as<event::SideLookStart>()) v.push_back(*x);
  return v;
}
std::vector<event::SideLookEnd> sideLookEnds(const Recorder& r) {
  std::vector<event::SideLookEnd> v;
  for (const auto& e : r.events)
    if (const auto* x = e.as<event::SideLookEnd>()) v.push_back(*x);
  return v;
}

TEST(Executive, TurnsToLookForALandmarkTheSketchPutsToTheSide) {
  Scenario s;
  landmarkBesideTheStart(s, true);
  const auto sum = s.run();
  EXPECT_EQ(sum.status, RunStatus::Succeeded) << sum.reason;
  const auto starts = sideLookStarts(s.rec);
  const auto ends = sideLookEnds(s.rec);
  ASSERT_EQ(starts.size(), 1u);
  ASSERT_EQ(ends.size(), 1u);
  EXPECT_EQ(starts[0].id, "A");
  EXPECT_GE(starts[0].bearing_deg, 70);
  EXPECT_LE(starts[0].bearing_deg, 90);
  EXPECT_EQ(ends[0].id, "A");
  EXPECT_TRUE(ends[0].seen);
  EXPECT_LT(ends[0].duration_s, s.settings.exec.side_look_s);
  ASSERT_EQ(sum.landmarks.size(), 1u);
  EXPECT_EQ(sum.landmarks[0].state, "passed");
  EXPECT_EQ(s.rec.count("landmark_missed"), 0);
  EXPECT_LT(distTo(s, 8, 0), 0.6);
  EXPECT_GT(s.rec.min_clearance, 0.05);

  // Without the look the robot drives past it.
  Scenario off;
  landmarkBesideTheStart(off, true);
  off.settings.exec.side_look_s = 0;
  const auto so = off.run();
  EXPECT_EQ(so.status, RunStatus::Succeeded) << so.reason;
  EXPECT_EQ(off.rec.count("side_look_start"), 0);
  ASSERT_EQ(so.landmarks.size(), 1u);
  EXPECT_EQ(so.landmarks[0].state, "missed");
}

TEST(Executive, ASideLookEndsWithItsBudgetAndTheRobotGoesOnWithout) {
  // A is not where the sketch puts it: the look takes side_look_s, once, and the robot then
  // follows the route on; A is missed and the run arrives.
  Scenario s;
  landmarkBesideTheStart(s, false);
  s.settings.exec.side_look_s = 3.0;
  const auto sum = s.run();
  EXPECT_EQ(sum.status, RunStatus::Succeeded) << sum.reason;
  const auto ends = sideLookEnds(s.rec);
  ASSERT_EQ(s.rec.count("side_look_start"), 1);  // once per landmark
  ASSERT_EQ(ends.size(), 1u);
  EXPECT_FALSE(ends[0].seen);
  EXPECT_GE(ends[0].duration_s, 3.0);
  EXPECT_LE(ends[0].duration_s, 3.0 + 2 * s.settings.exec.tick_s);
  ASSERT_EQ(sum.landmarks.size(), 1u);
  EXPECT_EQ(sum.landmarks[0].state, "missed");
  EXPECT_LT(distTo(s, 8, 0), 0.6);
}

TEST(Executive, NoSideLookForALandmarkInViewOrBehindTheAngleBudget) {
  // Ahead and a little to the side: seen before it leaves the view, no turn to look.
  Scenario ahead;
  ahead.route = makeRoute({{0, 0}, {8, 0}}, {{0, "A", "cup", {4.0, 0.6}}});
  ahead.world.obstacles = {{{4.1, 0.8}, 0.15}};
  ahead.perception = std::make_unique<GeometricPerception>(
      ahead.world, std::vector<TrueMark>{{"cup", {4.1, 0.8}}});
  const auto sa = ahead.run();
  EXPECT_EQ(sa.status, RunStatus::Succeeded) << sa.reason;
  EXPECT_EQ(ahead.rec.count("side_look_start"), 0);
  ASSERT_EQ(sa.landmarks.size(), 1u);
  EXPECT_EQ(sa.landmarks[0].state, "passed");

  // The same landmark beside the start, with an angle budget below its bearing: no look.
  Scenario narrow;
  landmarkBesideTheStart(narrow, true);
  narrow.settings.exec.side_look_max_bearing_deg = 60;
  narrow.run();
  EXPECT_EQ(narrow.rec.count("side_look_start"), 0);
}

namespace {
// An L-shaped corridor 2 m wide (y in [-1, 1] eastwards to its end wall at x = 10, then north
// up x in [8, 10] to y = 9) with the sketch's first corner drawn 2 m past the corridor's end
// (distances drawn too long): the first section's end lies beyond the end wall, where the robot
// cannot get within 2 m of it, and the line through the end is never crossed inside the
// corridor. The second section leads to a goal up the north leg.
void cornerBeyondTheWall(Scenario& s) {
  s.route = makeRoute({{0, 0}, {12, 0}, {9, 6}});
  s.world.obstacles.clear();
  s.world.walls = {{{-1, -1}, {10, -1}}, {{10, -1}, {10, 9}}, {{10, 9}, {8, 9}},
                   {{8, 9}, {8, 1}},     {{8, 1}, {-1, 1}},   {{-1, 1}, {-1, -1}}};
  s.settings.exec.max_time_s = 150;
}
double firstSectionSettledToEnd(const Recorder& r) {
  for (const auto& e : r.events)
    if (const auto* s = std::get_if<event::SectionSettled>(&e.data)) return s->to_end_m;
  return -1;
}
}  // namespace

TEST(Executive, ASectionEndDrawnBeyondTheWallEndsWhereTheRobotCameClosest) {
  Scenario s;
  cornerBeyondTheWall(s);
  const auto sum = s.run();
  ASSERT_EQ(sum.status, RunStatus::Succeeded) << sum.reason;
  EXPECT_EQ(s.rec.count("section_settled"), 1);
  const double at = firstSectionSettledToEnd(s.rec);
  EXPECT_GT(at, 1.0);  // farther than end_blocked_m: the rule before it could not end it
  EXPECT_LT(at, 0.3 * 12);
  EXPECT_LT(std::hypot(s.world.truth.x - 9.0, s.world.truth.y - 6.0), 0.6);
  EXPECT_GT(s.rec.min_clearance, 0.05);

  // Without it (section_settle_frac 0) the first section never ends.
  Scenario off;
  cornerBeyondTheWall(off);
  off.settings.exec.section_settle_frac = 0;
  const auto sum_off = off.run();
  EXPECT_NE(sum_off.status, RunStatus::Succeeded);
  EXPECT_EQ(off.rec.count("section_settled"), 0);
  EXPECT_EQ(off.rec.count("section_done"), 0);
}

TEST(GoalChecker, ReachedOnlyOnTheLastSectionWithinItsRadiusOrWhenFinished) {
  SectionTracker tr(makeRoute({{0, 0}, {6, 0}, {6, 5}}), SectionParams{});
  const GoalChecker goal(0.15);
  EXPECT_FALSE(goal.reached(tr, {6, 4.9, M_PI / 2}));  // still on the first section
  tr.advance();
  EXPECT_TRUE(goal.reached(tr, {6, 4.9, M_PI / 2}));
  EXPECT_FALSE(goal.reached(tr, {6, 4.7, M_PI / 2}));
  EXPECT_FALSE(goal.reached(tr, {3, 0, 0}));
  tr.advance();
  ASSERT_TRUE(tr.finished());
  EXPECT_TRUE(goal.reached(tr, {3, 0, 0}));
  EXPECT_TRUE(GoalChecker::overrules(FailureCode::Lost));
  for (auto c : {FailureCode::SafetyStop, FailureCode::Timeout, FailureCode::NoProgress,
                 FailureCode::Stopped})
    EXPECT_FALSE(GoalChecker::overrules(c)) << toString(c);
}

TEST(NavEvent, WritesTheEventsJsonlFormat) {
  // The JSON lines old run folders and the run page read: field names, types and presence.
  const NavEvent seen{1.5, event::LandmarkSeen{"L1", "cup", 2, 9, -19.5, 0.0, -29.0, 2.5, false,
                                               std::size_t{1}, true}};
  EXPECT_EQ(seen.toJson().dump(),
            R"({"attended_first":true,"bearing_deg":-19.5,"candidates":1,"class":"cup",)"
            R"("id":"L1","inliers":9,"predicted_bearing_deg":-29.0,"predicted_range_m":2.5,)"
            R"("range_dropped":false,"range_m":0.0,"section":2,"t":1.5,"type":"landmark_seen"})");
  EXPECT_EQ((NavEvent{2.0, event::AvoidEnd{DodgeSide::None, true}}.toJson().dump()),
            R"({"docking":true,"side":"none","t":2.0,"type":"avoid_end"})");
  EXPECT_EQ((NavEvent{2.0, event::AvoidEnd{DodgeSide::Left}}.toJson().dump()),
            R"({"side":"left","t":2.0,"type":"avoid_end"})");
  // The failure code stays out of the line (it predates the code; summary.json carries it).
  EXPECT_EQ((NavEvent{3.0, event::Failed{FailureCode::Lost, "lost: x"}}.toJson().dump()),
            R"({"reason":"lost: x","t":3.0,"type":"failed"})");
  event::LandmarkPassed p{"L2", "bin", 1, 1.3, 15, true};
  EXPECT_EQ((NavEvent{4.0, p}.toJson().dump()),
            R"({"class":"bin","frames_seen":15,"id":"L2","in_view":true,"range_m":1.3,)"
            R"("section":1,"t":4.0,"type":"landmark_passed"})");
  auto& f = p.fix.emplace();
  f.method = "ranges";
  f.rays = 2;
  f.sightings = {{0.12345, -0.0834, -0.374712, 1.93949}};
  f.realign = event::LandmarkPassed::Realign{0.0, 0.48};
  f.disagreement_m = 0.6;
  f.route = {2.0, -1.0};
  f.odom = {1.5, -0.5};
  const auto j = NavEvent{4.0, p}.toJson();
  EXPECT_EQ(j["sightings"].dump(), "[[0.123,-0.083,-0.3747,1.939]]");
  EXPECT_FALSE(j.contains("fix_height_sigma_m"));  // only with height ranges
  EXPECT_FALSE(j.contains("fit_scale"));
  EXPECT_EQ(j["reanchor_m"], 0.48);
  EXPECT_EQ(j["fix_odom"].dump(), "[1.5,-0.5]");
  EXPECT_STREQ((NavEvent{0, event::YieldEnd{}}.type()), "yield_end");
  EXPECT_EQ((NavEvent{5.0, event::SideLookStart{"L3", 2, 80.0, 2.0}}.toJson().dump()),
            R"({"bearing_deg":80.0,"id":"L3","range_m":2.0,"section":2,"t":5.0,)"
            R"("type":"side_look_start"})");
  EXPECT_EQ((NavEvent{6.5, event::SideLookEnd{"L3", true, 1.5}}.toJson().dump()),
            R"({"duration_s":1.5,"id":"L3","seen":true,"t":6.5,"type":"side_look_end"})");
}

TEST(Executive, StopsWithin200msOfADroppedCamera) {
  Scenario s(true, true, /*drop_camera=*/3.0);
  const auto sum = s.run();
  EXPECT_EQ(sum.status, RunStatus::Failed);
  EXPECT_NE(sum.reason.find("camera"), std::string::npos) << sum.reason;
  ASSERT_TRUE(s.world.stopped_called);
  // The last frame came at <= 3.0 s: the stop must follow within 200 ms of the data going stale.
  EXPECT_LE(s.world.last_stop_t, 3.0 + s.settings.safety.camera_timeout_s + 0.2);
  EXPECT_LT(s.world.last_motion_cmd_t, s.world.last_stop_t + 1e-9);
  EXPECT_EQ(s.world.v, 0.0);
  EXPECT_EQ(s.rec.count("fault"), 1);
  EXPECT_EQ(sum.failure, FailureCode::SafetyStop);
}

TEST(Executive, StopsOnAnException) {
  Scenario s;
  s.perception->throw_now = true;
  const auto sum = s.run();
  EXPECT_EQ(sum.status, RunStatus::Failed);
  EXPECT_NE(sum.reason.find("exception"), std::string::npos) << sum.reason;
  EXPECT_TRUE(s.world.stopped_called);
  EXPECT_EQ(s.world.v, 0.0);
  EXPECT_LT(s.world.clock->now(), 0.5);
}

TEST(Executive, StopsOnALostBaseLink) {
  Scenario s;
  Executive ex(s.route, {s.camera.get(), &s.base, {&s.laser}, s.world.clock.get()}, *s.perception,
               s.settings, &s.rec);
  ex.start();
  double t = 0;
  for (int i = 0; i < 40; ++i) s.world.clock->sleepUntil(t += 0.05), ex.step();
  EXPECT_GT(s.world.v, 0.0);
  s.world.link_ok = false;
  s.world.clock->sleepUntil(t += 0.05);
  ex.step();
  EXPECT_TRUE(ex.done());
  EXPECT_EQ(ex.summary().status, RunStatus::Failed);
  EXPECT_EQ(s.world.v, 0.0);
  EXPECT_NEAR(s.world.last_stop_t, t, 1e-9);
}

// The goal is a doorway (mapsketch::GoalPlace): a wall y = 5.6 with a 1 m opening at
// x 6.1-7.1, the goal 0.6 m in front of it at (6.6, 5.0), drawn at (6, 5), 0.6 m off. The
// robot finds the opening with the laser near its goal estimate and stops in front of it;
// with the search off it stops where the sketch says.
void doorAtTheGoal(Scenario& s) {
  s.route = makeRoute({{0, 0}, {6, 0}, {6, 5}},
                      {{0, "A", "cup", {7.0, 0.3}}, {1, "B", "bin", {6.9, 2.6}}});
  s.route.goal_place.kind = mapsketch::GoalPlace::Kind::Doorway;
  s.route.goal_place.standoff_m = 0.6;
  s.world.obstacles = {{{7.3, 0.5}, 0.15}, {{7.2, 2.8}, 0.15}};
  s.world.walls = {{{2.0, 5.6}, {6.1, 5.6}}, {{7.1, 5.6}, {10.0, 5.6}}};
  s.perception = std::make_unique<GeometricPerception>(
      s.world, std::vector<TrueMark>{{"cup", {7.3, 0.5}}, {"bin", {7.2, 2.8}}});
}

TEST(Executive, StopsInFrontOfTheGoalDoorwayItSees) {
  Scenario s;
  doorAtTheGoal(s);
  const auto sum = s.run();
  EXPECT_EQ(sum.status, RunStatus::Succeeded) << sum.reason;
  ASSERT_EQ(s.rec.count("goal_door"), 1);
  for (const auto& e : s.rec.events)
    if (const auto* x = e.as<event::GoalDoor>()) {
      EXPECT_NEAR(x->width_m, 1.0, 0.1);
      EXPECT_GE(x->sightings, s.settings.goal_door.min_scans);
    }
  const double off = std::hypot(s.world.truth.x - 6.6, s.world.truth.y - 5.0);
  EXPECT_LT(off, 0.15);
  EXPECT_GT(s.rec.min_clearance, 0.05);

  Scenario blind;
  doorAtTheGoal(blind);
  blind.settings.goal_door.enabled = false;
  EXPECT_EQ(blind.run().status, RunStatus::Succeeded);
  EXPECT_EQ(blind.rec.count("goal_door"), 0);
  EXPECT_GT(std::hypot(blind.world.truth.x - 6.6, blind.world.truth.y - 5.0), 0.3);
}

TEST(Executive, AGoalDrawnAsAPointIgnoresDoorways) {
  Scenario s;
  doorAtTheGoal(s);
  s.route.goal_place = {};
  s.run();
  EXPECT_EQ(s.rec.count("goal_door"), 0);
}
