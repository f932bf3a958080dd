#pragma once
// The sim:// device URIs:
//   sim://lab[?seed=N]                 the built-in lab world
//   sim://corridor                     another world shipped in share/worlds (<name>.world.json)
//   sim:///path/to/world.json[?seed=N] a world file
// Camera, base and range sensors (laser by default, `?sensor=sonar` for the sonar ring)
// created from URIs with the same authority + path share one Simulator (through
// DeviceContext::shared, key "sim:<authority><path>"), whose SimClock is installed in
// DeviceContext::clock. SimParams are read from the context's config section "sim"
// (e.g. --set sim.odom_slip_std=0.05); `?seed=` overrides sim.seed.
#include <memory>
#include <string>

#include "sketchnav/hw/registry.h"

namespace sketchnav::sim {
class Simulator;

/// Registers the sim:// camera, base and range drivers with hw::Registry. Idempotent.
void registerDrivers();

/// The Simulator behind a sim:// URI in `ctx` (created on first use). For run harnesses that
/// need ground truth (truePose, collided) next to the devices.
std::shared_ptr<Simulator> simulatorFor(const std::string& uri, hw::DeviceContext& ctx);

}  // namespace sketchnav::sim
