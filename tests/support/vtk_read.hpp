// An independent reader of the VTK XML files swim writes, written from VTK's file-format
// description (not from common/vtk.cpp): the DataArrays of a file, and the values of one
// inline binary array compressed with vtkZLibDataCompressor (header_type UInt32).
#pragma once

#include <gtest/gtest.h>
#include <zlib.h>

#include <cctype>
#include <cstdint>
#include <cstring>
#include <regex>
#include <string>
#include <vector>

namespace swim::test::vtk_read {

inline std::vector<unsigned char> unbase64(const std::string& s) {
  auto val = [](char c) -> int {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+') return 62;
    if (c == '/') return 63;
    return -1;
  };
  std::vector<unsigned char> out;
  std::uint32_t acc = 0;
  int bits = 0;
  for (char c : s) {
    if (c == '=') break;
    const int v = val(c);
    if (v < 0) continue;  // whitespace
    acc = (acc << 6) | std::uint32_t(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<unsigned char>((acc >> bits) & 0xFF));
    }
  }
  return out;
}

struct Array {
  std::string type, name, body;
};

// Every DataArray of a file (a plain scan: std::regex recurses per character and would
// overflow the stack on the long base64 bodies of real frames).
inline std::vector<Array> arrays(const std::string& xml) {
  const auto attribute = [](const std::string& tag, const std::string& name) {
    const std::string key = " " + name + "=\"";
    const std::size_t at = tag.find(key);
    if (at == std::string::npos) return std::string();
    const std::size_t from = at + key.size();
    return tag.substr(from, tag.find('"', from) - from);
  };
  std::vector<Array> out;
  for (std::size_t at = xml.find("<DataArray"); at != std::string::npos; at = xml.find("<DataArray", at + 1)) {
    const std::size_t close = xml.find('>', at);
    const std::size_t end = xml.find("</DataArray>", close);
    if (close == std::string::npos || end == std::string::npos) break;
    const std::string tag = xml.substr(at, close - at);
    if (attribute(tag, "format") != "binary") continue;
    std::string body;
    for (std::size_t k = close + 1; k < end; ++k)
      if (!std::isspace(static_cast<unsigned char>(xml[k]))) body += xml[k];
    out.push_back({attribute(tag, "type"), attribute(tag, "Name"), body});
  }
  return out;
}

// One compressed inline binary DataArray body -> its values.
template <class T>
inline std::vector<T> decode(const std::string& body) {
  // the header's length follows from its first word (the number of blocks)
  const auto first = unbase64(body.substr(0, 8));
  EXPECT_GE(first.size(), 4u);
  if (first.size() < 4) return {};
  std::uint32_t blocks = 0;
  std::memcpy(&blocks, first.data(), 4);
  const std::size_t header_bytes = 4 * (3 + std::size_t(blocks));
  const std::size_t header_chars = 4 * ((header_bytes + 2) / 3);
  const auto header_raw = unbase64(body.substr(0, header_chars));
  EXPECT_EQ(header_raw.size(), header_bytes);
  std::vector<std::uint32_t> h(3 + blocks);
  std::memcpy(h.data(), header_raw.data(), header_bytes);
  const std::uint32_t block = h[1], partial = h[2];
  const auto packed = unbase64(body.substr(header_chars));
  std::vector<unsigned char> raw;
  std::size_t at = 0;
  for (std::uint32_t b = 0; b < blocks; ++b) {
    const uLongf want = (b + 1 == blocks && partial) ? partial : block;
    std::vector<unsigned char> out(want);
    uLongf got = want;
    EXPECT_LE(at + h[3 + b], packed.size());
    EXPECT_EQ(uncompress(out.data(), &got, packed.data() + at, h[3 + b]), Z_OK) << "block " << b;
    EXPECT_EQ(got, want);
    raw.insert(raw.end(), out.begin(), out.begin() + got);
    at += h[3 + b];
  }
  EXPECT_EQ(at, packed.size());
  EXPECT_EQ(raw.size() % sizeof(T), 0u);
  std::vector<T> v(raw.size() / sizeof(T));
  std::memcpy(v.data(), raw.data(), v.size() * sizeof(T));
  return v;
}

}  // namespace swim::test::vtk_read
