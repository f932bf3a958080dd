#pragma once
// Angles [rad]: the one wrap used by the sketch's route, the navigation and the simulator.
#include <cmath>

namespace sketchnav {

/// `a` wrapped to (-pi, pi]. Computed as fmod(a + pi, 2 pi) - pi, so an angle already in range
/// may come back one rounding step away (what every caller has always used; keep it so, or
/// the simulator's trajectories change in their last digits).
inline double wrapAngle(double a) {
  a = std::fmod(a + M_PI, 2 * M_PI);
  if (a <= 0) a += 2 * M_PI;
  return a - M_PI;
}

}  // namespace sketchnav
