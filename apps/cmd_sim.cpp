// sketchnav sim: render a world view / step the simulator.
#include <iostream>

#include "cli.h"

namespace sketchnav::app {
namespace {
int runSim(const std::vector<std::string>& argv, GlobalOptions&) {
  Args args("sim", "render a world view / step the simulator", "render|drive [options]");
  // Only --help is answered until the capability lands; everything else says so.
  for (const auto& a : argv)
    if (a == "--help" || a == "-h") return (std::cout << args.helpText(), 0);
  return notAvailable("sim", "the simulator", 3);
}
const CommandRegistration reg("sim", "render a world view / step the simulator", runSim);
}  // namespace
}  // namespace sketchnav::app
