#include "common/vtk.hpp"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <algorithm>
#include <fstream>
#include <stdexcept>

#include <zlib.h>

#include "common/atomic_file.hpp"
#include "common/errors.hpp"

namespace swim::vtk {

namespace {

constexpr char kB64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

}  // namespace

std::string base64(const unsigned char* p, std::size_t n) {
  std::string s(4 * ((n + 2) / 3), '=');
  char* o = s.data();
  std::size_t i = 0;
  for (; i + 2 < n; i += 3, o += 4) {
    const std::uint32_t v = (std::uint32_t(p[i]) << 16) | (std::uint32_t(p[i + 1]) << 8) | p[i + 2];
    o[0] = kB64[v >> 18];
    o[1] = kB64[(v >> 12) & 63];
    o[2] = kB64[(v >> 6) & 63];
    o[3] = kB64[v & 63];
  }
  if (i < n) {  // one or two bytes left: the padding '=' is already in place
    const std::uint32_t v = (std::uint32_t(p[i]) << 16) | (i + 1 < n ? std::uint32_t(p[i + 1]) << 8 : 0u);
    o[0] = kB64[v >> 18];
    o[1] = kB64[(v >> 12) & 63];
    if (i + 1 < n) o[2] = kB64[(v >> 6) & 63];
  }
  return s;
}

std::string encode_block(const void* data, std::size_t bytes) {
  if (bytes > 0xFFFFFFFFull) throw std::length_error("VTK array larger than 4 GiB");
  const auto* in = static_cast<const unsigned char*>(data);
  const std::size_t blocks = (bytes + kBlockBytes - 1) / kBlockBytes;
  // header (little-endian host: x86-64, aarch64): blocks, block size, partial last block, sizes
  std::vector<std::uint32_t> header = {static_cast<std::uint32_t>(blocks), static_cast<std::uint32_t>(kBlockBytes),
                                       static_cast<std::uint32_t>(bytes % kBlockBytes)};
  std::vector<unsigned char> packed;
  packed.reserve(compressBound(static_cast<uLong>(std::min(bytes, kBlockBytes))) * std::max<std::size_t>(blocks, 1));
  for (std::size_t b = 0; b < blocks; ++b) {
    const std::size_t n = std::min(kBlockBytes, bytes - b * kBlockBytes);
    uLongf size = compressBound(static_cast<uLong>(n));
    const std::size_t at = packed.size();
    packed.resize(at + size);
    if (compress2(packed.data() + at, &size, in + b * kBlockBytes, static_cast<uLong>(n), Z_DEFAULT_COMPRESSION) != Z_OK)
      throw std::runtime_error("zlib could not compress a VTK array");
    packed.resize(at + size);
    header.push_back(static_cast<std::uint32_t>(size));
  }
  return base64(reinterpret_cast<const unsigned char*>(header.data()), header.size() * sizeof(std::uint32_t)) +
         base64(packed.data(), packed.size());
}

std::string float32_block(const std::vector<double>& v, const std::string& what) {
  std::vector<float> f(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!std::isfinite(v[i]))
      throw NumericalError("non-finite value in VTK array '" + what + "'", "reduce the time step");
    f[i] = static_cast<float>(v[i]);
  }
  return encode_block(f.data(), f.size() * sizeof(float));
}

namespace {

void float_array(std::ostream& out, const std::string& name, int components, const std::vector<double>& v) {
  out << "<DataArray type=\"Float32\"";
  if (!name.empty()) out << " Name=\"" << name << "\"";
  out << " NumberOfComponents=\"" << components << "\" format=\"binary\">\n" << float32_block(v, name.empty() ? "Points" : name)
      << "\n</DataArray>\n";
}

void int_array(std::ostream& out, const std::string& name, const std::vector<std::int32_t>& v, int components = 1) {
  out << "<DataArray type=\"Int32\" Name=\"" << name << "\" NumberOfComponents=\"" << components
      << "\" format=\"binary\">\n" << encode_block(v.data(), v.size() * sizeof(std::int32_t)) << "\n</DataArray>\n";
}

void data_array(std::ostream& out, const PointArray& a) {
  if (!a.integer) return float_array(out, a.name, a.components, a.values);
  std::vector<std::int32_t> v(a.values.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!(std::abs(a.values[i]) < 2147483647.0) || a.values[i] != std::round(a.values[i]))
      throw std::logic_error("VTK integer array " + a.name + " holds a value that is not a 32-bit integer");
    v[i] = static_cast<std::int32_t>(a.values[i]);
  }
  int_array(out, a.name, v, a.components);
}

// The frame's time as ParaView and VTK read it: FieldData TimeValue (one Float64).
void time_value(std::ostream& out, double time_s) {
  if (std::isnan(time_s)) return;
  if (!std::isfinite(time_s)) throw NumericalError("non-finite frame time in a VTK file", "reduce the time step");
  out << "<FieldData>\n<DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" format=\"binary\">\n"
      << encode_block(&time_s, sizeof time_s) << "\n</DataArray>\n</FieldData>\n";
}

const char* kHeader = "<?xml version=\"1.0\"?>\n";
const char* kCompressed = "byte_order=\"LittleEndian\" header_type=\"UInt32\" compressor=\"vtkZLibDataCompressor\"";

}  // namespace

void write_polydata(const std::string& path, const std::vector<double>& xyz,
                    const std::vector<std::array<int, 3>>& triangles, const std::vector<PointArray>& arrays,
                    double time_s) {
  const size_t n = xyz.size() / 3;
  for (const auto& a : arrays)
    if (a.values.size() != n * static_cast<size_t>(a.components))
      throw std::logic_error("VTK array " + a.name + " has the wrong size");
  output::AtomicFile file(path);
  std::ostream& out = file.stream();
  out << kHeader
      << "<VTKFile type=\"PolyData\" version=\"1.0\" " << kCompressed << ">\n<PolyData>\n";
  time_value(out, time_s);
  out << "<Piece NumberOfPoints=\"" << n << "\" NumberOfVerts=\"0\" NumberOfLines=\"0\" NumberOfStrips=\"0\" "
      << "NumberOfPolys=\"" << triangles.size() << "\">\n";
  out << "<PointData>\n";
  for (const auto& a : arrays) data_array(out, a);
  out << "</PointData>\n<Points>\n";
  float_array(out, "", 3, xyz);
  out << "</Points>\n<Polys>\n";
  std::vector<std::int32_t> conn, offs;
  conn.reserve(3 * triangles.size());
  offs.reserve(triangles.size());
  for (size_t k = 0; k < triangles.size(); ++k) {
    for (int c = 0; c < 3; ++c) conn.push_back(triangles[k][c]);
    offs.push_back(static_cast<std::int32_t>(3 * (k + 1)));
  }
  int_array(out, "connectivity", conn);
  int_array(out, "offsets", offs);
  out << "</Polys>\n</Piece>\n</PolyData>\n</VTKFile>\n";
  file.commit();
}

void write_image_data(const std::string& path, std::array<int, 3> cells, double spacing,
                      const std::vector<PointArray>& cell_arrays, double time_s) {
  const size_t n = size_t(cells[0]) * cells[1] * cells[2];
  for (const auto& a : cell_arrays)
    if (a.values.size() != n * static_cast<size_t>(a.components))
      throw std::logic_error("VTK array " + a.name + " has the wrong size");
  output::AtomicFile file(path);
  std::ostream& out = file.stream();
  char h[32];
  std::snprintf(h, sizeof h, "%.17g", spacing);
  const std::string extent = "0 " + std::to_string(cells[0]) + " 0 " + std::to_string(cells[1]) + " 0 " +
                             std::to_string(cells[2]);
  out << kHeader
      << "<VTKFile type=\"ImageData\" version=\"1.0\" " << kCompressed << ">\n"
      << "<ImageData WholeExtent=\"" << extent << "\" Origin=\"0 0 0\" Spacing=\"" << h << " " << h << " " << h
      << "\">\n";
  time_value(out, time_s);
  out << "<Piece Extent=\"" << extent << "\">\n<CellData>\n";
  for (const auto& a : cell_arrays) data_array(out, a);
  out << "</CellData>\n</Piece>\n</ImageData>\n</VTKFile>\n";
  file.commit();
}

void Collection::add(double time_s, const std::string& file) { frames_.emplace_back(time_s, file); }

void Collection::truncate_after(double t) {
  while (!frames_.empty() && frames_.back().first > t) frames_.pop_back();
}

void Collection::write() const {
  output::AtomicFile file(path_);
  std::ostream& out = file.stream();
  out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n";
  char b[32];
  for (const auto& [t, f] : frames_) {
    std::snprintf(b, sizeof b, "%.9g", t);
    out << "  <DataSet timestep=\"" << b << "\" part=\"0\" file=\"" << f << "\"/>\n";
  }
  out << "</Collection>\n</VTKFile>\n";
  file.commit();
}

}  // namespace swim::vtk
