#pragma once
// Registers the real-hardware drivers with hw::Registry:
//   camera  aravis://IP-or-ID        GigE Vision / USB3 Vision / Aravis Fake cameras
//   base    dani://HOST:PORT         the DaNI base protocol (doc/base-protocol.md)
//   range   dani://HOST:PORT         the base's sonar, over the same link
//   range   laser://DRIVER?...       a laser scanner through MRPT hwdrivers
//   range   rawlog:///FILE.rawlog    2-D scans replayed from an MRPT rawlog
// Called by registerBuiltinDrivers(); idempotent.
namespace sketchnav::hw {
void registerHardwareDrivers();
}  // namespace sketchnav::hw
