// FNV-1a, 64 bits: a stable hash of bytes (the same in every run and build), for cache keys
// (the SPIR-V cache, the bench's reference cache). Not for anything adversarial.
#pragma once

#include <cstdint>
#include <string_view>

namespace plume {

inline uint64_t fnv1a(std::string_view s) {
  uint64_t h = 1469598103934665603ull;
  for (unsigned char c : s) h = (h ^ c) * 1099511628211ull;
  return h;
}

}  // namespace plume
