#include "entry_points.h"

#include "sketchnav/core/error.h"
#include "sketchnav/drivers/base_protocol.h"

namespace sketchnav::fuzz {

void baseProtocol(const std::uint8_t* d, std::size_t n) {
  drivers::proto::Message m;
  if (drivers::proto::decode(d, n, m) == drivers::proto::DecodeError::None) {
    // Whatever decodes must encode again and decode to the same type.
    const auto again = drivers::proto::encode(m);
    drivers::proto::Message m2;
    if (drivers::proto::decode(again.data(), again.size(), m2) !=
            drivers::proto::DecodeError::None ||
        m2.header.type != m.header.type)
      __builtin_trap();
  }
  (void)drivers::proto::decode(d, n, m, "fuzz-secret");
}

}  // namespace sketchnav::fuzz
