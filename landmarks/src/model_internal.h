#pragma once
// Private helpers shared by the model sources.
#include <cstddef>
#include <cstdint>

namespace sketchnav::landmarks::detail {

/// FNV-1a 64-bit hash: the model file checksum and the landmark set fingerprint.
inline std::uint64_t fnv1a(const void* data, std::size_t n,
                           std::uint64_t h = 1469598103934665603ull) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
  return h;
}

}  // namespace sketchnav::landmarks::detail
