#pragma once
// The device interfaces and data types of sketchnav::hw that the drivers implement and
// exchange, named in sketchnav::drivers too, so a driver reads `class DaniBase : public Base`.
// They are the same entities as hw::Base etc. (using-declarations, not copies).
#include "sketchnav/hw/clock.h"
#include "sketchnav/hw/devices.h"
#include "sketchnav/hw/registry.h"
#include "sketchnav/hw/types.h"

namespace sketchnav::drivers {

using hw::Base;
using hw::Camera;
using hw::Clock;
using hw::DeviceContext;
using hw::DeviceStats;
using hw::Frame;
using hw::GrabStatus;
using hw::Intrinsics;
using hw::Odometry;
using hw::Pose2D;
using hw::RangeScan;
using hw::RangeSensor;
using hw::Registry;
using hw::SimClock;
using hw::SteadyClock;

}  // namespace sketchnav::drivers
