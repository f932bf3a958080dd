// sketchnav base-emulator: reference base-side implementation of the base protocol, over the
// simulator.
#include <iostream>

#include "cli.h"

namespace sketchnav::app {
namespace {
int runBaseEmulator(const std::vector<std::string>& argv, GlobalOptions&) {
  Args args("base-emulator",
            "reference base-side implementation of the base protocol, over the simulator",
            "--port P");
  // Only --help is answered until the capability lands; everything else says so.
  for (const auto& a : argv)
    if (a == "--help" || a == "-h") return (std::cout << args.helpText(), 0);
  return notAvailable("base-emulator", "the robot base protocol", 9);
}
const CommandRegistration reg(
    "base-emulator", "reference base-side implementation of the base protocol, over the simulator",
    runBaseEmulator);
}  // namespace
}  // namespace sketchnav::app
