#pragma once
// FNV-1a, 64 bit (Fowler, Noll & Vo): a fast hash of bytes for fingerprints that tell one
// scene or file from another (not a checksum against damage: the checkpoints use Fletcher-32).
#include <cstdint>
#include <string_view>

namespace grainflow {

inline constexpr std::uint64_t kFnv1a64Start = 14695981039346656037ull;

// The hash of `bytes` continued from `hash` (kFnv1a64Start for a new one).
inline std::uint64_t fnv1a64(std::string_view bytes, std::uint64_t hash = kFnv1a64Start) {
  for (const char c : bytes) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 1099511628211ull;
  }
  return hash;
}

}  // namespace grainflow
