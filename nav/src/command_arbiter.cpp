#include "sketchnav/nav/command_arbiter.h"

namespace sketchnav::nav {

const char* toString(Behaviour b) {
  switch (b) {
    case Behaviour::FinalLook:
      return "final_look";
    case Behaviour::Yield:
      return "yield";
    case Behaviour::Recover:
      return "recover";
    case Behaviour::Dock:
      return "dock";
    case Behaviour::SideLook:
      return "side_look";
    case Behaviour::Detour:
      return "detour";
    case Behaviour::Avoid:
      return "avoid";
    case Behaviour::Servo:
      return "servo";
    case Behaviour::Look:
      return "look";
    case Behaviour::Follow:
      return "follow";
  }
  return "follow";
}

Mode modeOf(Behaviour b) {
  switch (b) {
    case Behaviour::FinalLook:
    case Behaviour::SideLook:
    case Behaviour::Look:
      return Mode::Look;
    case Behaviour::Yield:
      return Mode::Yield;
    case Behaviour::Recover:
      return Mode::Recover;
    case Behaviour::Dock:
      return Mode::Dock;
    case Behaviour::Detour:
      return Mode::Detour;
    case Behaviour::Avoid:
      return Mode::Avoid;
    case Behaviour::Servo:
      return Mode::Servo;
    case Behaviour::Follow:
      return Mode::Follow;
  }
  return Mode::Follow;
}

const std::array<Behaviour, 10>& CommandArbiter::priority() {
  // The enum is declared in this order; the list says it where it is used.
  static const std::array<Behaviour, 10> p = {
      Behaviour::FinalLook, Behaviour::Yield,  Behaviour::Recover, Behaviour::Dock,
      Behaviour::SideLook,  Behaviour::Detour, Behaviour::Avoid,   Behaviour::Servo,
      Behaviour::Look,      Behaviour::Follow};
  return p;
}

void CommandArbiter::clear() {
  set_.fill(false);
}

void CommandArbiter::propose(Behaviour b, const Command& c) {
  const int i = static_cast<int>(b);
  cmd_[i] = c;
  set_[i] = true;
}

bool CommandArbiter::proposed(Behaviour b) const {
  return set_[static_cast<int>(b)];
}

bool CommandArbiter::any() const {
  for (bool s : set_)
    if (s) return true;
  return false;
}

Behaviour CommandArbiter::winning() const {
  for (Behaviour b : priority())
    if (proposed(b)) return b;
  return Behaviour::Follow;
}

const Command& CommandArbiter::winner() const {
  return any() ? cmd_[static_cast<int>(winning())] : none_;
}

void CommandArbiter::setWinnerSpeed(double v) {
  if (any()) cmd_[static_cast<int>(winning())].v = v;
}

}  // namespace sketchnav::nav
