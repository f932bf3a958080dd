// The landmark tracker on its own: misses in a row and the "lost" verdict, passing (and what it
// settles behind the robot), which detection goes to which landmark, losing a track from view,
// the pass distance, holding a section open and the final look's candidate.
#include <gtest/gtest.h>

#include <cmath>

#include "route_util.h"
#include "sketchnav/nav/landmark_tracker.h"

namespace sketchnav::nav {
namespace {

using mapsketch::Side;

// Two sections along x then y; A, B, C, D beside the first, E on the second.
mapsketch::Route fiveLandmarks() {
  return test::makeRoute({{0, 0}, {10, 0}, {10, 8}}, {{0, "A", "sign", {2, 1}, Side::Left},
                                                      {0, "B", "carton", {4, -1}, Side::Right},
                                                      {0, "C", "carton", {6, 1}, Side::Left},
                                                      {0, "D", "box", {8, -1}, Side::Right},
                                                      {1, "E", "sign", {11, 4}, Side::Right}});
}

Detection det(const std::string& cls, double bearing, int inliers = 20) {
  Detection d;
  d.class_name = cls;
  d.bearing = bearing;
  d.inliers = inliers;
  d.x_t = -bearing;
  return d;
}

TEST(LandmarkTracker, MoreMissesInARowThanAllowedAreLostWithTheirIds) {
  const auto route = fiveLandmarks();
  LandmarkTrackerParams p;
  p.max_missed_in_row = 2;
  LandmarkTracker lt(route, p);
  auto a = lt.miss(0, 0);
  EXPECT_EQ(a.event.id, "A");
  EXPECT_EQ(a.event.class_name, "sign");
  EXPECT_FALSE(a.event.seen_before);
  EXPECT_FALSE(a.lost);
  EXPECT_FALSE(lt.miss(0, 1).lost);
  const auto c = lt.miss(0, 2);
  ASSERT_TRUE(c.lost.has_value());
  EXPECT_EQ(*c.lost, "lost: 3 landmarks in a row not found (A, B, C)");
  EXPECT_EQ(lt.track(0, 2).state, LandmarkState::Missed);
  // A miss that does not count leaves the run as it is.
  LandmarkTracker lt2(route, p);
  lt2.miss(0, 0);
  EXPECT_FALSE(lt2.miss(0, 1, false).lost);
  EXPECT_FALSE(lt2.miss(0, 2).lost);
}

TEST(LandmarkTracker, PassingSettlesTheLandmarksBehindAndEndsTheRunOfMisses) {
  const auto route = fiveLandmarks();
  LandmarkTracker lt(route, {});
  lt.miss(0, 0);                   // A: one miss so far
  lt.track(0, 1).frames_seen = 3;  // B: seen, then lost from view (pending)
  // D is passed first (it was seen before C): B was seen, so it is passed too; C was never
  // seen, so it is missed, and that does not count towards "lost".
  const auto behind = lt.pass(0, 3);
  ASSERT_EQ(behind.size(), 1u);
  EXPECT_EQ(behind[0].event.id, "C");
  EXPECT_FALSE(behind[0].lost);
  EXPECT_EQ(lt.track(0, 0).state, LandmarkState::Missed);
  EXPECT_EQ(lt.track(0, 1).state, LandmarkState::Passed);
  EXPECT_EQ(lt.track(0, 2).state, LandmarkState::Missed);
  EXPECT_EQ(lt.track(0, 3).state, LandmarkState::Passed);
  EXPECT_EQ(lt.track(1, 0).state, LandmarkState::Pending);
  // The run of misses starts again after a pass: with a limit of 1, two misses after it are lost.
  LandmarkTrackerParams strict;
  strict.max_missed_in_row = 1;
  LandmarkTracker lt2(route, strict);
  lt2.miss(0, 0);
  lt2.pass(0, 1);
  EXPECT_FALSE(lt2.miss(0, 2).lost);
  EXPECT_TRUE(lt2.miss(0, 3).lost);
}

TEST(LandmarkTracker, EachAttendedLandmarkGetsTheDetectionWhereItIsExpected) {
  const auto route = fiveLandmarks();
  SectionTracker sections(route);
  RouteAnchor anchor;
  anchor.start(sections);
  LandmarkTracker lt(route, {});
  const hw::Pose2D pose{1, 0, 0};
  // B and C are both cartons: B expected 40 deg right, C 20 deg left.
  std::vector<AttendedLandmark> att = {{0, 1, {-0.7, 3.2}, true}, {0, 2, {0.35, 5.1}, true}};
  std::vector<Detection> ds = {det("carton", 0.3), det("carton", -0.65)};
  ds[0].recognised_only = true;  // C's: placed by a loose match, steers but gives no sighting
  std::vector<Candidate> all = {{&ds[0], 0.0}, {&ds[1], 3.0}};
  std::vector<bool> used(all.size(), false);
  const auto expect = lt.expectations(att, pose);
  const auto b = lt.associate(att, 0, expect, all, used, anchor, {}, pose, 10.0, 0.2, true);
  ASSERT_TRUE(b.has_value());
  EXPECT_EQ(b->detection, &ds[1]);
  EXPECT_DOUBLE_EQ(b->range_m, 3.0);
  ASSERT_TRUE(b->seen.has_value());
  EXPECT_EQ(b->seen->id, "B");
  EXPECT_TRUE(b->seen->attended_first);
  EXPECT_EQ(b->seen->candidates, 2u);
  const auto c = lt.associate(att, 1, expect, all, used, anchor, {}, pose, 10.0, 0.2, true);
  ASSERT_TRUE(c.has_value());
  EXPECT_EQ(c->detection, &ds[0]);
  EXPECT_FALSE(c->seen->attended_first);
  EXPECT_EQ(c->seen->candidates, 1u) << "B's detection is used";
  const auto& tb = lt.track(0, 1);
  EXPECT_EQ(tb.state, LandmarkState::Tracking);
  EXPECT_EQ(tb.frames_seen, 1);
  EXPECT_EQ(tb.max_inliers, 20);
  EXPECT_DOUBLE_EQ(tb.last_seen, 10.0);
  ASSERT_EQ(tb.sightings.size(), 1u);
  EXPECT_NEAR(tb.sightings[0].direction, -0.65, 1e-12);
  EXPECT_NEAR(tb.sightings[0].camera_along_m, 0.2 * std::cos(-0.65), 1e-12);
  EXPECT_TRUE(lt.track(0, 2).sightings.empty()) << "recognised-only: no sighting";
  // Seen again: no new "seen" event; nothing left to give: nothing.
  std::vector<bool> fresh(all.size(), false);
  const auto again = lt.associate(att, 0, lt.expectations(att, pose), all, fresh, anchor, {}, pose,
                                  10.1, 0.2, true);
  ASSERT_TRUE(again.has_value());
  EXPECT_FALSE(again->seen.has_value());
  EXPECT_EQ(lt.track(0, 1).frames_seen, 2);
  std::vector<bool> none(all.size(), true);
  EXPECT_FALSE(lt.associate(att, 0, expect, all, none, anchor, {}, pose, 10.2, 0.2, true));
}

TEST(LandmarkTracker, AFarRangeIsKeptAsABearingOnlyWhenAsked) {
  const auto route = fiveLandmarks();
  SectionTracker sections(route);
  RouteAnchor anchor;
  anchor.start(sections);
  const hw::Pose2D pose{0, 0, 0};
  std::vector<AttendedLandmark> att = {{0, 3, {-0.12, 8.1}, true}};
  std::vector<Detection> ds = {det("box", -0.12)};
  std::vector<Candidate> all = {{&ds[0], 8.0}};
  for (bool keep : {true, false}) {
    LandmarkTracker lt(route, {});
    std::vector<bool> used(1, false);
    ASSERT_TRUE(
        lt.associate(att, 0, lt.expectations(att, pose), all, used, anchor, {}, pose, 1, 0, keep));
    const auto& ss = lt.track(0, 3).sightings;
    if (!keep) {
      EXPECT_TRUE(ss.empty());
      continue;
    }
    ASSERT_EQ(ss.size(), 1u);  // beyond fixRange (4 m): a bearing, the reading kept as beyond_m
    EXPECT_EQ(ss[0].range_m, 0.0);
    EXPECT_EQ(ss[0].beyond_m, 8.0);
  }
}

TEST(LandmarkTracker, ARangeTheSketchRefusesIsKeptAsGatedForTheFix) {
  // D (the only box) predicted 2 m ahead; the laser along its bearing reads 3.8 m, outside the
  // range gate: taken by its bearing, the reading kept for locateLandmark to judge.
  const auto route = fiveLandmarks();
  SectionTracker sections(route);
  RouteAnchor anchor;
  anchor.start(sections);
  const hw::Pose2D pose{0, 0, 0};
  std::vector<AttendedLandmark> att = {{0, 3, {-0.12, 2.0}, true}};
  std::vector<Detection> ds = {det("box", -0.12)};
  std::vector<Candidate> all = {{&ds[0], 3.8}};
  LandmarkTracker lt(route, {});
  std::vector<bool> used(1, false);
  const auto a =
      lt.associate(att, 0, lt.expectations(att, pose), all, used, anchor, {}, pose, 1, 0, true);
  ASSERT_TRUE(a.has_value());
  ASSERT_TRUE(a->seen.has_value());
  EXPECT_TRUE(a->seen->range_dropped);
  EXPECT_EQ(a->range_m, 0.0);
  const auto& ss = lt.track(0, 3).sightings;
  ASSERT_EQ(ss.size(), 1u);
  EXPECT_EQ(ss[0].range_m, 0.0);
  EXPECT_EQ(ss[0].gated_range_m, 3.8);
}

TEST(LandmarkTracker, ADetectionWhereAnEarlierLandmarkOfItsClassWasFixedIsNotTheNextOne) {
  const auto route = fiveLandmarks();
  SectionTracker sections(route);
  RouteAnchor anchor;
  anchor.start(sections);
  // B (carton) was located at (4, -1).
  std::vector<Sighting> ss;
  for (int j = 0; j < 6; ++j) {
    const Eigen::Vector2d o(1.0 + 0.4 * j, 0);
    ss.push_back({o, std::atan2(-1.0, 4.0 - o.x()), 0.0});
  }
  ASSERT_TRUE(anchor.correct(sections, {4, -1}, "carton", ss, {}).fix);
  LandmarkTracker lt(route, {});
  lt.pass(0, 1);
  // From (3, 0) the robot sees a carton at B's place (45 deg right, 1.41 m) and nothing else:
  // C, the next carton, is expected 60 deg left, but a wide gate would still take it.
  const hw::Pose2D pose{3, 0, 0};
  SelectParams wide;
  wide.bearing_gate_deg = 180;
  wide.range_gate_min_m = 10;
  std::vector<AttendedLandmark> att = {{0, 2, {0.32, 3.2}, true}};
  std::vector<Detection> ds = {det("carton", -M_PI / 4)};
  std::vector<Candidate> all = {{&ds[0], std::sqrt(2.0)}};
  std::vector<bool> used(1, false);
  EXPECT_FALSE(
      lt.associate(att, 0, lt.expectations(att, pose), all, used, anchor, wide, pose, 1, 0, true));
  EXPECT_EQ(lt.track(0, 2).state, LandmarkState::Pending);
  // Another class there is not that landmark's business.
  std::vector<AttendedLandmark> att_d = {{0, 3, {-0.2, 5.1}, true}};
  std::vector<Detection> box = {det("box", -M_PI / 4)};
  std::vector<Candidate> all_d = {{&box[0], std::sqrt(2.0)}};
  std::vector<bool> used_d(1, false);
  EXPECT_TRUE(lt.associate(att_d, 0, lt.expectations(att_d, pose), all_d, used_d, anchor, wide,
                           pose, 1, 0, true));
}

TEST(LandmarkTracker, ATrackUnseenTooLongIsPassedWhenCloseElseLookedForAgain) {
  const auto route = fiveLandmarks();
  LandmarkTrackerParams p;
  p.lost_after_s = 2.0;
  LandmarkTracker lt(route, p);
  auto& a = lt.track(0, 0);
  a.state = LandmarkState::Tracking;
  a.last_seen = 10.0;
  a.last_range = 2.0;  // A is 1 m off the path: passed within max(1.4, 1) + 1 m
  EXPECT_EQ(lt.checkUnseen(0, 0, 11.9), LandmarkTracker::Unseen::No);
  EXPECT_EQ(lt.checkUnseen(0, 0, 12.1), LandmarkTracker::Unseen::AtIt);
  EXPECT_EQ(a.state, LandmarkState::Tracking) << "the executive passes it";
  a.last_range = 3.0;
  EXPECT_EQ(lt.checkUnseen(0, 0, 12.1), LandmarkTracker::Unseen::LostToView);
  EXPECT_EQ(a.state, LandmarkState::Pending);
  EXPECT_EQ(lt.checkUnseen(0, 0, 20.0), LandmarkTracker::Unseen::No) << "pending: no track";
  a.state = LandmarkState::Tracking;
  a.last_range = 0;  // no range: never "at it"
  EXPECT_EQ(lt.checkUnseen(0, 0, 12.1), LandmarkTracker::Unseen::LostToView);
}

TEST(LandmarkTracker, PassDistanceIsTheLateralOffsetClampedOrTheDistanceFromTheEnd) {
  const auto route =
      test::makeRoute({{0, 0}, {10, 0}, {10, 8}}, {{0, "near", "sign", {2, 0.5}, Side::Left},
                                                   {0, "mid", "sign", {4, 2.0}, Side::Left},
                                                   {0, "far", "sign", {6, -4}, Side::Right},
                                                   {0, "wall", "sign", {12, 0}, Side::Ahead}});
  LandmarkTracker lt(route, {});
  EXPECT_DOUBLE_EQ(lt.passDistance(0, 0), 1.4);  // approach_m
  EXPECT_DOUBLE_EQ(lt.passDistance(0, 1), 2.0);
  EXPECT_DOUBLE_EQ(lt.passDistance(0, 2), 2.5);  // max_approach_m
  EXPECT_DOUBLE_EQ(lt.passDistance(0, 3), 2.0);  // ahead beyond the end: 2 m from it
  EXPECT_TRUE(lt.atLandmark(0, 1, 3.0));
  EXPECT_FALSE(lt.atLandmark(0, 1, 3.1));
  EXPECT_FALSE(lt.atLandmark(0, 1, 0.0));
  EXPECT_DOUBLE_EQ(lt.fixRange(), 4.0);
}

TEST(LandmarkTracker, AServoedLandmarkHoldsItsSectionOpen) {
  const auto route = fiveLandmarks();
  LandmarkTracker lt(route, {});
  EXPECT_FALSE(lt.holdsSection(0, 5.0, 1.0));
  auto& c = lt.track(0, 2);
  c.state = LandmarkState::Tracking;
  c.last_seen = 4.5;
  EXPECT_TRUE(lt.holdsSection(0, 5.0, 1.0));
  EXPECT_FALSE(lt.holdsSection(0, 5.6, 1.0)) << "not seen for longer than 1 s";
  EXPECT_FALSE(lt.holdsSection(0, 5.0, 1.0, 2)) << "the final look's own does not";
  EXPECT_FALSE(lt.holdsSection(1, 5.0, 1.0)) << "another section's";
}

TEST(LandmarkTracker, TheFinalLookLooksForTheNearestLandmarkNeverSeen) {
  const auto route = fiveLandmarks();
  SectionTracker sections(route);
  LandmarkTracker lt(route, {});
  const hw::Pose2D at_d{8, 0, 0};
  double r = 0;
  auto c = lt.finalLookCandidate(sections, at_d, 4.0, r);
  ASSERT_TRUE(c.has_value());
  EXPECT_EQ(*c, std::make_pair(0, 3));  // D, 1 m away
  EXPECT_NEAR(r, 1.0, 1e-9);
  lt.track(0, 3).frames_seen = 1;  // D was seen: C (2.24 m), missed on the way, is next
  lt.miss(0, 2);
  c = lt.finalLookCandidate(sections, at_d, 4.0, r);
  ASSERT_TRUE(c.has_value());
  EXPECT_EQ(*c, std::make_pair(0, 2));
  lt.pass(0, 2);  // passed: no longer looked for; nothing else within 2 m
  EXPECT_FALSE(lt.finalLookCandidate(sections, at_d, 2.0, r).has_value());
}

TEST(LandmarkTrackerParams, ValidateNamesTheSetting) {
  LandmarkTrackerParams p;
  EXPECT_NO_THROW(p.validate());
  p.approach_m = 3.0;  // more than max_approach_m
  try {
    p.validate();
    FAIL() << "approach_m > max_approach_m accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("nav.approach_m"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace sketchnav::nav
