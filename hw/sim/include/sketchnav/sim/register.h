#pragma once
namespace sketchnav::sim {
/// Registers the sim:// camera, base and range drivers with hw::Registry. Idempotent.
void registerDrivers();
}  // namespace sketchnav::sim
