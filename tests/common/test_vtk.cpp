// VTK XML output (common/vtk.hpp): well-formed XML whose inline binary arrays (base64 of a
// UInt32 byte count and little-endian values) decode to the written values, in the layout
// VTK 9 / ParaView 5.11 read (file version 0.1: UInt32 block headers; Float32 fields, Int32 connectivity).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "common/errors.hpp"
#include "common/vtk.hpp"

using namespace swim;

namespace {

std::vector<unsigned char> unbase64(const std::string& s) {
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

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Tags balance (a minimal well-formedness check: every element closed in order).
bool balanced(const std::string& xml) {
  std::vector<std::string> stack;
  const std::regex tag(R"(<(/?)([A-Za-z][A-Za-z0-9]*)[^>]*?(/?)>)");
  for (std::sregex_iterator it(xml.begin(), xml.end(), tag), end; it != end; ++it) {
    const std::string name = (*it)[2];
    if ((*it)[1] == "/") {
      if (stack.empty() || stack.back() != name) return false;
      stack.pop_back();
    } else if ((*it)[3] != "/") {
      stack.push_back(name);
    }
  }
  return stack.empty();
}

struct Array {
  std::string type, name, body;
};

std::vector<Array> arrays(const std::string& xml) {
  std::vector<Array> out;
  const std::regex da(R"re(<DataArray type="([A-Za-z0-9]+)"(?: Name="([^"]*)")?[^>]*format="binary">\s*([A-Za-z0-9+/=]*)\s*</DataArray>)re");
  for (std::sregex_iterator it(xml.begin(), xml.end(), da), end; it != end; ++it)
    out.push_back({(*it)[1], (*it)[2], (*it)[3]});
  return out;
}

template <class T>
std::vector<T> decode(const std::string& body) {
  const auto bytes = unbase64(body);
  EXPECT_GE(bytes.size(), 4u);
  std::uint32_t n = 0;
  std::memcpy(&n, bytes.data(), 4);
  EXPECT_EQ(n, bytes.size() - 4);
  std::vector<T> v(n / sizeof(T));
  std::memcpy(v.data(), bytes.data() + 4, n);
  return v;
}

std::string tmp(const std::string& name) {
  const std::string d = std::string(SWIM_BINARY_DIR) + "/tests/out_vtk";
  std::filesystem::create_directories(d);
  return d + "/" + name;
}

}  // namespace

TEST(Vtk, Base64MatchesRfc4648) {
  const std::string s = "Man is distinguished";
  EXPECT_EQ(vtk::base64(reinterpret_cast<const unsigned char*>(s.data()), 3), "TWFu");
  EXPECT_EQ(vtk::base64(reinterpret_cast<const unsigned char*>(s.data()), 2), "TWE=");
  EXPECT_EQ(vtk::base64(reinterpret_cast<const unsigned char*>(s.data()), 1), "TQ==");
  EXPECT_EQ(vtk::base64(reinterpret_cast<const unsigned char*>(s.data()), 0), "");
}

TEST(Vtk, PolyDataDecodesToTheWrittenValues) {
  const std::vector<double> xyz = {0, 0, 0, 1e-6, 0, 0, 0, 1e-6, 0, 0, 0, 1.25e-7};
  const std::vector<std::array<int, 3>> tri = {{0, 1, 2}, {0, 2, 3}};
  const vtk::PointArray r{"radius_m", 1, {1.0e-7, 2.5e-7, -3.0, 4.0}};
  const vtk::PointArray v{"velocity_m_per_s", 3, std::vector<double>(12, 1.5e-9)};
  const std::string path = tmp("poly.vtp");
  vtk::write_polydata(path, xyz, tri, {r, v});
  const std::string xml = slurp(path);
  EXPECT_TRUE(balanced(xml));
  EXPECT_NE(xml.find("version=\"0.1\""), std::string::npos);  // UInt32 block headers (the 0.1 default)
  EXPECT_NE(xml.find("NumberOfPoints=\"4\""), std::string::npos);
  EXPECT_NE(xml.find("NumberOfPolys=\"2\""), std::string::npos);
  EXPECT_EQ(xml.find("ascii"), std::string::npos);
  const auto a = arrays(xml);
  ASSERT_EQ(a.size(), 5u);  // two point arrays, the points, connectivity, offsets
  std::map<std::string, Array> by;
  for (const auto& x : a) by[x.name] = x;
  EXPECT_EQ(by["radius_m"].type, "Float32");
  const auto rr = decode<float>(by["radius_m"].body);
  ASSERT_EQ(rr.size(), 4u);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(rr[i], static_cast<float>(r.values[i]));
  EXPECT_EQ(decode<float>(by["velocity_m_per_s"].body).size(), 12u);
  const auto pts = decode<float>(by[""].body);
  ASSERT_EQ(pts.size(), 12u);
  for (int i = 0; i < 12; ++i) EXPECT_EQ(pts[i], static_cast<float>(xyz[i]));
  EXPECT_EQ(by["connectivity"].type, "Int32");
  EXPECT_EQ(decode<std::int32_t>(by["connectivity"].body), (std::vector<std::int32_t>{0, 1, 2, 0, 2, 3}));
  EXPECT_EQ(decode<std::int32_t>(by["offsets"].body), (std::vector<std::int32_t>{3, 6}));
}

TEST(Vtk, ImageDataDecodesAndRejectsNonFinite) {
  const std::array<int, 3> n = {3, 2, 2};
  vtk::PointArray p{"pressure_Pa", 1, std::vector<double>(12)};
  for (int i = 0; i < 12; ++i) p.values[i] = 0.1 * i - 0.3;
  const std::string path = tmp("image.vti");
  vtk::write_image_data(path, n, 1.5625e-8, {p});
  const std::string xml = slurp(path);
  EXPECT_TRUE(balanced(xml));
  EXPECT_NE(xml.find("WholeExtent=\"0 3 0 2 0 2\""), std::string::npos);
  const auto a = arrays(xml);
  ASSERT_EQ(a.size(), 1u);
  const auto v = decode<float>(a[0].body);
  ASSERT_EQ(v.size(), 12u);
  for (int i = 0; i < 12; ++i) EXPECT_EQ(v[i], static_cast<float>(p.values[i]));
  p.values[5] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(vtk::write_image_data(tmp("nan.vti"), n, 1e-8, {p}), NumericalError);
}
