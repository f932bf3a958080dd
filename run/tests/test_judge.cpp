// The ground-truth judge (run/judge.h): pure functions, no simulation.
#include <gtest/gtest.h>

#include <string>

#include "sketchnav/nav/executive.h"
#include "sketchnav/run/judge.h"

namespace sketchnav::run {
namespace {

// summary.json's "success" in simulation is ground truth (doc/navigation.md), not the
// executive's belief: a pure function, no simulation.
TEST(RunVerdict, SuccessIsInTheGoalRegionAndNothingHitWhateverTheExecutiveSays) {
  // In the goal, executive failed during the final look: a success, and the reason says so.
  auto v = judgeSimulatedRun(false, "lost: 3 landmarks in a row not found", true, false, "", 0.16);
  EXPECT_TRUE(v.success);
  EXPECT_NE(v.reason.find("reached the goal region"), std::string::npos) << v.reason;
  EXPECT_NE(v.reason.find("lost: 3 landmarks"), std::string::npos) << v.reason;
  v = judgeSimulatedRun(true, "", true, false, "", 0.1);
  EXPECT_TRUE(v.success);
  EXPECT_EQ(v.reason, "reached the goal");
  // The executive believed it arrived, the robot stands 1.2 m off: a failure.
  v = judgeSimulatedRun(true, "", false, false, "", 1.2);
  EXPECT_FALSE(v.success);
  EXPECT_NE(v.reason.find("1.20 m from the goal"), std::string::npos) << v.reason;
  // Anything hit fails, in the goal region or not.
  v = judgeSimulatedRun(true, "", true, true, "pedestrian 1", 0.1);
  EXPECT_FALSE(v.success);
  EXPECT_NE(v.reason.find("collision with pedestrian 1"), std::string::npos);
  v = judgeSimulatedRun(false, "no progress after 102 s", false, false, "", 3);
  EXPECT_FALSE(v.success);
  EXPECT_EQ(v.reason, "no progress after 102 s");
}

// summary.json's "failure" code: ground truth's codes first, then the executive's.
TEST(FailureCode, GroundTruthFirstThenTheExecutivesCode) {
  nav::ExecutiveSummary es;
  es.status = nav::RunStatus::Succeeded;
  EXPECT_EQ(failureCode(true, false, es), "");
  EXPECT_EQ(failureCode(false, true, es), "collision");
  EXPECT_EQ(failureCode(false, false, es), "short_of_goal");
  es.status = nav::RunStatus::Failed;
  es.failure = nav::FailureCode::Lost;
  EXPECT_EQ(failureCode(false, false, es), "lost");
  EXPECT_EQ(failureCode(false, true, es), "collision");
}

}  // namespace
}  // namespace sketchnav::run
