#pragma once
// Recording decorators: wrap a run's devices so everything that passes through them (frames,
// odometry, scans, velocity commands) is appended to one MRPT rawlog (RawlogRecorder), while
// the wrapped device behaves exactly as before. This is `sketchnav run --record FILE`.
//
// A failure to record (disk full) is logged once and recording stops; it never stops the robot
// by itself — the run's own safety checks still apply. A null device stays null (a run without
// that device). Built on hw::ForwardingCamera / ForwardingBase / ForwardingRangeSensor.
#include <memory>

#include "sketchnav/drivers/hw_names.h"
#include "sketchnav/drivers/rawlog.h"

namespace sketchnav::drivers {

std::unique_ptr<Camera> recordCamera(std::unique_ptr<Camera> inner,
                                     std::shared_ptr<RawlogRecorder> recorder);
/// Records each command (with the stamp of `clock`) and each odometry reading.
std::unique_ptr<Base> recordBase(std::unique_ptr<Base> inner,
                                 std::shared_ptr<RawlogRecorder> recorder,
                                 std::shared_ptr<Clock> clock);
/// Records each scan under `label` ("LASER" or "SONAR").
std::unique_ptr<RangeSensor> recordRange(std::unique_ptr<RangeSensor> inner,
                                         std::shared_ptr<RawlogRecorder> recorder,
                                         std::string label);

}  // namespace sketchnav::drivers
