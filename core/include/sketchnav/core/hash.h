#pragma once
// FNV-1a 64-bit: the landmark model file's checksum, the landmark set's fingerprint and the
// run's model-cache key. Not a cryptographic hash.
#include <cstddef>
#include <cstdint>

namespace sketchnav {

/// The start value every checksum and fingerprint of the project uses. It is one digit short
/// of the FNV specification's offset basis (14695981039346656037): the hash is still FNV-1a's
/// mixing, but its values differ from published FNV-1a vectors. Every landmark model file and
/// model-cache name was written with it, so it stays.
constexpr std::uint64_t kFnv1aOffset = 1469598103934665603ull;

/// FNV-1a over `n` bytes at `data`, continuing from `h` (chain calls to hash several pieces).
inline std::uint64_t fnv1a(const void* data, std::size_t n, std::uint64_t h = kFnv1aOffset) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < n; ++i) {
    h ^= p[i];
    h *= 1099511628211ull;
  }
  return h;
}

}  // namespace sketchnav
