#pragma once
// Recording decorators: wrap a run's devices so everything that passes through them (frames,
// odometry, scans, velocity commands) is appended to one recording (a Recorder: an MRPT rawlog,
// RawlogRecorder, or a ROS bag when sketchnav is built with ROS), while the wrapped device
// behaves exactly as before. This is `sketchnav run --record FILE`.
//
// A failure to record (disk full) is logged once and recording stops; it never stops the robot
// by itself — the run's own safety checks still apply. A null device stays null (a run without
// that device). Built on hw::ForwardingCamera / ForwardingBase / ForwardingRangeSensor.
#include <functional>
#include <memory>
#include <string>

#include "sketchnav/core/config.h"
#include "sketchnav/drivers/hw_names.h"
#include "sketchnav/drivers/rawlog.h"

namespace sketchnav::drivers {

/// Where the decorators write. Each add*() writes one record and throws RuntimeError when the
/// file refuses it; calls may come from several threads (implementations serialise them).
class Recorder {
 public:
  virtual ~Recorder() = default;
  virtual void addFrame(const Frame& frame, const Intrinsics& k) = 0;
  virtual void addOdometry(const Odometry& odo) = 0;
  /// `label` "LASER" or "SONAR".
  virtual void addRange(const RangeScan& scan, const std::string& label) = 0;
  /// `stop`: a stop() rather than a command().
  virtual void addCommand(double v, double w, double stamp, bool stop) = 0;
  /// The settings the run took from its robot rather than from the user (the camera's mount,
  /// the robot's radius, the camera's period: `sketchnav run` lists them), as a flat object of
  /// setting keys; a replay of the recording runs with them (readRunInfo). Written once.
  virtual void addRunInfo(const Json& settings) = 0;
  virtual std::string path() const = 0;
};

/// What addRunInfo() stored in the recording `path` (a rawlog's "<path>.run.json" beside it, a
/// bag's /sketchnav/run_info message); an empty object when there is none (an older recording,
/// a bag from elsewhere). InputError naming the file when it is there but unreadable.
Json readRunInfo(const std::string& path);

/// What a recording made elsewhere shows of the robot without run info, as setting keys: a ROS
/// bag's tf gives the camera mount (robot.camera.*, from base_link to its images' optical
/// frame), as `ros nav` takes it from live tf. An empty object when it shows nothing (a
/// rawlog; a bag without tf to its camera). A replay takes these for the keys neither the run
/// info nor the user sets. Unlike run info, they do not change the replay's time origin.
Json readRecordedRobot(const std::string& path);

using RecorderFactory = std::function<std::shared_ptr<Recorder>(const std::string& path)>;
using RecordingReader = std::function<Json(const std::string& path)>;
/// A recording file format other than the built-in MRPT rawlog (".bag", registered by
/// sketchnav::ros): how to write one and what to read back from one. An empty reader reads
/// nothing (an empty object).
struct RecordingFormat {
  RecorderFactory open;      // openRecorder()
  RecordingReader run_info;  // readRunInfo()
  RecordingReader robot;     // readRecordedRobot()
};
/// `extension` with its dot, e.g. ".bag". Thread-safe; a later registration replaces one.
void registerRecordingFormat(const std::string& extension, RecordingFormat format);

/// A RawlogRecorder as a Recorder (labels CAMERA, ODOMETRY, LASER / SONAR, CMD_VEL / CMD_STOP).
std::shared_ptr<Recorder> rawlogRecorder(std::shared_ptr<RawlogRecorder> rawlog);

/// Opens a recording by the file name's extension: one registered with registerRecordingFormat()
/// (".bag" by sketchnav::ros), an MRPT rawlog otherwise. InputError for ".bag" in a build
/// without ROS.
std::shared_ptr<Recorder> openRecorder(const std::string& path);

std::unique_ptr<Camera> recordCamera(std::unique_ptr<Camera> inner,
                                     std::shared_ptr<Recorder> recorder);
/// Records each command (with the stamp of `clock`) and each odometry reading.
std::unique_ptr<Base> recordBase(std::unique_ptr<Base> inner, std::shared_ptr<Recorder> recorder,
                                 std::shared_ptr<Clock> clock);
/// Records each scan under `label` ("LASER" or "SONAR").
std::unique_ptr<RangeSensor> recordRange(std::unique_ptr<RangeSensor> inner,
                                         std::shared_ptr<Recorder> recorder, std::string label);

}  // namespace sketchnav::drivers
