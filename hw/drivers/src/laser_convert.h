#pragma once
// MRPT 2-D scan -> hw::RangeScan, shared by the laser driver, the rawlog replay and the
// recorder's tests. Private to hw (MRPT types stay out of public headers).
#include <mrpt/obs/CObservation2DRangeScan.h>

#include <cstring>
#include <string>

#include "sketchnav/hw/types.h"

namespace sketchnav::drivers {
/// Bearings in the robot frame (sensor yaw added), invalid ranges as max_range; the stamp is
/// left at 0 for the caller to set on its clock.
void toRangeScan(const mrpt::obs::CObservation2DRangeScan& o, RangeScan& s);

/// The byte behind a bool MRPT deserialised: it copies the byte from the file, so a corrupt
/// record can leave 5 there, and reading that as a bool is undefined (UBSan, fuzz_rawlog).
inline unsigned boolByte(const bool& b) {
  unsigned char c;
  std::memcpy(&c, &b, 1);
  return c;
}

/// "" when the bool fields the readers use hold 0 or 1, else what is wrong ("rightToLeft byte
/// 5"): such a record is corrupt and must not be converted.
inline std::string corruptScanField(const mrpt::obs::CObservation2DRangeScan& o) {
  const unsigned b = boolByte(o.rightToLeft);
  return b > 1 ? "rightToLeft byte " + std::to_string(b) : std::string();
}
}  // namespace sketchnav::drivers
