#pragma once
// The safety supervisor: every tick it checks that the camera, the range sensors and the base
// link are alive; any stale stream, a lost link or an exception in the loop means
// hw::Base::stop() now. Stale thresholds plus the executive's tick bound the time from a fault
// to the stop command (<= 200 ms with the defaults: 150 ms + one 50 ms tick).
#include <string>

namespace sketchnav::nav {

struct SafetyParams {
  double camera_timeout_s = 0.15;  // [s] no new camera frame for this long -> stop
  double range_timeout_s = 0.15;   // [s] no new laser / sonar scan for this long -> stop
  double odom_timeout_s = 0.15;    // [s] no new odometry for this long -> stop
  bool require_camera = true;      // a run without a camera cannot see landmarks
  bool require_range = true;       // avoidance needs range data
  template <class B>
  void bind(B& b) {
    b("camera_timeout_s", camera_timeout_s);
    b("range_timeout_s", range_timeout_s);
    b("odom_timeout_s", odom_timeout_s);
    b("require_camera", require_camera);
    b("require_range", require_range);
  }
  void validate() const;  // InputError "nav.safety.<field> = ...: ..."
};

enum class Fault { None, CameraStale, RangeStale, OdometryStale, BaseLinkLost, Exception };
const char* toString(Fault f);

struct SafetyStatus {
  Fault fault = Fault::None;
  std::string reason;  // one line, for the summary and events
  bool ok() const { return fault == Fault::None; }
};

class SafetySupervisor {
 public:
  explicit SafetySupervisor(SafetyParams params = {});
  /// The clock time the supervision starts (streams are judged from then on).
  void start(double now);
  /// Record fresh data (stamps on the run's clock). Non-increasing stamps are not "fresh".
  void cameraFrame(double stamp);
  void rangeScan(double stamp);
  void odometry(double stamp);
  /// Check everything at `now`; `base_ok` is hw::Base::ok().
  SafetyStatus check(double now, bool base_ok) const;
  const SafetyParams& params() const { return params_; }

 private:
  SafetyParams params_;
  double start_ = 0, camera_ = -1e300, range_ = -1e300, odom_ = -1e300;
};

}  // namespace sketchnav::nav
