// sketchnav experiments: the paper's experiments 2-4 in simulation, N trials each; report.
#include <iostream>

#include "cli.h"

namespace sketchnav::app {
namespace {
int runExperiments(const std::vector<std::string>& argv, GlobalOptions&) {
  Args args("experiments", "the paper's experiments 2-4 in simulation, N trials each; report",
            "[--trials N] [--variants a,b]");
  // Only --help is answered until the capability lands; everything else says so.
  for (const auto& a : argv)
    if (a == "--help" || a == "-h") return (std::cout << args.helpText(), 0);
  return notAvailable("experiments", "the experiments", 8);
}
const CommandRegistration reg("experiments",
                              "the paper's experiments 2-4 in simulation, N trials each; report",
                              runExperiments);
}  // namespace
}  // namespace sketchnav::app
