// sketchnav ros: this build has no ROS 1 (the packages were not found at configure time).
#include <iostream>

#include "cli.h"

namespace sketchnav::app {
namespace {
int runRos(const std::vector<std::string>&, GlobalOptions&) {
  std::cerr << "sketchnav ros: this build has no ROS 1 interface: install the ROS packages "
               "(./bootstrap.sh build installs them) and reconfigure (doc/ros.md)\n";
  return 1;
}
const CommandRegistration reg("ros", "ROS 1 interface (not in this build)", runRos);
}  // namespace
}  // namespace sketchnav::app
