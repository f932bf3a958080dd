#pragma once
// Registers the drivers of this library with hw::Registry, by URI scheme:
//   camera  folder:///DIR?fps=&loop=&hfov_deg=   the images of a folder, sorted by name
//   camera  video:///FILE, video://INDEX         a video file or a V4L2 device (OpenCV)
//   camera  aravis://IP-or-ID                    GigE Vision / USB3 Vision / Aravis Fake cameras
//   camera  rawlog:///FILE.rawlog                frames replayed from an MRPT rawlog
//   base    dani://HOST:PORT                     the DaNI base protocol (doc/base-protocol.md)
//   base    rawlog:///FILE.rawlog                odometry replayed from an MRPT rawlog
//   range   dani://HOST:PORT                     the base's sonar, over the same link
//   range   laser://DRIVER?...                   a laser scanner through MRPT hwdrivers
//   range   rawlog:///FILE.rawlog                2-D scans replayed from an MRPT rawlog
// The simulator's sim:// devices register from sim::registerDrivers() (hw/sim). A program
// that opens devices from URIs calls both once at start-up; the registry itself (sketchnav::hw)
// knows no driver, so linking the device interfaces does not link Aravis, MRPT hwdrivers,
// OpenSSL or zlib. Idempotent (each call registers the same factories again).
namespace sketchnav::drivers {
void registerDrivers();
}  // namespace sketchnav::drivers
