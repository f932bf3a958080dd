#pragma once
// Shared by the bag:// devices (bag_camera.cpp, bag_devices.cpp); not a public header.
#include <string>

#include "sketchnav/hw/clock.h"

namespace sketchnav::ros {

/// The earliest header stamp among the first messages of a bag's topics [s] (the bag time of a
/// message without one): the common time origin of one bag's replayed devices. Cached per path.
/// Throws (rosbag) when the file is no bag.
double bagFirstStamp(const std::string& path);

/// Where a paced bag:// device starts on `clock`: drivers::replayOrigin() of the bag's first
/// stamp (a message stamped s is due at t0_clock + (s - t0_bag)).
struct BagOrigin {
  double t0_bag = 0, t0_clock = 0;
};
BagOrigin bagOrigin(const std::string& path, hw::Clock& clock);

/// Registers the bag:// base and range sensors and the ".bag" recorder (bag.h).
void registerBagDevices();

}  // namespace sketchnav::ros
