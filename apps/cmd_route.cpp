// sketchnav route: convert a sketch into its route (path sections).
#include <iostream>

#include "cli.h"

namespace sketchnav::app {
namespace {
int runRoute(const std::vector<std::string>& argv, GlobalOptions&) {
  Args args("route", "convert a sketch into its route (path sections)",
            "SKETCH [--json] [-o route.png]");
  // Only --help is answered until the capability lands; everything else says so.
  for (const auto& a : argv)
    if (a == "--help" || a == "-h") return (std::cout << args.helpText(), 0);
  return notAvailable("route", "sketch maps", 4);
}
const CommandRegistration reg("route", "convert a sketch into its route (path sections)", runRoute);
}  // namespace
}  // namespace sketchnav::app
