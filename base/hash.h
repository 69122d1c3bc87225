// FNV-1a 64 (offset basis 0xcbf29ce484222325, prime 0x100000001b3), one byte at a time: fast
// enough (about 1 GB/s) for logs of a few hundred kB, not cryptographic. The content hash of a
// log, the cache key (pipeline/store/cache.h), the output set's and the report's checksums.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace bifilar {

constexpr uint64_t kFnvOffsetBasis = 0xcbf29ce484222325ULL;

uint64_t Fnv1a64(const void* data, size_t size, uint64_t hash = kFnvOffsetBasis);
uint64_t Fnv1a64(const std::string& text, uint64_t hash = kFnvOffsetBasis);
std::string HashToHex(uint64_t hash);  // 16 lowercase hex digits

}  // namespace bifilar
