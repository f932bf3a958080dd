#pragma once
// MRPT 2-D scan -> hw::RangeScan, shared by the laser driver, the rawlog replay and the
// recorder's tests. Private to hw (MRPT types stay out of public headers).
#include <mrpt/obs/CObservation2DRangeScan.h>

#include "sketchnav/hw/types.h"

namespace sketchnav::drivers {
/// Bearings in the robot frame (sensor yaw added), invalid ranges as max_range; the stamp is
/// left at 0 for the caller to set on its clock.
void toRangeScan(const mrpt::obs::CObservation2DRangeScan& o, RangeScan& s);
}  // namespace sketchnav::drivers
