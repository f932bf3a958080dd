#include "entry_points.h"

#include "sketchnav/core/error.h"
#include "sketchnav/hw/base_protocol.h"

namespace sketchnav::fuzz {

void baseProtocol(const std::uint8_t* d, std::size_t n) {
  hw::proto::Message m;
  if (hw::proto::decode(d, n, m) == hw::proto::DecodeError::None) {
    // Whatever decodes must encode again and decode to the same type.
    const auto again = hw::proto::encode(m);
    hw::proto::Message m2;
    if (hw::proto::decode(again.data(), again.size(), m2) != hw::proto::DecodeError::None ||
        m2.header.type != m.header.type)
      __builtin_trap();
  }
  (void)hw::proto::decode(d, n, m, "fuzz-secret");
}

}  // namespace sketchnav::fuzz
