#pragma once
// Recording a run as an MRPT rawlog ("observations" format, readable by MRPT's RawLogViewer
// and rawlog-edit) and reading it back.
//
// What goes in, one MRPT observation per item, each with its sensor label:
//   camera frame  -> CObservationImage, the image stored externally as a PNG in
//                    "<FILE stem>_Images/" beside the log (MRPT's convention), intrinsics kept
//   odometry      -> CObservationOdometry (pose + velocities)           label "ODOMETRY"
//   laser scan    -> CObservation2DRangeScan                            label "LASER"
//   sonar scan    -> CObservationRange (one measurement per beam)      label "SONAR"
//   command       -> CObservationOdometry, velocities only             label "CMD_VEL"
// Timestamps are the run clock's seconds (Frame::stamp etc.) stored as MRPT times, so a
// replay gets exactly the recorded stamps back (on a simulated run they read as 1970 dates).
//
// Every record is written with one write() to the file descriptor, so a run that is killed
// leaves a log that reads up to its last complete record.
#include <cstdint>
#include <memory>
#include <string>

#include "sketchnav/drivers/hw_names.h"

namespace sketchnav::drivers {

class RawlogRecorder {
 public:
  /// Creates (truncates) `path` and its image folder. Throws RuntimeError naming the path.
  explicit RawlogRecorder(const std::string& path);
  ~RawlogRecorder();
  RawlogRecorder(const RawlogRecorder&) = delete;
  RawlogRecorder& operator=(const RawlogRecorder&) = delete;

  /// Each add*() writes one record; RuntimeError when the disk refuses it. Thread-safe.
  void addFrame(const Frame& frame, const Intrinsics& k, const std::string& label = "CAMERA");
  void addOdometry(const Odometry& odo, const std::string& label = "ODOMETRY");
  void addRange(const RangeScan& scan, const std::string& label = "");  // LASER / SONAR
  void addCommand(double v, double w, double stamp, const std::string& label = "CMD_VEL");

  std::uint64_t records() const;
  const std::string& path() const { return path_; }
  const std::string& imageDir() const { return image_dir_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::string path_, image_dir_;
};

/// One record read back from a rawlog.
struct RawlogEntry {
  enum class Kind { Frame, Odometry, Range, Command, Other };
  Kind kind = Kind::Other;
  std::string label;
  double stamp = 0.0;
  Frame frame;  // Kind::Frame (image loaded from the image folder)
  Intrinsics intrinsics;
  Odometry odometry;        // Kind::Odometry
  RangeScan range;          // Kind::Range
  double v = 0.0, w = 0.0;  // Kind::Command
};

/// Sequential reader of a rawlog written by RawlogRecorder. Each record is read into memory
/// with every length and count in it checked against the bytes there (at most 64 MiB a
/// record) before MRPT deserialises it. A truncated tail, a corrupt record, or a record of a
/// class or version the recorder does not write ends the log with a one-line warning naming
/// the file, the record (counted from 1) and the field (counted in truncated()).
class RawlogReader {
 public:
  /// Throws InputError naming the file when it cannot be opened.
  explicit RawlogReader(const std::string& path);
  ~RawlogReader();
  /// False at the end of the log. Images are loaded only when `load_images`.
  bool next(RawlogEntry& out, bool load_images = true);
  std::uint64_t truncated() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Where a replayed recording's devices start on the replay clock: a record stamped s is due
/// at t0_clock + (s - t0_rec). A recording `run --record` made (`run_clock`: it holds the run
/// info, drivers::readRunInfo) is stamped in the run's clock seconds and keeps its times
/// (t0_rec = t0_clock = 0), so a replay whose clock starts at 0, as the run's did, shows at
/// time t what the run saw at t, and gives the run's commands. Any other recording (an MRPT
/// dataset, a robot's bag in epoch time) starts at its first stamp where the clock is now.
/// Every device of one recording uses the same origin.
struct ReplayOrigin {
  double t0_rec = 0, t0_clock = 0;
};
ReplayOrigin replayOrigin(double first_stamp, const Clock& clock, bool run_clock);
/// True when the rawlog `path` was written by `run --record` (its run info is beside it).
bool rawlogHasRunInfo(const std::string& path);
/// A record due within this of the replay clock [s] is due now: stamps come back rounded
/// (MRPT keeps 100 ns ticks, a bag nanoseconds), and a clock jumped forward by that rounding
/// would put the replay a hair after the run's instants, where a period check that held at the
/// run's time fails.
constexpr double kReplaySlack = 1e-6;

/// The stamp of the first record of a rawlog (any kind): the common time origin of the
/// replayed devices, so a replayed camera, base and laser stay in step. NaN when none.
double rawlogFirstStamp(const std::string& path);

/// The camera frames of a rawlog as a Camera (rawlog:///FILE[?realtime=1] as a camera URI).
/// Without `clock` each grab() returns the next frame at once with its recorded stamp; with
/// one, frames come out at their recorded pace on it (sleepUntil: a SimClock jumps) stamped in
/// its time, in step with RawlogBase and the rawlog range sensor. EndOfStream at the end.
class RawlogCamera final : public Camera {
 public:
  RawlogCamera(const std::string& path, std::string label = {}, std::string uri = {},
               std::shared_ptr<Clock> clock = nullptr);
  ~RawlogCamera() override;
  GrabStatus grab(Frame& frame, double timeout_s = 1.0) override;
  Intrinsics intrinsics() const override { return intrinsics_; }
  DeviceStats stats() const override { return stats_; }
  std::string uri() const override { return uri_; }

 private:
  std::unique_ptr<RawlogReader> reader_;
  std::string label_, uri_;
  Intrinsics intrinsics_;
  DeviceStats stats_;
  bool have_first_ = false;
  RawlogEntry first_;
  std::shared_ptr<Clock> clock_;  // null: no pacing
  double t0_rec_ = 0, t0_clock_ = 0;
};

/// The recorded odometry of a rawlog as a Base (rawlog:///FILE as a base URI), for running
/// the navigation on a recording without the simulator. Odometry records come out at their
/// recorded pace on `clock` (the log's first record at construction); commands are accepted and
/// ignored (the recording already holds what the robot did); ok() turns false at the end.
class RawlogBase final : public Base {
 public:
  RawlogBase(const std::string& path, std::shared_ptr<Clock> clock, std::string label = "ODOMETRY",
             std::string uri = {});
  ~RawlogBase() override;
  void command(double v, double w) override;
  void stop() noexcept override {}
  bool odometry(Odometry& out) override;
  bool ok() const override { return !ended_; }
  DeviceStats stats() const override { return stats_; }
  std::string uri() const override { return uri_; }

 private:
  bool fetch();
  std::unique_ptr<RawlogReader> reader_;
  std::shared_ptr<Clock> clock_;
  std::string label_, uri_;
  bool have_next_ = false, have_current_ = false, ended_ = false;
  Odometry next_, current_;
  double t0_rec_ = 0, t0_clock_ = 0;
  DeviceStats stats_;
};

}  // namespace sketchnav::drivers
