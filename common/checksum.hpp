// FNV-1a 64-bit checksum: the one hash of the product (result-file checksums in
// summary.json, scene hashes of run folders and checkpoints, the checkpoint payload).
// Not cryptographic: it detects accidental damage and mismatches, not tampering.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

namespace swim {

constexpr std::uint64_t kFnv1a64Offset = 1469598103934665603ull;
constexpr std::uint64_t kFnv1a64Prime = 1099511628211ull;

/// FNV-1a 64 of n bytes, continuing from h (kFnv1a64Offset for a fresh checksum).
inline std::uint64_t fnv1a64(const void* data, std::size_t n, std::uint64_t h = kFnv1a64Offset) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t k = 0; k < n; ++k) h = (h ^ p[k]) * kFnv1a64Prime;
  return h;
}
inline std::uint64_t fnv1a64(const std::string& s) { return fnv1a64(s.data(), s.size()); }

/// 16 lower-case hex digits.
inline std::string hex64(std::uint64_t v) {
  char b[20];
  std::snprintf(b, sizeof b, "%016llx", static_cast<unsigned long long>(v));
  return b;
}

}  // namespace swim
