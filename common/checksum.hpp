// FNV-1a 64-bit checksum (Fowler, Noll, Vo; offset basis 14695981039346656037, prime
// 1099511628211): the one hash of the product (result-file checksums in summary.json, the
// checksum a summary.json or calibration.json carries of itself, scene hashes of run folders and
// checkpoints, the checkpoint payload). Any FNV-1a 64 implementation verifies them; the
// published test vectors are checked in tests/common/test_checksum.cpp.
// Not cryptographic: it detects accidental damage and mismatches, not tampering.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>

namespace swim {

constexpr std::uint64_t kFnv1a64Offset = 14695981039346656037ull;
constexpr std::uint64_t kFnv1a64Prime = 1099511628211ull;

/// The offset basis of swim's checksums before they were the standard FNV-1a 64 (one digit
/// short of it). Summaries without "checksum_algorithm" were written with it; they are
/// recognised by that and never taken for verified results (docs/reliability.md).
constexpr std::uint64_t kFnv1a64LegacyOffset = 1469598103934665603ull;

/// The algorithm's name as summary.json and calibration.json give it ("checksum_algorithm").
inline constexpr const char* kChecksumAlgorithm =
    "FNV-1a 64-bit (offset basis 14695981039346656037, prime 1099511628211), 16 lower-case hex digits";

/// FNV-1a 64 of n bytes, continuing from h (kFnv1a64Offset for a fresh checksum).
constexpr std::uint64_t fnv1a64(const void* data, std::size_t n, std::uint64_t h = kFnv1a64Offset) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t k = 0; k < n; ++k) h = (h ^ p[k]) * kFnv1a64Prime;
  return h;
}
constexpr std::uint64_t fnv1a64(std::string_view s, std::uint64_t h = kFnv1a64Offset) {
  for (const char c : s) h = (h ^ static_cast<unsigned char>(c)) * kFnv1a64Prime;
  return h;
}
inline std::uint64_t fnv1a64(const std::string& s) { return fnv1a64(std::string_view(s)); }
inline std::uint64_t fnv1a64(const char* s) { return fnv1a64(std::string_view(s)); }

// The published test vectors of FNV-1a 64 (IETF draft-eastlake-fnv, Landon Curt Noll's page).
static_assert(fnv1a64(std::string_view("")) == 0xcbf29ce484222325ull);
static_assert(fnv1a64(std::string_view("a")) == 0xaf63dc4c8601ec8cull);
static_assert(fnv1a64(std::string_view("foobar")) == 0x85944171f73967e8ull);

/// 16 lower-case hex digits.
inline std::string hex64(std::uint64_t v) {
  char b[20];
  std::snprintf(b, sizeof b, "%016llx", static_cast<unsigned long long>(v));
  return b;
}

}  // namespace swim
