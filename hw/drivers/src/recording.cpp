#include "sketchnav/drivers/recording.h"

#include <atomic>
#include <filesystem>
#include <map>
#include <mutex>
#include <optional>

#include "sketchnav/core/error.h"
#include "sketchnav/core/input_file.h"
#include "sketchnav/core/json_io.h"
#include "sketchnav/core/log.h"
#include "sketchnav/hw/forwarding.h"

namespace sketchnav::drivers {
namespace {

class RawlogSink final : public Recorder {
 public:
  explicit RawlogSink(std::shared_ptr<RawlogRecorder> r) : r_(std::move(r)) {}
  void addFrame(const Frame& frame, const Intrinsics& k) override { r_->addFrame(frame, k); }
  void addOdometry(const Odometry& odo) override { r_->addOdometry(odo); }
  void addRange(const RangeScan& scan, const std::string& label) override {
    r_->addRange(scan, label);
  }
  void addCommand(double v, double w, double stamp, bool stop) override {
    r_->addCommand(v, w, stamp, stop ? "CMD_STOP" : "CMD_VEL");
  }
  // Beside the log, as its images are: MRPT's observation types have no place for it. Whole
  // or absent after kill -9 (a replay refuses a half-written file): temp file + rename.
  void addRunInfo(const Json& settings) override {
    writeFileAtomically(r_->path() + ".run.json", settings.dump(1) + "\n", "run info");
  }
  std::string path() const override { return r_->path(); }

 private:
  std::shared_ptr<RawlogRecorder> r_;
};

struct Formats {
  std::mutex m;
  std::map<std::string, RecordingFormat> by_extension;
};
Formats& formats() {
  static Formats r;
  return r;
}
// The registered format of `path`'s extension, if any (a copy: used outside the lock).
std::optional<RecordingFormat> formatOf(const std::string& path) {
  auto& f = formats();
  std::lock_guard<std::mutex> l(f.m);
  const auto it = f.by_extension.find(std::filesystem::path(path).extension().string());
  if (it == f.by_extension.end()) return std::nullopt;
  return it->second;
}

// Shared by the three decorators: the first write error turns recording off (logged once), so a
// full disk costs the log, not the run.
class Sink {
 public:
  explicit Sink(std::shared_ptr<Recorder> r) : rec_(std::move(r)) {}
  template <class F>
  void write(F&& f) {
    if (failed_) return;
    try {
      f(*rec_);
    } catch (const std::exception& e) {
      if (!failed_.exchange(true))
        log::error("record", "recording stopped", {{"file", rec_->path()}, {"why", e.what()}});
    }
  }

 private:
  std::shared_ptr<Recorder> rec_;
  std::atomic<bool> failed_{false};
};

class RecordingCamera final : public hw::ForwardingCamera {
 public:
  RecordingCamera(std::unique_ptr<Camera> inner, std::shared_ptr<Recorder> r)
      : ForwardingCamera(std::move(inner)), sink_(std::move(r)) {}
  GrabStatus grab(Frame& frame, double timeout_s) override {
    const GrabStatus st = inner().grab(frame, timeout_s);
    if (st == GrabStatus::Ok)
      sink_.write([&](Recorder& r) { r.addFrame(frame, inner().intrinsics()); });
    return st;
  }

 private:
  Sink sink_;
};

class RecordingBase final : public hw::ForwardingBase {
 public:
  RecordingBase(std::unique_ptr<Base> inner, std::shared_ptr<Recorder> r,
                std::shared_ptr<Clock> clock)
      : ForwardingBase(std::move(inner)), sink_(std::move(r)), clock_(std::move(clock)) {}
  void command(double v, double w) override {
    inner().command(v, w);
    const double t = clock_ ? clock_->now() : 0.0;
    sink_.write([&](Recorder& r) { r.addCommand(v, w, t, false); });
  }
  void stop() noexcept override {
    inner().stop();
    const double t = clock_ ? clock_->now() : 0.0;
    sink_.write([&](Recorder& r) { r.addCommand(0.0, 0.0, t, true); });
  }
  bool odometry(Odometry& out) override {
    if (!inner().odometry(out)) return false;
    sink_.write([&](Recorder& r) { r.addOdometry(out); });
    return true;
  }

 private:
  Sink sink_;
  std::shared_ptr<Clock> clock_;
};

class RecordingRange final : public hw::ForwardingRangeSensor {
 public:
  RecordingRange(std::unique_ptr<RangeSensor> inner, std::shared_ptr<Recorder> r, std::string label)
      : ForwardingRangeSensor(std::move(inner)), sink_(std::move(r)), label_(std::move(label)) {}
  bool read(RangeScan& out) override {
    if (!inner().read(out)) return false;
    sink_.write([&](Recorder& r) { r.addRange(out, label_); });
    return true;
  }

 private:
  Sink sink_;
  std::string label_;
};

}  // namespace

std::shared_ptr<Recorder> rawlogRecorder(std::shared_ptr<RawlogRecorder> rawlog) {
  return std::make_shared<RawlogSink>(std::move(rawlog));
}

void registerRecordingFormat(const std::string& extension, RecordingFormat format) {
  auto& f = formats();
  std::lock_guard<std::mutex> l(f.m);
  f.by_extension[extension] = std::move(format);
}

std::shared_ptr<Recorder> openRecorder(const std::string& path) {
  if (const auto f = formatOf(path); f && f->open) return f->open(path);
  if (std::filesystem::path(path).extension() == ".bag")
    throw InputError("--record " + path +
                     ": this sketchnav was built without ROS, so it cannot write bags "
                     "(record a .rawlog, or build with the ROS packages: bootstrap.sh)");
  return rawlogRecorder(std::make_shared<RawlogRecorder>(path));
}

Json readRecordedRobot(const std::string& path) {
  if (const auto f = formatOf(path); f && f->robot) return f->robot(path);
  return Json::object();
}

Json readRunInfo(const std::string& path) {
  if (const auto f = formatOf(path)) return f->run_info ? f->run_info(path) : Json::object();
  const std::string p = path + ".run.json";
  if (!std::filesystem::exists(p)) return Json::object();
  Json j = parseJsonFile(p, "run info");
  if (!j.is_object()) throw InputError("run info '" + p + "': not a JSON object");
  return j;
}

std::unique_ptr<Camera> recordCamera(std::unique_ptr<Camera> inner,
                                     std::shared_ptr<Recorder> recorder) {
  if (!inner) return inner;
  return std::make_unique<RecordingCamera>(std::move(inner), std::move(recorder));
}
std::unique_ptr<Base> recordBase(std::unique_ptr<Base> inner, std::shared_ptr<Recorder> recorder,
                                 std::shared_ptr<Clock> clock) {
  if (!inner) return inner;
  return std::make_unique<RecordingBase>(std::move(inner), std::move(recorder), std::move(clock));
}
std::unique_ptr<RangeSensor> recordRange(std::unique_ptr<RangeSensor> inner,
                                         std::shared_ptr<Recorder> recorder, std::string label) {
  if (!inner) return inner;
  return std::make_unique<RecordingRange>(std::move(inner), std::move(recorder), std::move(label));
}

}  // namespace sketchnav::drivers
