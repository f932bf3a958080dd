// sketchnav tune: sweep the turn-radius gain over scenarios; table + plot.
#include <iostream>

#include "cli.h"

namespace sketchnav::app {
namespace {
int runTune(const std::vector<std::string>& argv, GlobalOptions&) {
  Args args("tune", "sweep the turn-radius gain over scenarios; table + plot", "[options]");
  // Only --help is answered until the capability lands; everything else says so.
  for (const auto& a : argv)
    if (a == "--help" || a == "-h") return (std::cout << args.helpText(), 0);
  return notAvailable("tune", "gain tuning", 8);
}
const CommandRegistration reg("tune", "sweep the turn-radius gain over scenarios; table + plot",
                              runTune);
}  // namespace
}  // namespace sketchnav::app
