// sketchnav recognise: classify images with a landmark model; --eval DIR prints accuracy.
#include <iostream>

#include "cli.h"

namespace sketchnav::app {
namespace {
int runRecognise(const std::vector<std::string>& argv, GlobalOptions&) {
  Args args("recognise", "classify images with a landmark model; --eval DIR prints accuracy",
            "--model MODEL IMAGE...");
  // Only --help is answered until the capability lands; everything else says so.
  for (const auto& a : argv)
    if (a == "--help" || a == "-h") return (std::cout << args.helpText(), 0);
  return notAvailable("recognise", "landmark recognition", 6);
}
const CommandRegistration reg("recognise",
                              "classify images with a landmark model; --eval DIR prints accuracy",
                              runRecognise);
}  // namespace
}  // namespace sketchnav::app
