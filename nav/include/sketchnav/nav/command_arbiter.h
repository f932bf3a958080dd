#pragma once
// Which behaviour drives the base in a control tick. Each behaviour that applies this tick
// proposes a velocity command; the one highest on an explicit priority list wins, whatever the
// order the proposals were made in (the executive's tick used to decide it by the order of its
// statements alone). The winner's behaviour is the tick's Mode (TelemetryRow::mode).
#include <array>

#include "sketchnav/nav/events.h"
#include "sketchnav/servo/turn_law.h"

namespace sketchnav::nav {

/// The behaviours, highest priority first (CommandArbiter::priority()).
enum class Behaviour {
  FinalLook,  // at the goal, turning on the spot to look for a landmark never seen
  Yield,      // keeping out of a walking person's lane (it takes the command it would replace)
  Recover,    // stuck: driving clear towards the most open direction
  Dock,       // the last metres to the goal (the avoider is not run while docking)
  SideLook,   // on the way, turning on the spot towards a landmark predicted out of view
              // (above the dodges: it does not move the robot, and it gives way to an
              // oncoming person's dodge, executive.cpp)
  Detour,     // a path planned round an obstacle
  Avoid,      // the reactive dodge
  Servo,      // visual servo on the tracked landmark
  Look,       // following the route, heading held towards an expected landmark
  Follow,     // following the route
};
const char* toString(Behaviour b);
/// The telemetry mode a winning behaviour gives the tick (FinalLook, SideLook and Look:
/// Mode::Look).
Mode modeOf(Behaviour b);

/// A velocity command: v [m/s] forward, w [rad/s] CCW, and the turn it stands for.
struct Command {
  double v = 0, w = 0;
  servo::Turn turn = servo::Turn::Straight;
};

class CommandArbiter {
 public:
  /// Highest first: FinalLook, Yield, Recover, Dock, SideLook, Detour, Avoid, Servo, Look, Follow.
  static const std::array<Behaviour, 10>& priority();

  /// Forget this tick's proposals.
  void clear();
  /// `b` proposes `c` (replacing its earlier proposal of this tick).
  void propose(Behaviour b, const Command& c);
  bool proposed(Behaviour b) const;
  /// Whether anything was proposed this tick.
  bool any() const;
  /// The winning behaviour: the highest proposed one (Follow when none was).
  Behaviour winning() const;
  /// Its command (a zero command when nothing was proposed).
  const Command& winner() const;
  /// Sets the winner's forward speed (a cap by the clearance ahead applies to whatever drives).
  /// Nothing happens when nothing was proposed.
  void setWinnerSpeed(double v);

 private:
  static constexpr int kCount = 10;
  std::array<Command, kCount> cmd_{};
  std::array<bool, kCount> set_{};
  Command none_{};
};

}  // namespace sketchnav::nav
