// The executive's behaviours on their own: heading for a bearing, following and looking,
// looking to the side, the final look at the goal, the stuck recovery, docking, detours and
// giving way to walking people.
#include <gtest/gtest.h>

#include <cmath>

#include "route_util.h"
#include "scan_sim.h"
#include "sketchnav/nav/behaviours.h"

namespace sketchnav::nav {
namespace {

using mapsketch::Side;
constexpr double kDeg = M_PI / 180;

TEST(HeadFor, TurnsInPlaceAboveTheLimitAndSlowsWithTheBearing) {
  DriveParams p;  // 0.3 m/s, 1.2 /s, 0.8 rad/s, 60 deg
  Command c = headFor(0.0, 1.0, p);
  EXPECT_DOUBLE_EQ(c.v, 0.3);
  EXPECT_DOUBLE_EQ(c.w, 0.0);
  c = headFor(0.5, 1.0, p);
  EXPECT_NEAR(c.w, 0.6, 1e-12);
  EXPECT_NEAR(c.v, 0.3 * std::cos(0.5), 1e-12);
  c = headFor(-1.2, 0.5, p);  // over 60 deg: on the spot, yaw rate clamped
  EXPECT_DOUBLE_EQ(c.v, 0.0);
  EXPECT_DOUBLE_EQ(c.w, -0.8);
  c = headFor(0.2, 0.5, p);  // scaled (docking's last metres)
  EXPECT_NEAR(c.v, 0.15 * std::cos(0.2), 1e-12);
  EXPECT_EQ(turnOf(0.04), servo::Turn::Straight);
  EXPECT_EQ(turnOf(0.06), servo::Turn::Left);
  EXPECT_EQ(turnOf(-0.06), servo::Turn::Right);
}

TEST(FollowBehaviour, HoldsTheHeadingTowardsANearUnseenLandmark) {
  const FollowBehaviour f(DriveParams{}, LookParams{}, 1.4);
  // Nothing expected: pure pursuit on the look-ahead point.
  auto p = f.propose(0.3, nullptr);
  EXPECT_EQ(p.behaviour, Behaviour::Follow);
  EXPECT_DOUBLE_EQ(p.target_bearing, 0.3);
  EXPECT_EQ(p.command.turn, servo::Turn::Left);
  // A landmark 40 deg right, 3 m away, not seen: the heading is held within 10 deg of it.
  const Polar right{-40 * kDeg, 3.0};
  p = f.propose(0.0, &right);
  EXPECT_EQ(p.behaviour, Behaviour::Look);
  EXPECT_NEAR(p.target_bearing, -30 * kDeg, 1e-12);
  EXPECT_EQ(p.command.turn, servo::Turn::Right);
  EXPECT_NEAR(p.command.w, 1.2 * p.target_bearing, 1e-12);
  // Already within 10 deg of it: following is looking enough.
  EXPECT_EQ(f.propose(-35 * kDeg, &right).behaviour, Behaviour::Follow);
  // Too far (look_range_m 5 m), being passed (approach_m), or behind (look_max_bearing_deg 60).
  const Polar far{-40 * kDeg, 5.5}, close{-40 * kDeg, 1.2}, behind{-70 * kDeg, 3.0};
  for (const Polar* q : {&far, &close, &behind}) {
    p = f.propose(0.0, q);
    EXPECT_EQ(p.behaviour, Behaviour::Follow);
    EXPECT_DOUBLE_EQ(p.target_bearing, 0.0);
  }
}

// One section along x, landmark A 2 m ahead and 2 m left (never seen), B further on.
mapsketch::Route sideRoute() {
  return test::makeRoute({{0, 0}, {10, 0}}, {{0, "A", "sign", {2, 2}, Side::Left},
                                             {0, "B", "box", {6, -1}, Side::Right}});
}

TEST(SideLook, TurnsTowardsALandmarkOutOfViewUntilItIsSeen) {
  const auto route = sideRoute();
  LandmarkTracker lt(route, {});
  SideLookParams p;  // 4 s, 0.5-4 m, 5 deg margin, 110 deg
  SideLook look(p, 30 * kDeg, 1.2, 0.8);
  const AttendedLandmark a{0, 0, {45 * kDeg, 2.8}, true};
  // Busy (docking, recovering), no camera, or the final look running: no look starts.
  EXPECT_FALSE(look.update(lt, &a, 1.0, true, true, false, false, 0.0).started);
  EXPECT_FALSE(look.update(lt, &a, 1.0, false, false, false, false, 0.0).started);
  EXPECT_FALSE(look.update(lt, &a, 1.0, true, false, true, false, 0.0).started);
  // In view (20 deg < 30 - 5): no need.
  const AttendedLandmark in_view{0, 0, {20 * kDeg, 2.8}, true};
  EXPECT_FALSE(look.update(lt, &in_view, 1.0, true, false, false, false, 0.0).started);
  auto o = look.update(lt, &a, 1.0, true, false, false, false, 0.0);
  ASSERT_TRUE(o.started.has_value());
  EXPECT_EQ(o.started->id, "A");
  EXPECT_NEAR(o.started->bearing_deg, 45, 1e-9);
  ASSERT_TRUE(o.command.has_value());
  EXPECT_DOUBLE_EQ(o.command->v, 0.0);
  EXPECT_DOUBLE_EQ(o.command->w, 0.8);  // 1.2 x 0.785 clamped
  EXPECT_TRUE(look.active());
  // Dodging someone coming towards the robot: the dodge drives, the look goes on.
  o = look.update(lt, &a, 1.5, true, false, false, true, 0.0);
  EXPECT_FALSE(o.command.has_value());
  EXPECT_FALSE(o.ended.has_value());
  // Recognised: over.
  lt.track(0, 0).frames_seen = 1;
  o = look.update(lt, &a, 2.0, true, false, false, false, 0.0);
  ASSERT_TRUE(o.ended.has_value());
  EXPECT_TRUE(o.ended->seen);
  EXPECT_NEAR(o.ended->duration_s, 1.0, 1e-12);
  EXPECT_FALSE(o.command.has_value());
  EXPECT_FALSE(look.active());
}

TEST(SideLook, OncePerLandmarkWithinItsBudget) {
  const auto route = sideRoute();
  LandmarkTracker lt(route, {});
  SideLookParams p;
  p.side_look_s = 2.0;
  SideLook look(p, 30 * kDeg, 1.2, 0.8);
  const AttendedLandmark a{0, 0, {60 * kDeg, 2.0}, true};
  ASSERT_TRUE(look.update(lt, &a, 10.0, true, false, false, false, 0.0).started);
  EXPECT_FALSE(look.update(lt, &a, 12.0, true, false, false, false, 0.0).ended) << "2 s: not over";
  const auto o = look.update(lt, &a, 12.1, true, false, false, false, 0.0);
  ASSERT_TRUE(o.ended.has_value());
  EXPECT_FALSE(o.ended->seen);
  // Never again for A.
  EXPECT_FALSE(look.update(lt, &a, 13.0, true, false, false, false, 0.0).started);
  // Beyond the angle budget (110 deg), too close or too far: none for B either.
  for (const Polar q : {Polar{120 * kDeg, 2.0}, Polar{60 * kDeg, 0.4}, Polar{60 * kDeg, 4.5}}) {
    const AttendedLandmark b{0, 1, q, true};
    EXPECT_FALSE(look.update(lt, &b, 14.0, true, false, false, false, 0.0).started);
  }
  // Another landmark attended while looking ends the look.
  SideLook look2(p, 30 * kDeg, 1.2, 0.8);
  const AttendedLandmark b{0, 1, {-50 * kDeg, 3.0}, true};
  ASSERT_TRUE(look2.update(lt, &b, 20.0, true, false, false, false, 0.0).started);
  const auto moved_on = look2.update(lt, &a, 20.5, true, false, false, false, 0.0);
  ASSERT_TRUE(moved_on.ended.has_value());
  EXPECT_EQ(moved_on.ended->id, "B");
  EXPECT_FALSE(moved_on.started.has_value()) << "one thing per tick: A's look waits";
}

TEST(SideLook, FurtherLooksOnlyFromANewViewpoint) {
  const auto route = sideRoute();
  LandmarkTracker lt(route, {});
  SideLookParams p;
  p.side_look_s = 2.0;
  p.side_look_max_looks = 3;
  p.side_look_rebearing_deg = 25;
  SideLook look(p, 30 * kDeg, 1.2, 0.8);
  // Driving along x past A (heading 0): first look at 35 deg, unseen after its 2 s.
  const AttendedLandmark a35{0, 0, {35 * kDeg, 3.0}, true};
  ASSERT_TRUE(look.update(lt, &a35, 10.0, true, false, false, false, 0.0).started);
  ASSERT_TRUE(look.update(lt, &a35, 12.1, true, false, false, false, 0.0).ended);
  // Turned on the spot by 30 deg (a dodge): the line of sight has not moved, no new look.
  const AttendedLandmark turned{0, 0, {65 * kDeg, 3.0}, true};
  EXPECT_FALSE(look.update(lt, &turned, 13.0, true, false, false, false, -30 * kDeg).started);
  // Driven on: the line of sight at 50 deg (15 deg on) is not yet a new viewpoint; at 62 it is.
  const AttendedLandmark a50{0, 0, {50 * kDeg, 2.5}, true}, a62{0, 0, {62 * kDeg, 2.2}, true};
  EXPECT_FALSE(look.update(lt, &a50, 14.0, true, false, false, false, 0.0).started);
  auto o = look.update(lt, &a62, 15.0, true, false, false, false, 0.0);
  ASSERT_TRUE(o.started.has_value());
  EXPECT_NEAR(o.started->bearing_deg, 62, 1e-9);
  ASSERT_TRUE(look.update(lt, &a62, 17.1, true, false, false, false, 0.0).ended);
  // The third and last at 90 deg (abreast), then never again.
  const AttendedLandmark a90{0, 0, {90 * kDeg, 2.0}, true}, a105{0, 0, {105 * kDeg, 2.1}, true};
  ASSERT_TRUE(look.update(lt, &a90, 20.0, true, false, false, false, 0.0).started);
  ASSERT_TRUE(look.update(lt, &a90, 22.1, true, false, false, false, 0.0).ended);
  const AttendedLandmark behind{0, 0, {-150 * kDeg, 2.5}, true};  // beyond 110 anyway
  EXPECT_FALSE(look.update(lt, &a105, 30.0, true, false, false, false, 40 * kDeg).started);
  EXPECT_FALSE(look.update(lt, &behind, 31.0, true, false, false, false, 0.0).started);
  // With one look per landmark (the default until 2026-12-07), the second viewpoint gets none.
  SideLookParams one;
  one.side_look_max_looks = 1;
  SideLook once(one, 30 * kDeg, 1.2, 0.8);
  ASSERT_TRUE(once.update(lt, &a35, 10.0, true, false, false, false, 0.0).started);
  ASSERT_TRUE(once.update(lt, &a35, 14.1, true, false, false, false, 0.0).ended);
  EXPECT_FALSE(once.update(lt, &a90, 20.0, true, false, false, false, 0.0).started);
}

// The goal at (10, 0); C 2 m before it on the left, D behind the start.
mapsketch::Route goalRoute() {
  return test::makeRoute({{0, 0}, {10, 0}}, {{0, "D", "sign", {0.5, -1}, Side::Right},
                                             {0, "C", "carton", {8, 1.5}, Side::Left}});
}

TEST(FinalLook, LooksForTheNearestLandmarkNeverSeenAndPassesItWhenSeen) {
  const auto route = goalRoute();
  SectionTracker sections(route);
  LandmarkTracker lt(route, {});
  lt.miss(0, 1);  // C was missed on the way
  FinalLook fl(FinalLookParams{}, 1.2);
  const hw::Pose2D at_goal{9.8, 0, 0};
  auto o = fl.step(lt, sections, at_goal, 50.0);
  ASSERT_TRUE(o.started.has_value());
  EXPECT_EQ(o.started->id, "C");
  EXPECT_NEAR(o.started->range_m, std::hypot(1.8, 1.5), 1e-9);
  EXPECT_TRUE(o.looking);
  EXPECT_TRUE(fl.underWay());
  EXPECT_TRUE(fl.isTarget(0, 1));
  EXPECT_EQ(lt.track(0, 1).state, LandmarkState::Pending) << "looked for again";
  // Seen on 3 frames: over, pass it.
  lt.track(0, 1).frames_seen = 2;
  lt.track(0, 1).state = LandmarkState::Tracking;
  EXPECT_TRUE(fl.step(lt, sections, at_goal, 51.0).looking);
  lt.track(0, 1).frames_seen = 3;
  o = fl.step(lt, sections, at_goal, 51.5);
  EXPECT_FALSE(o.looking);
  ASSERT_TRUE(o.ended.has_value());
  EXPECT_TRUE(o.ended->seen);
  EXPECT_EQ(o.verdict, FinalLook::Verdict::Pass);
  EXPECT_TRUE(fl.done());
  EXPECT_FALSE(fl.isTarget(0, 1));
  // Done: never again.
  o = fl.step(lt, sections, at_goal, 52.0);
  EXPECT_FALSE(o.started || o.ended || o.looking);
  // The turn towards it: none within 0.1 rad.
  EXPECT_DOUBLE_EQ(fl.command(0.05).w, 0.0);
  EXPECT_NEAR(fl.command(0.5).w, 0.6, 1e-12);
  EXPECT_DOUBLE_EQ(fl.command(0.5).v, 0.0);
}

TEST(FinalLook, NotSeenInTimeTheLandmarkIsMissedOrStaysMissed) {
  const auto route = goalRoute();
  SectionTracker sections(route);
  FinalLookParams p;
  p.final_look_s = 5.0;
  const hw::Pose2D at_goal{9.8, 0, 0};
  for (bool missed_before : {false, true}) {
    LandmarkTracker lt(route, {});
    if (missed_before) lt.miss(0, 1);
    FinalLook fl(p, 1.2);
    ASSERT_TRUE(fl.step(lt, sections, at_goal, 10.0).started);
    EXPECT_TRUE(fl.step(lt, sections, at_goal, 15.0).looking);
    const auto o = fl.step(lt, sections, at_goal, 15.1);
    ASSERT_TRUE(o.ended.has_value());
    EXPECT_FALSE(o.ended->seen);
    EXPECT_EQ(o.verdict, missed_before ? FinalLook::Verdict::Kept : FinalLook::Verdict::Miss);
    EXPECT_EQ(lt.track(0, 1).state, missed_before ? LandmarkState::Missed : LandmarkState::Pending);
  }
  // Nothing within range (D is 9 m away, C seen already): done at once; off with range 0.
  LandmarkTracker lt(route, {});
  lt.track(0, 1).frames_seen = 4;
  FinalLook fl(p, 1.2);
  const auto o = fl.step(lt, sections, at_goal, 1.0);
  EXPECT_FALSE(o.started || o.looking);
  EXPECT_TRUE(fl.done());
  p.final_look_range_m = 0;
  LandmarkTracker lt2(route, {});
  FinalLook off(p, 1.2);
  EXPECT_FALSE(off.step(lt2, sections, at_goal, 1.0).started);
}

TEST(Recovery, DrivesClearTowardsTheMostOpenDirectionThenEnds) {
  RecoverParams p;  // 1 m, 8 s
  Recovery r(p, 1.5, 0.8);
  // A dead end (robot frame): a wall 0.45 m ahead, walls 0.4 m to either side running back
  // 5 m. The route is ahead, but the only way out is straight back.
  std::vector<std::pair<double, double>> dead_end;
  for (double y = -0.4; y <= 0.4; y += 0.05) dead_end.push_back({0.45, y});
  for (double x = -5; x <= 0.45; x += 0.05)
    dead_end.push_back({x, 0.4}), dead_end.push_back({x, -0.4});
  const auto dir = r.openDirection(dead_end, 0.3, 4.0, 0.0);
  ASSERT_TRUE(dir.has_value());
  EXPECT_NEAR(std::abs(*dir), M_PI, 1e-9);
  // Open to the left as well (no left wall): left is nearer the route's side and wins.
  std::vector<std::pair<double, double>> open_left;
  for (double y = -0.4; y <= 0.4; y += 0.05) open_left.push_back({0.45, y});
  for (double x = -5; x <= 0.45; x += 0.05) open_left.push_back({x, -0.4});
  const auto left = r.openDirection(open_left, 0.3, 4.0, 0.0);
  ASSERT_TRUE(left.has_value());
  EXPECT_GT(*left, 0.0);
  EXPECT_LT(*left, M_PI - 0.1);
  // The way back lies in the laser's blind sector (no range points there, which is not free
  // floor: a person can stand at the robot's back): not taken without a scan that saw it free.
  const auto seen_ahead = [](double a, double) { return std::abs(a) <= 2.1; };
  EXPECT_FALSE(r.openDirection(dead_end, 0.3, 4.0, 0.0, seen_ahead).has_value());
  const auto left_seen = r.openDirection(open_left, 0.3, 4.0, 0.0, seen_ahead);
  ASSERT_TRUE(left_seen.has_value());
  EXPECT_NEAR(*left_seen, *left, 1e-9);
  // A person who walked up to the robot's side (within the corridors' half-width of its
  // centre, their body 0.03 m from its own) is in the way of the directions towards them
  // only: driving off, the robot gets further from them.
  std::vector<std::pair<double, double>> beside;
  for (double a = -0.6; a <= 0.6; a += 0.1)  // the near side of a 0.2 m body centred 0.43 m right
    beside.push_back({0.2 * std::sin(a), -0.43 + 0.2 * std::cos(a)});
  const auto away = r.openDirection(beside, 0.32, 4.0, -M_PI / 2);
  ASSERT_TRUE(away.has_value());
  EXPECT_GT(*away, 0.0) << "away from the person on the right";
  // Boxed in all round: nowhere.
  std::vector<std::pair<double, double>> box;
  for (int i = 0; i < 360; ++i) box.push_back({0.3 * std::cos(i * kDeg), 0.3 * std::sin(i * kDeg)});
  EXPECT_FALSE(r.openDirection(box, 0.3, 4.0, 0.0).has_value());

  const hw::Pose2D from{1, 1, 0};
  const auto ev = r.start(M_PI / 2, from, 100.0);
  EXPECT_NEAR(ev.direction_deg, 90, 1e-9);
  EXPECT_TRUE(r.active());
  EXPECT_EQ(r.count(), 1);
  // Facing away from the escape heading: turn on the spot first.
  auto s = r.step(from, 100.1, 0.2);
  EXPECT_DOUBLE_EQ(s.command.v, 0.0);
  EXPECT_DOUBLE_EQ(s.command.w, 0.8);
  EXPECT_FALSE(s.ended);
  // Aligned: drive at the capped speed until 1 m from where it started.
  s = r.step({1, 1.5, M_PI / 2}, 103.0, 0.2);
  EXPECT_DOUBLE_EQ(s.command.v, 0.2);
  EXPECT_FALSE(s.ended);
  s = r.step({1, 2.0, M_PI / 2}, 105.0, 0.2);
  EXPECT_TRUE(s.ended);
  EXPECT_FALSE(r.active());
  // Out of time, or aligned with nothing free ahead (blocked): over too.
  r.start(0.0, from, 200.0);
  EXPECT_TRUE(r.step(from, 208.1, 0.2).ended);
  r.start(0.0, from, 300.0);
  EXPECT_TRUE(r.step(from, 300.1, 0.0).ended);
  EXPECT_EQ(r.count(), 3);
  // A look (the way out unseen): turn to face it, never drive, over once it is ahead.
  const auto look = r.start(M_PI, from, 400.0, true);
  EXPECT_TRUE(look.look);
  EXPECT_TRUE(r.looking());
  s = r.step(from, 400.1, 0.2);
  EXPECT_DOUBLE_EQ(s.command.v, 0.0);
  EXPECT_DOUBLE_EQ(std::abs(s.command.w), 0.8);
  EXPECT_FALSE(s.ended);
  s = r.step({1, 1, 2.9}, 402.0, 0.2);
  EXPECT_DOUBLE_EQ(s.command.v, 0.0);
  EXPECT_TRUE(s.ended);
  EXPECT_FALSE(r.start(0.0, from, 500.0).look);
  EXPECT_FALSE(r.looking());
}

// Docking: a free line to the goal is driven straight, slowing in the last 0.6 m; a blocked
// line takes a short way round when one is planned, and nothing when the way is long or none.
TEST(Docking, DrivesAFreeLineOrAShortWayRoundToTheGoal) {
  const DriveParams drive;           // 0.3 m/s
  const Docking dock(DockParams{});  // dock_m 1.5
  const auto at = [](double range, double bearing) {
    Polar g;
    g.range = range;
    g.bearing = bearing;
    return g;
  };
  EXPECT_TRUE(dock.near(1.5));
  EXPECT_FALSE(dock.near(1.6));
  int planned = 0;
  const auto way = [&](double bearing, double length, double left) {
    return [&planned, bearing, length, left]() -> std::optional<Docking::WayRound> {
      ++planned;
      return Docking::WayRound{bearing, length, left};
    };
  };
  // Free: straight at the goal, the plan never asked for.
  auto d = dock.propose(at(1.2, 0.2), 3.0, way(-0.5, 1.0, 1.0), drive);
  ASSERT_TRUE(d);
  EXPECT_EQ(planned, 0);
  EXPECT_DOUBLE_EQ(d->bearing, 0.2);
  EXPECT_NEAR(d->command.v, 0.3 * std::cos(0.2), 1e-12);  // 1.2 m left: full speed
  EXPECT_EQ(d->command.turn, servo::Turn::Left);
  d = dock.propose(at(0.3, 0.0), 3.0, nullptr, drive);  // 0.3 m left: half speed
  ASSERT_TRUE(d);
  EXPECT_NEAR(d->command.v, 0.15, 1e-12);
  EXPECT_EQ(d->command.turn, servo::Turn::Straight);
  d = dock.propose(at(0.05, 0.0), 3.0, nullptr, drive);  // never below 30 %
  EXPECT_NEAR(d->command.v, 0.09, 1e-12);
  // Blocked: the way round's bearing and what is left of it.
  d = dock.propose(at(1.2, 0.0), 0.5, way(-0.3, 2.0, 0.6), drive);
  ASSERT_TRUE(d);
  EXPECT_EQ(planned, 1);
  EXPECT_DOUBLE_EQ(d->bearing, -0.3);
  EXPECT_NEAR(d->command.v, 0.3 * std::cos(0.3), 1e-12);
  EXPECT_EQ(d->command.turn, servo::Turn::Right);
  // A long way round (over dock_m + 1.5 m): the goal estimate is behind a wall.
  EXPECT_FALSE(dock.propose(at(1.2, 0.0), 0.5, way(-0.3, 3.1, 3.0), drive));
  // No way found, or no planning: no docking.
  EXPECT_FALSE(dock.propose(
      at(1.2, 0.0), 0.5, [] { return std::optional<Docking::WayRound>(); }, drive));
  EXPECT_FALSE(dock.propose(at(1.2, 0.0), 0.5, nullptr, drive));
}

TEST(Detour, GoesRoundWhatStandsStillAndLeavesWhatComesTowardsTheRobotToTheDodge) {
  LocalPlanner planner;
  auto boxes = test::room();
  boxes.push_back({3, 0, 0.3, 0.3});  // in the way of the route along y = 0
  planner.insert({0, 0, 0}, test::scanAt({0, 0, 0}, boxes));
  const hw::Pose2D pose{0, 0, 0};
  const Eigen::Vector2d route_point(6, 0);
  const auto free = [](double v) { return v; };
  Detour d(DetourParams{}, DriveParams{});
  AvoidOutput av;
  av.active = av.started = true;
  // Something standing still: a way round, planned once and followed.
  auto o = d.whileDodging(av, planner, pose, route_point, 0.0, 2, free);
  ASSERT_TRUE(o.started);
  EXPECT_EQ(o.started->section, 2);
  EXPECT_GT(o.started->length_m, 6.0);  // round the box, not through it
  ASSERT_TRUE(o.command);
  EXPECT_NE(o.command->turn, servo::Turn::Straight);
  EXPECT_TRUE(d.active());
  av.started = false;
  o = d.whileDodging(av, planner, pose, route_point, 0.1, 2,
                     [](double v) { return std::min(v, 0.1); });
  EXPECT_FALSE(o.started);
  ASSERT_TRUE(o.command);
  EXPECT_LE(o.command->v, 0.1);  // the clearance ahead caps it
  EXPECT_EQ(d.count(), 1);
  // Something comes towards the robot: the reactive dodge drives for the rest of the
  // manoeuvre, even once the approach estimate drops.
  av.approach_speed = 0.4;
  o = d.whileDodging(av, planner, pose, route_point, 0.2, 2, free);
  ASSERT_TRUE(o.ended);
  EXPECT_EQ(o.ended->reason, "coming towards the robot");
  EXPECT_FALSE(o.command);
  EXPECT_TRUE(d.movingSeen());
  av.approach_speed = 0;
  o = d.whileDodging(av, planner, pose, route_point, 0.3, 2, free);
  EXPECT_FALSE(o.command || o.ended || o.started);
  // A walker's lane counts the same; a new manoeuvre forgets.
  av.started = true;
  o = d.whileDodging(av, planner, pose, route_point, 0.4, 2, free);
  EXPECT_TRUE(o.command && o.started);
  EXPECT_EQ(d.count(), 2);
  av.started = false;
  av.in_lane = true;
  o = d.whileDodging(av, planner, pose, route_point, 0.5, 2, free);
  EXPECT_FALSE(o.command);
  ASSERT_TRUE(o.ended);

  // Off: never planned.
  DetourParams off;
  off.detour = false;
  Detour none(off, DriveParams{});
  av = AvoidOutput{};
  av.active = av.started = true;
  o = none.whileDodging(av, planner, pose, route_point, 0.0, 0, free);
  EXPECT_FALSE(o.command || o.started || o.ended);
}

TEST(Detour, HeldAfterTheDodgeUntilTheLineToTheRouteIsClear) {
  LocalPlanner planner;
  auto boxes = test::room();
  boxes.push_back({3, 0, 0.3, 0.3});
  planner.insert({0, 0, 0}, test::scanAt({0, 0, 0}, boxes));
  const auto free = [](double v) { return v; };
  const double hwid = 0.3;
  DetourParams hold;
  hold.detour_hold = true;
  Detour d(hold, DriveParams{});
  AvoidOutput av;
  av.active = av.started = true;
  ASSERT_TRUE(d.whileDodging(av, planner, {0, 0, 0}, {6, 0}, 0.0, 0, free).command);
  // The avoider has let go, the box still between the robot and the route point: held.
  auto o = d.afterDodge(planner, {1.5, 0.5, 0}, {6, 0}, 0.1, false, hwid, free);
  EXPECT_TRUE(o.command);
  EXPECT_FALSE(o.ended);
  // Past the box: the line is clear, the detour ends.
  o = d.afterDodge(planner, {4.5, 0.8, 0}, {6, 0}, 0.2, false, hwid, free);
  EXPECT_FALSE(o.command);
  ASSERT_TRUE(o.ended);
  EXPECT_EQ(o.ended->reason, "route clear");
  EXPECT_FALSE(d.active());
  // Without holding, the servo taking over ends it, and nothing else does.
  Detour plain(DetourParams{}, DriveParams{});
  ASSERT_TRUE(plain.whileDodging(av, planner, {0, 0, 0}, {6, 0}, 0.0, 0, free).command);
  o = plain.afterDodge(planner, {1.5, 0.8, 0}, {6, 0}, 0.1, false, hwid, free);
  EXPECT_FALSE(o.command || o.ended);
  o = plain.afterDodge(planner, {1.5, 0.8, 0}, {6, 0}, 0.2, true, hwid, free);
  ASSERT_TRUE(o.ended);
  EXPECT_EQ(o.ended->reason, "servoing");
}

TEST(YieldBehaviour, WaitsShortOfALaneStepsOutOfOneAndBacksOnlyWithRoom) {
  YieldBehaviour y(0.1);
  const Command cur{0.3, 0.2, servo::Turn::Left};
  const hw::Pose2D pose{1, 2, 0.5};
  int asked = 0;
  double rear = 0.4;
  const auto rear_free = [&] {
    ++asked;
    return rear;
  };
  const auto half = [](double v) { return 0.5 * v; };
  YieldAdvice adv;
  auto o = y.update(adv, cur, pose, half, rear_free);
  EXPECT_FALSE(o.command || o.started || o.ended);
  // About to enter a lane: wait, the turn kept.
  adv.active = true;
  adv.clearance_m = 1.7;
  adv.mover.position = {3, 2};
  o = y.update(adv, cur, pose, half, rear_free);
  ASSERT_TRUE(o.command && o.started);
  EXPECT_EQ(o.command->v, 0.0);
  EXPECT_EQ(o.command->w, 0.2);
  EXPECT_FALSE(o.started->in_lane);
  EXPECT_DOUBLE_EQ(o.started->clearance_m, 1.7);
  EXPECT_EQ(o.started->mover_odom, Eigen::Vector2d(3, 2));
  // In one: step out as advised, capped by the clearance ahead; one yield, not two.
  adv.in_lane = true;
  adv.v = 0.2;
  adv.w = -0.5;
  o = y.update(adv, cur, pose, half, rear_free);
  ASSERT_TRUE(o.command);
  EXPECT_FALSE(o.started);
  EXPECT_DOUBLE_EQ(o.command->v, 0.1);
  EXPECT_EQ(o.command->turn, servo::Turn::Right);
  EXPECT_EQ(asked, 0);
  // Backing: only with room behind.
  adv.v = -0.1;
  o = y.update(adv, cur, pose, half, rear_free);
  EXPECT_EQ(o.command->v, 0.0);
  rear = 2.0;
  o = y.update(adv, cur, pose, half, rear_free);
  EXPECT_DOUBLE_EQ(o.command->v, -0.1);
  EXPECT_EQ(asked, 2);
  EXPECT_TRUE(y.active());
  // The lane is clear: the yield ends once.
  adv.active = false;
  o = y.update(adv, cur, pose, half, rear_free);
  EXPECT_TRUE(o.ended);
  EXPECT_FALSE(o.command);
  EXPECT_FALSE(y.active());
  EXPECT_FALSE(y.update(adv, cur, pose, half, rear_free).ended);
  EXPECT_EQ(y.count(), 1);
}

TEST(BehaviourParams, ValidateNamesTheSetting) {
  auto names = [](auto p, auto&& spoil, const char* key) {
    EXPECT_NO_THROW(p.validate());
    spoil(p);
    try {
      p.validate();
      ADD_FAILURE() << key << " accepted";
    } catch (const std::exception& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  };
  names(
      DriveParams{}, [](DriveParams& p) { p.max_w = 0; }, "nav.max_w");
  names(
      DetourParams{}, [](DetourParams& p) { p.detour_ahead_m = 0.5; }, "nav.detour_ahead_m");
  names(
      DetourParams{}, [](DetourParams& p) { p.replan_s = 0; }, "nav.replan_s");
  names(
      LookParams{}, [](LookParams& p) { p.look_bearing_deg = 95; }, "nav.look_bearing_deg");
  names(
      SideLookParams{}, [](SideLookParams& p) { p.side_look_min_range_m = 5; },
      "nav.side_look_min_range_m");
  names(
      SideLookParams{}, [](SideLookParams& p) { p.side_look_max_looks = 0; },
      "nav.side_look_max_looks");
  names(
      SideLookParams{}, [](SideLookParams& p) { p.side_look_rebearing_deg = 0; },
      "nav.side_look_rebearing_deg");
  names(
      FinalLookParams{}, [](FinalLookParams& p) { p.final_look_s = 0; }, "nav.final_look_s");
  names(
      RecoverParams{}, [](RecoverParams& p) { p.recover_m = 0; }, "nav.recover_m");
  names(
      RecoverParams{}, [](RecoverParams& p) { p.recover_back_m = -1; }, "nav.recover_back_m");
  names(
      RecoverParams{}, [](RecoverParams& p) { p.recover_back_speed = 0; },
      "nav.recover_back_speed");
  names(
      DockParams{}, [](DockParams& p) { p.dock_m = -1; }, "nav.dock_m");
}

TEST(Trail, BacksOutOnlyStraightAlongTheWayItCame) {
  Trail t;
  EXPECT_FALSE(t.backOut({0, 0}, 0.5, 0.1).has_value()) << "no trail yet";
  for (double x = 0; x <= 2.0001; x += 0.01) t.add({x, 0.02 * std::sin(7 * x)});
  const auto to = t.backOut({2, 0}, 0.5, 0.1);
  ASSERT_TRUE(to.has_value());
  EXPECT_NEAR(to->x(), 1.5, 0.06);
  EXPECT_LT(std::abs(to->y()), 0.03);
  EXPECT_FALSE(t.backOut({2, 0}, 2.5, 0.1).has_value()) << "longer than the trail";
  // Round a corner 0.3 m back: the straight line back leaves the floor the robot came over.
  Trail corner;
  for (double x = 0; x <= 1.0001; x += 0.01) corner.add({x, 0});
  for (double y = 0.01; y <= 0.30001; y += 0.01) corner.add({1, y});
  EXPECT_FALSE(corner.backOut({1, 0.3}, 0.5, 0.1).has_value());
  EXPECT_TRUE(corner.backOut({1, 0.3}, 0.25, 0.1).has_value()) << "the straight part";
  // Only the last keep_m (3 m) of path is kept.
  Trail longer;
  for (double x = 0; x <= 10.0001; x += 0.01) longer.add({x, 0});
  EXPECT_TRUE(longer.backOut({10, 0}, 2.9, 0.1).has_value());
  EXPECT_FALSE(longer.backOut({10, 0}, 3.2, 0.1).has_value());
  // Backed out to 9.5: the trail ends there, so the next back-out goes further back, not
  // forward again over the stretch just reversed.
  longer.backTo({9.5, 0});
  const auto again = longer.backOut({9.5, 0}, 0.5, 0.1);
  ASSERT_TRUE(again.has_value());
  EXPECT_NEAR(again->x(), 9.0, 0.06);
}

TEST(Recovery, BacksOutAlongTheTrailThenEnds) {
  RecoverParams p;  // 0.1 m/s back, 8 s at most
  Recovery r(p, 1.5, 0.8);
  const auto ev = r.startBack({1.5, 0}, {2, 0, 0}, 10.0);
  EXPECT_TRUE(ev.back);
  EXPECT_FALSE(ev.look);
  EXPECT_NEAR(std::abs(ev.direction_deg), 180, 1e-9);
  EXPECT_TRUE(r.active());
  EXPECT_TRUE(r.backing());
  EXPECT_TRUE((NavEvent{10.0, ev}.toJson().value("back", false)));
  // Facing away from the point behind: reverse slowly, no turn.
  auto s = r.step({2, 0, 0}, 10.1, 0.3);
  EXPECT_DOUBLE_EQ(s.command.v, -p.recover_back_speed);
  EXPECT_NEAR(s.command.w, 0.0, 1e-9);
  EXPECT_FALSE(s.ended);
  // Drifted off the line: steers back onto it while reversing (the point to the robot's
  // right-behind: turn so the back points at it).
  s = r.step({1.8, 0.05, 0}, 12.0, 0.3);
  EXPECT_LT(s.command.v, 0.0);
  EXPECT_GT(s.command.w, 0.0);
  // Turned far away from it: turn on the spot first.
  s = r.step({1.8, 0, 1.2}, 12.5, 0.3);
  EXPECT_DOUBLE_EQ(s.command.v, 0.0);
  EXPECT_FALSE(s.ended);
  // There: over, and a forward recovery afterwards is not a back-out.
  s = r.step({1.53, 0, 0}, 14.0, 0.3);
  EXPECT_TRUE(s.ended);
  EXPECT_FALSE(r.active());
  r.startBack({1.5, 0}, {2, 0, 0}, 20.0);
  EXPECT_TRUE(r.step({1.9, 0, 0}, 28.5, 0.3).ended) << "out of time (recover_s)";
  EXPECT_FALSE(r.start(0.5, {0, 0, 0}, 30.0).back);
  EXPECT_FALSE(r.backing());
}

}  // namespace
}  // namespace sketchnav::nav
