// VTK XML output (common/vtk.hpp): well-formed XML whose inline binary arrays decode, with a
// decoder written here from VTK's file-format description, to the written values, in the layout
// VTK 9 / ParaView 5.11 read: zlib-compressed blocks (compressor="vtkZLibDataCompressor",
// header_type="UInt32": base64 of the header [blocks, block size, partial last block size,
// compressed sizes], then base64 of the zlib streams), Float32 fields, Int32 connectivity and
// integer fields, the frame's time as FieldData TimeValue.
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
#include "tests/support/vtk_read.hpp"

#include <zlib.h>

using namespace swim;

namespace {

using namespace swim::test::vtk_read;

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
  vtk::PointArray seg{"segment", 1, {0, 1, 5, 2}};
  seg.integer = true;
  vtk::write_polydata(path, xyz, tri, {r, v, seg}, 0.0125);
  const std::string xml = slurp(path);
  EXPECT_TRUE(balanced(xml));
  EXPECT_NE(xml.find("compressor=\"vtkZLibDataCompressor\""), std::string::npos);
  EXPECT_NE(xml.find("header_type=\"UInt32\""), std::string::npos);
  EXPECT_NE(xml.find("NumberOfPoints=\"4\""), std::string::npos);
  EXPECT_NE(xml.find("NumberOfPolys=\"2\""), std::string::npos);
  EXPECT_EQ(xml.find("ascii"), std::string::npos);
  const auto a = arrays(xml);
  ASSERT_EQ(a.size(), 7u);  // the time, three point arrays, the points, connectivity, offsets
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
  EXPECT_EQ(by["segment"].type, "Int32");
  EXPECT_EQ(decode<std::int32_t>(by["segment"].body), (std::vector<std::int32_t>{0, 1, 5, 2}));
  EXPECT_EQ(by["TimeValue"].type, "Float64");
  EXPECT_NE(xml.find("<FieldData>"), std::string::npos);
  EXPECT_EQ(decode<double>(by["TimeValue"].body), (std::vector<double>{0.0125}));
}

// Arrays longer than one block (32 KiB) are split into blocks, each its own zlib stream, the
// last one partial; smooth fields compress.
TEST(Vtk, LargeArraysSplitIntoCompressedBlocks) {
  const std::array<int, 3> n = {40, 30, 20};  // 24 000 cells: 96 000 bytes of Float32 per scalar
  vtk::PointArray p{"pressure_Pa", 1, std::vector<double>(24000)};
  for (int i = 0; i < 24000; ++i) p.values[i] = std::sin(1e-3 * i);
  vtk::PointArray mask{"inside_container", 1, std::vector<double>(24000)};
  for (int i = 0; i < 24000; ++i) mask.values[i] = (i / 40) % 3 == 0;
  mask.integer = true;
  const std::string path = tmp("large.vti");
  vtk::write_image_data(path, n, 1e-8, {p, mask}, 2.5);
  const std::string xml = slurp(path);
  EXPECT_TRUE(balanced(xml));
  const auto a = arrays(xml);
  ASSERT_EQ(a.size(), 3u);
  std::map<std::string, Array> by;
  for (const auto& x : a) by[x.name] = x;
  const auto first = unbase64(by["pressure_Pa"].body.substr(0, 8));
  std::uint32_t blocks = 0;
  std::memcpy(&blocks, first.data(), 4);
  EXPECT_EQ(blocks, 3u);  // 96 000 bytes = 2 full blocks and a partial one
  const auto v = decode<float>(by["pressure_Pa"].body);
  ASSERT_EQ(v.size(), 24000u);
  for (int i = 0; i < 24000; i += 997) EXPECT_EQ(v[i], static_cast<float>(p.values[i]));
  const auto m = decode<std::int32_t>(by["inside_container"].body);
  ASSERT_EQ(m.size(), 24000u);
  for (int i = 0; i < 24000; i += 101) EXPECT_EQ(m[i], static_cast<std::int32_t>(mask.values[i]));
  EXPECT_LT(by["inside_container"].body.size(), 96000u / 10);  // a mask compresses well
  EXPECT_EQ(decode<double>(by["TimeValue"].body), (std::vector<double>{2.5}));
  vtk::PointArray bad{"segment", 1, std::vector<double>(24000, 0.5)};
  bad.integer = true;
  EXPECT_THROW(vtk::write_image_data(tmp("bad.vti"), n, 1e-8, {bad}), std::logic_error);
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
