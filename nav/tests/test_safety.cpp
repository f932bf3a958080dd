// The safety supervisor's fault detection (the executive tests check the stop itself).
#include <gtest/gtest.h>

#include "sketchnav/nav/safety.h"

using namespace sketchnav::nav;

TEST(Safety, HealthyStreamsAreOk) {
  SafetySupervisor s;
  s.start(0);
  for (double t = 0; t < 2; t += 0.05) {
    s.odometry(t);
    s.rangeScan(t);
    if (static_cast<int>(t * 20 + 0.5) % 2 == 0) s.cameraFrame(t);
    EXPECT_TRUE(s.check(t + 0.01, true).ok()) << t;
  }
}

TEST(Safety, StaleCameraIsAFault) {
  SafetyParams p;
  SafetySupervisor s(p);
  s.start(0);
  for (double t = 0; t <= 1.0; t += 0.05) s.odometry(t), s.rangeScan(t);
  s.cameraFrame(0.8);
  EXPECT_TRUE(s.check(0.9, true).ok());
  const auto st = s.check(0.8 + p.camera_timeout_s + 0.01, true);
  EXPECT_EQ(st.fault, Fault::CameraStale);
  EXPECT_NE(st.reason.find("camera"), std::string::npos);
}

TEST(Safety, StaleRangeOdometryAndLostLink) {
  SafetySupervisor s;
  s.start(0);
  s.cameraFrame(1.0);
  s.odometry(1.0);
  EXPECT_EQ(s.check(1.0, true).fault, Fault::RangeStale);
  s.rangeScan(1.0);
  EXPECT_TRUE(s.check(1.0, true).ok());
  EXPECT_EQ(s.check(1.0, false).fault, Fault::BaseLinkLost);
  EXPECT_EQ(s.check(1.5, true).fault, Fault::OdometryStale);
}

TEST(Safety, NothingAtAllAfterStartIsAFault) {
  SafetySupervisor s;
  s.start(10.0);
  EXPECT_TRUE(s.check(10.1, true).ok());  // grace: streams are judged from start()
  EXPECT_FALSE(s.check(10.3, true).ok());
}

TEST(Safety, OptionalStreams) {
  SafetyParams p;
  p.require_camera = false;
  p.require_range = false;
  SafetySupervisor s(p);
  s.start(0);
  s.odometry(1.0);
  EXPECT_TRUE(s.check(1.05, true).ok());
}
