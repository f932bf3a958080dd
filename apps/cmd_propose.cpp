// sketchnav propose: objectness windows for images; --eval VOCDIR prints a recall table.
#include <iostream>

#include "cli.h"

namespace sketchnav::app {
namespace {
int runPropose(const std::vector<std::string>& argv, GlobalOptions&) {
  Args args("propose", "objectness windows for images; --eval VOCDIR prints a recall table",
            "IMAGE [-o out.png] | --eval VOCDIR");
  // Only --help is answered until the capability lands; everything else says so.
  for (const auto& a : argv)
    if (a == "--help" || a == "-h") return (std::cout << args.helpText(), 0);
  return notAvailable("propose", "objectness", 5);
}
const CommandRegistration reg("propose",
                              "objectness windows for images; --eval VOCDIR prints a recall table",
                              runPropose);
}  // namespace
}  // namespace sketchnav::app
