// sketchnav probe: open a camera / base / range URI, read for a while and report its health.
// The first thing a user runs when wiring a robot, and what device tests use.
#include <cmath>
#include <iostream>

#include "cli.h"
#include "sketchnav/core/error.h"
#include "sketchnav/hw/registry.h"

namespace sketchnav::app {
namespace {

int runProbe(const std::vector<std::string>& argv, GlobalOptions& g) {
  Args args("probe", "open a camera / base / range URI and report its health",
            "URI [--kind camera|base|range] [--frames N | --seconds T]");
  args.positionals("URI", "device URI, e.g. folder:///data/frames, video://0, sim://lab", 1, 1)
      .option("kind", "camera, base or range (default: camera)", "camera")
      .option("frames", "stop after N frames / messages", "100")
      .option("seconds", "stop after T seconds of wall time", "10");
  if (!args.parse(argv)) return 0;
  hw::registerBuiltinDrivers();
  const std::string uri = args.positional().front();
  const std::string kind = args.get("kind");
  const int max_frames = args.getInt("frames");
  const double max_seconds = args.getDouble("seconds");
  if (max_frames <= 0) throw InputError("sketchnav probe: --frames must be positive");
  if (!(max_seconds > 0)) throw InputError("sketchnav probe: --seconds must be positive");

  hw::DeviceContext ctx;
  ctx.config = g.config;
  hw::SteadyClock wall;
  Json report = {{"uri", uri},   {"kind", kind},    {"received", 0},         {"rate_hz", 0.0},
                 {"dropped", 0}, {"incomplete", 0}, {"latency_ms", nullptr}, {"error", nullptr}};
  hw::DeviceStats stats;
  double first = -1, last = -1;
  std::uint64_t n = 0;
  if (kind == "camera") {
    auto cam = hw::Registry::instance().createCamera(uri, ctx);
    hw::Frame f;
    double latency_sum = 0;
    while (static_cast<int>(n) < max_frames && wall.now() < max_seconds) {
      const double t0 = wall.now();
      const auto st = cam->grab(f, 1.0);
      if (st == hw::GrabStatus::EndOfStream) break;
      if (st == hw::GrabStatus::Error) break;
      if (st != hw::GrabStatus::Ok) continue;
      latency_sum += wall.now() - t0;
      if (first < 0) first = wall.now();
      last = wall.now();
      ++n;
    }
    stats = cam->stats();
    const auto k = cam->intrinsics();
    report["width"] = k.width;
    report["height"] = k.height;
    if (n > 0) report["latency_ms"] = 1000.0 * latency_sum / static_cast<double>(n);
  } else if (kind == "base") {
    auto base = hw::Registry::instance().createBase(uri, ctx);
    hw::Odometry o;
    while (static_cast<int>(n) < max_frames && wall.now() < max_seconds) {
      if (base->odometry(o)) {
        if (first < 0) first = wall.now();
        last = wall.now();
        ++n;
      }
      hw::SteadyClock().sleepUntil(0.01);
    }
    base->stop();
    stats = base->stats();
  } else if (kind == "range") {
    auto range = hw::Registry::instance().createRange(uri, ctx);
    hw::RangeScan s;
    while (static_cast<int>(n) < max_frames && wall.now() < max_seconds) {
      if (range->read(s)) {
        if (first < 0) first = wall.now();
        last = wall.now();
        ++n;
      }
    }
    stats = range->stats();
  } else {
    throw InputError("sketchnav probe: --kind must be camera, base or range, got '" + kind + "'");
  }
  report["received"] = stats.received;
  report["dropped"] = stats.dropped;
  report["incomplete"] = stats.incomplete;
  if (n > 1 && last > first) report["rate_hz"] = static_cast<double>(n - 1) / (last - first);
  if (!stats.last_error.empty()) report["error"] = stats.last_error;
  if (g.json) {
    printJson(report);
  } else {
    std::cout << "uri        " << uri << "\nkind       " << kind << "\nreceived   "
              << stats.received << "\nrate       " << report["rate_hz"].get<double>()
              << " Hz\ndropped    " << stats.dropped << "\nincomplete " << stats.incomplete
              << "\nlast error " << (stats.last_error.empty() ? "none" : stats.last_error) << "\n";
  }
  return stats.received > 0 ? 0 : 1;
}

const CommandRegistration reg("probe", "open a camera / base / range URI and report its health",
                              runProbe);
}  // namespace
}  // namespace sketchnav::app
