// sketchnav replay: offline servo over an image sequence / video / rawlog; per-frame CSV.
#include <iostream>

#include "cli.h"

namespace sketchnav::app {
namespace {
int runReplay(const std::vector<std::string>& argv, GlobalOptions&) {
  Args args("replay", "offline servo over an image sequence / video / rawlog; per-frame CSV",
            "--frames URI --model MODEL --target CLASS");
  // Only --help is answered until the capability lands; everything else says so.
  for (const auto& a : argv)
    if (a == "--help" || a == "-h") return (std::cout << args.helpText(), 0);
  return notAvailable("replay", "offline servo replay", 8);
}
const CommandRegistration reg(
    "replay", "offline servo over an image sequence / video / rawlog; per-frame CSV", runReplay);
}  // namespace
}  // namespace sketchnav::app
