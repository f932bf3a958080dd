// sketchnav run: navigate: the simulated lab by default, or a real robot via device URIs.
#include <iostream>

#include "cli.h"

namespace sketchnav::app {
namespace {
int runRun(const std::vector<std::string>& argv, GlobalOptions&) {
  Args args("run", "navigate: the simulated lab by default, or a real robot via device URIs",
            "[options]");
  // Only --help is answered until the capability lands; everything else says so.
  for (const auto& a : argv)
    if (a == "--help" || a == "-h") return (std::cout << args.helpText(), 0);
  return notAvailable("run", "the navigation executive (servo and navigation)", 7);
}
const CommandRegistration reg(
    "run", "navigate: the simulated lab by default, or a real robot via device URIs", runRun);
}  // namespace
}  // namespace sketchnav::app
