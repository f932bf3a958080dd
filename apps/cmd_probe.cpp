// sketchnav probe: open a camera / base / range URI, read for a while and report its health.
// The first thing a user runs when wiring a robot, and what device tests use.
#include <algorithm>
#include <cmath>
#include <iostream>

#include "cli.h"
#include "sketchnav/core/error.h"
#include "sketchnav/drivers/aravis_camera.h"
#include "sketchnav/drivers/dani_base.h"
#include "sketchnav/drivers/register.h"
#include "sketchnav/hw/registry.h"
#include "sketchnav/sim/register.h"

namespace sketchnav::app {
namespace {

/// Arrival times of what a device delivered, for the rate.
struct Arrivals {
  double first = -1, last = -1;
  std::uint64_t n = 0;
  void add(double t) {
    if (first < 0) first = t;
    last = t;
    ++n;
  }
  double rate() const {
    return n > 1 && last > first ? static_cast<double>(n - 1) / (last - first) : 0.0;
  }
};

/// camera / base / range from the scheme when --kind is not given.
std::string kindOf(const std::string& uri_text) {
  const std::string scheme = Uri::parse(uri_text).scheme;
  if (scheme == "dani") return "base";
  if (scheme == "laser" || scheme == "rawlog") return "range";
  const auto& r = hw::Registry::instance();
  auto in = [&](const std::vector<std::string>& v) {
    return std::find(v.begin(), v.end(), scheme) != v.end();
  };
  if (in(r.cameraSchemes())) return "camera";
  if (in(r.baseSchemes())) return "base";
  if (in(r.rangeSchemes())) return "range";
  return "camera";  // createCamera() then names the unknown scheme and the known ones
}

int runProbe(const std::vector<std::string>& argv, GlobalOptions& g) {
  Args args("probe", "open a camera / base / range URI and report its health",
            "URI [--kind camera|base|range] [--frames N | --seconds T]");
  args.positionals("URI",
                   "device URI, e.g. aravis://192.168.1.10, dani://192.168.1.20:5600, "
                   "laser://CHokuyoURG?COM_port_LIN=ttyACM0, rawlog:///log.rawlog, "
                   "folder:///data/frames, video://0, sim://lab",
                   1, 1)
      .option("kind", "camera, base or range (default: from the URI scheme)")
      .option("frames", "stop after N frames / messages (default 100 unless --seconds)")
      .option("seconds", "stop after T seconds of wall time (default 10)");
  if (!args.parse(argv)) return 0;
  drivers::registerDrivers();
  sim::registerDrivers();
  const std::string uri = args.positional().front();
  const std::string kind = args.has("kind") ? args.get("kind") : kindOf(uri);
  const bool by_frames = args.has("frames") || !args.has("seconds");
  const long max_frames = args.has("frames") ? args.getInt("frames") : 100;
  const double max_seconds = args.has("seconds") ? args.getDouble("seconds") : 10.0;
  if (max_frames <= 0) throw InputError("sketchnav probe: --frames must be positive");
  if (!(max_seconds > 0)) throw InputError("sketchnav probe: --seconds must be positive");
  if (kind != "camera" && kind != "base" && kind != "range")
    throw InputError("sketchnav probe: --kind must be camera, base or range, got '" + kind + "'");
  auto enough = [&](std::uint64_t n) { return by_frames && static_cast<long>(n) >= max_frames; };

  // The device's driver settings are applied when it is opened (checked below); no other.
  g.config.requireAllUsedExcept({"base.", "camera.", "laser.", "sonar.", "sim."});
  hw::DeviceContext ctx;
  ctx.config = g.config;
  hw::SteadyClock wall;
  Json report = {{"uri", uri},   {"kind", kind},    {"received", 0},         {"rate_hz", 0.0},
                 {"dropped", 0}, {"incomplete", 0}, {"latency_ms", nullptr}, {"error", nullptr}};
  hw::DeviceStats stats;
  Arrivals got;
  try {
    if (kind == "camera") {
      auto cam = hw::Registry::instance().createCamera(uri, ctx);
      hw::Frame f;
      double latency_sum = 0;
      while (!enough(got.n) && wall.now() < max_seconds) {
        const double t0 = wall.now();
        const auto st = cam->grab(f, std::min(1.0, std::max(0.01, max_seconds - t0)));
        if (st == hw::GrabStatus::EndOfStream || st == hw::GrabStatus::Error) break;
        if (st != hw::GrabStatus::Ok) continue;
        latency_sum += wall.now() - t0;  // time the caller waits for a frame
        got.add(wall.now());
      }
      stats = cam->stats();
      const auto k = cam->intrinsics();
      report["width"] = k.width;
      report["height"] = k.height;
      // A live camera knows when a frame reached the host; otherwise report the wait.
      const auto* gige = dynamic_cast<const drivers::AravisCamera*>(cam.get());
      if (gige && gige->meanLatencyMs() >= 0)
        report["latency_ms"] = gige->meanLatencyMs();
      else if (got.n > 0)
        report["latency_ms"] = 1000.0 * latency_sum / static_cast<double>(got.n);
    } else if (kind == "base") {
      auto base = hw::Registry::instance().createBase(uri, ctx);
      auto* dani = dynamic_cast<drivers::DaniBase*>(base.get());
      // Count odometry messages as they arrive (the base streams them on its own).
      std::uint64_t seen = base->stats().received;
      double rtt_sum = 0;
      int rtt_n = 0;
      hw::Odometry o;
      const bool counts_itself = dani != nullptr;
      double last_stamp = -1;
      while (!enough(got.n) && wall.now() < max_seconds) {
        if (counts_itself) {
          const std::uint64_t now_seen = base->stats().received;
          for (; seen < now_seen; ++seen) got.add(wall.now());
          const double rtt = dani->status().rtt_ms;
          if (rtt >= 0) rtt_sum += rtt, ++rtt_n;
        } else if (base->odometry(o) && o.stamp != last_stamp) {
          last_stamp = o.stamp;
          got.add(wall.now());
        }
        wall.sleepUntil(wall.now() + 0.002);
      }
      base->stop();
      stats = base->stats();
      if (!counts_itself) stats.received = got.n;
      report["ok"] = base->ok();
      if (dani) {
        const auto st = dani->status();
        report["base_state"] = drivers::proto::toString(st.base_state);
        report["link_faults"] = st.faults;
        if (rtt_n > 0) report["latency_ms"] = 0.5 * rtt_sum / rtt_n;  // one way: half the RTT
        report["rtt_ms"] = rtt_n > 0 ? Json(rtt_sum / rtt_n) : Json(nullptr);
      }
    } else {
      auto range = hw::Registry::instance().createRange(uri, ctx);
      hw::RangeScan s;
      while (!enough(got.n) && wall.now() < max_seconds) {
        if (range->read(s)) {
          got.add(wall.now());
          report["beams"] = s.ranges.size();
          report["max_range_m"] = s.max_range;
        } else {
          wall.sleepUntil(wall.now() + 0.002);
        }
      }
      stats = range->stats();
    }
  } catch (const RuntimeError& e) {
    // An unreachable device is exactly what a probe reports, not a crash.
    stats.last_error = e.what();
  }
  report["received"] = stats.received;
  report["dropped"] = stats.dropped;
  report["incomplete"] = stats.incomplete;
  report["rate_hz"] = got.rate();
  if (!stats.last_error.empty()) report["error"] = stats.last_error;
  if (g.json) {
    printJson(report);
  } else {
    std::cout << "uri        " << uri << "\nkind       " << kind << "\nreceived   "
              << stats.received << "\nrate       " << got.rate() << " Hz\ndropped    "
              << stats.dropped << "\nincomplete " << stats.incomplete << "\nlatency    "
              << (report["latency_ms"].is_null()
                      ? std::string("n/a")
                      : std::to_string(report["latency_ms"].get<double>()) + " ms")
              << "\nlast error " << (stats.last_error.empty() ? "none" : stats.last_error) << "\n";
  }
  return stats.received > 0 ? 0 : 1;
}

const CommandRegistration reg("probe", "open a camera / base / range URI and report its health",
                              runProbe);
}  // namespace
}  // namespace sketchnav::app
