// sketchnav ui: the local web UI: sketch editor, live run view and control.
#include <iostream>

#include "cli.h"

namespace sketchnav::app {
namespace {
int runUi(const std::vector<std::string>& argv, GlobalOptions&) {
  Args args("ui", "the local web UI: sketch editor, live run view and control", "[options]");
  // Only --help is answered until the capability lands; everything else says so.
  for (const auto& a : argv)
    if (a == "--help" || a == "-h") return (std::cout << args.helpText(), 0);
  return notAvailable("ui", "the web UI", 4);
}
const CommandRegistration reg("ui", "the local web UI: sketch editor, live run view and control",
                              runUi);
}  // namespace
}  // namespace sketchnav::app
