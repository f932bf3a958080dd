// sketchnav train: build a landmark model (.slm) from a folder of class folders.
#include <iostream>

#include "cli.h"

namespace sketchnav::app {
namespace {
int runTrain(const std::vector<std::string>& argv, GlobalOptions&) {
  Args args("train", "build a landmark model (.slm) from a folder of class folders",
            "--landmarks DIR -o MODEL");
  // Only --help is answered until the capability lands; everything else says so.
  for (const auto& a : argv)
    if (a == "--help" || a == "-h") return (std::cout << args.helpText(), 0);
  return notAvailable("train", "landmark recognition", 6);
}
const CommandRegistration reg("train",
                              "build a landmark model (.slm) from a folder of class folders",
                              runTrain);
}  // namespace
}  // namespace sketchnav::app
