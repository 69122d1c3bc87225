#include "base/hash.h"

#include <cinttypes>
#include <cstdio>

namespace bifilar {

uint64_t Fnv1a64(const void* data, size_t size, uint64_t hash) {
  const auto* bytes = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < size; ++i) {
    hash ^= bytes[i];
    hash *= 0x100000001b3ULL;
  }
  return hash;
}

uint64_t Fnv1a64(const std::string& text, uint64_t hash) {
  return Fnv1a64(text.data(), text.size(), hash);
}

std::string HashToHex(uint64_t hash) {
  char buffer[17];
  std::snprintf(buffer, sizeof(buffer), "%016" PRIx64, hash);
  return buffer;
}

}  // namespace bifilar
