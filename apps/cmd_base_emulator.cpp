// sketchnav base-emulator: reference base-side implementation of the base protocol
// (doc/base-protocol.md) over the simulator's vehicle, so the laptop side can be exercised
// over a real socket: `sketchnav base-emulator --port 5600` then
// `sketchnav probe dani://127.0.0.1:5600 --kind base`.
#include <csignal>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>

#include "cli.h"
#include "sketchnav/core/error.h"
#include "sketchnav/core/log.h"
#include "sketchnav/drivers/base_server.h"
#include "sketchnav/sim/simulator.h"
#include "sketchnav/sim/world.h"

namespace sketchnav::app {
namespace {

volatile std::sig_atomic_t g_stop = 0;
void onSignal(int) {
  g_stop = 1;
}

std::string readSecretFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError("sketchnav base-emulator: cannot read --secret-file '" + path + "'");
  std::stringstream ss;
  ss << in.rdbuf();
  std::string s = ss.str();
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r' || s.back() == ' ')) s.pop_back();
  if (s.size() < 8)
    throw InputError("sketchnav base-emulator: secret in '" + path + "' is shorter than 8 bytes");
  return s;
}

int runBaseEmulator(const std::vector<std::string>& argv, GlobalOptions& g) {
  Args args("base-emulator",
            "reference base-side implementation of the base protocol, over the simulator",
            "[--port P] [--bind HOST] [--laptop HOST] [--secret-file F] [--world lab|none]");
  args.option("port", "UDP port to listen on (0: any free port, printed on stdout)", "5600")
      .option("bind", "interface address to listen on; beyond loopback needs --secret-file",
              "127.0.0.1")
      .option("laptop", "the only host whose datagrams are obeyed", "127.0.0.1")
      .option("secret-file", "file holding the shared secret (HMAC-SHA256 authentication)")
      .option("watchdog-ms", "stop when moving and no valid command for this long", "200")
      .option("world", "simulated world driven by the commands ('none': a bare unicycle)", "lab")
      .option("seed", "simulator seed", "1")
      .option("seconds", "exit after T seconds of wall time (0: until Ctrl-C / SIGTERM)", "0");
  if (!args.parse(argv)) return 0;

  drivers::BaseServerParams p;
  applyConfig(p, g.config, "base_server");
  {
    sim::SimParams sp;  // --world none takes them too (and ignores them), as before
    applyConfig(sp, g.config, "sim");
  }
  g.config.requireAllUsed();
  p.port = args.getInt("port");
  p.bind_host = args.get("bind");
  p.allowed_peer = args.get("laptop");
  p.watchdog_s = args.getDouble("watchdog-ms") / 1000.0;
  if (!args.get("secret-file").empty()) p.secret = readSecretFile(args.get("secret-file"));
  p.validate();
  const double seconds = args.getDouble("seconds");
  if (seconds < 0) throw InputError("sketchnav base-emulator: --seconds must be >= 0");
  const int seed = args.getInt("seed");
  if (seed < 0) throw InputError("sketchnav base-emulator: --seed must be >= 0");

  // The vehicle: the simulator's differential-drive base (with its sonar), advanced in real
  // time by this loop; or a bare unicycle model with no world.
  hw::SteadyClock wall;
  std::unique_ptr<sim::Simulator> simulator;
  std::unique_ptr<drivers::UnicycleBase> unicycle;
  hw::Base* vehicle = nullptr;
  hw::RangeSensor* sonar = nullptr;
  const std::string world = args.get("world");
  if (world == "none") {
    unicycle = std::make_unique<drivers::UnicycleBase>(wall);
    vehicle = unicycle.get();
  } else {
    sim::SimParams sp;
    applyConfig(sp, g.config, "sim");
    simulator = std::make_unique<sim::Simulator>(sim::loadWorldByName(world), sp,
                                                 static_cast<std::uint64_t>(seed));
    vehicle = &simulator->base();
    sonar = &simulator->sonar();
  }

  drivers::BaseServer server(*vehicle, sonar, wall, p);
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  // The port on stdout, alone on its line, so scripts and tests started with --port 0 find it.
  if (!g.json)
    std::cout << "listening " << p.bind_host << ":" << server.port() << std::endl;
  else
    printJson({{"listening", p.bind_host + ":" + std::to_string(server.port())}});
  while (!g_stop && (seconds == 0 || wall.now() < seconds)) {
    server.spinOnce(0.005);
    // Time is an input: the simulated world follows wall time, so the base behaves like a
    // real one for the laptop on the other end of the socket.
    if (simulator) simulator->advanceTo(wall.now());
  }
  server.shutdown();
  const auto st = server.stats();
  log::info("base-emulator", "exiting",
            {{"received", std::to_string(st.received)},
             {"rejected", std::to_string(st.rejected)},
             {"refused", std::to_string(st.refused)},
             {"watchdog_trips", std::to_string(st.watchdog_trips)}});
  return 0;
}

const CommandRegistration reg(
    "base-emulator", "reference base-side implementation of the base protocol, over the simulator",
    runBaseEmulator);
}  // namespace
}  // namespace sketchnav::app
