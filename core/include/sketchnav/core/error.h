#pragma once
// The project's error model (doc/conventions.md):
//  - broken invariant            -> assert / std::logic_error (a bug)
//  - bad input (file, field, URI) -> InputError, caught once at the command boundary, exit 2
//  - runtime failure (device gone, I/O) -> RuntimeError, exit 1
//  - expected outcomes (no landmark seen, section failed) -> returned status, never thrown
#include <stdexcept>
#include <string>

namespace sketchnav {

/// Bad input: a malformed file, a bad field, an unknown URI scheme. The message names the
/// file or field so the user can fix it; it is a single line.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A failure of the environment rather than of the input: a device that stopped answering,
/// a disk that is full.
class RuntimeError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Thrown by a subcommand whose capability has not landed yet: it is never faked.
class NotImplementedError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace sketchnav
