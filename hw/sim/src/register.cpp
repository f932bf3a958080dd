#include "sketchnav/sim/register.h"

namespace sketchnav::sim {
// The sim:// drivers are registered here once the simulator lands (issue #3).
void registerDrivers() {}
}  // namespace sketchnav::sim
