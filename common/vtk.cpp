#include "common/vtk.hpp"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>

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
  std::vector<unsigned char> buf(4 + bytes);
  const std::uint32_t header = static_cast<std::uint32_t>(bytes);  // little-endian host (x86-64, aarch64)
  std::memcpy(buf.data(), &header, 4);
  if (bytes) std::memcpy(buf.data() + 4, data, bytes);
  return base64(buf.data(), buf.size());
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

void int_array(std::ostream& out, const std::string& name, const std::vector<std::int32_t>& v) {
  out << "<DataArray type=\"Int32\" Name=\"" << name << "\" format=\"binary\">\n"
      << encode_block(v.data(), v.size() * sizeof(std::int32_t)) << "\n</DataArray>\n";
}

const char* kHeader = "<?xml version=\"1.0\"?>\n";

}  // namespace

void write_polydata(const std::string& path, const std::vector<double>& xyz,
                    const std::vector<std::array<int, 3>>& triangles, const std::vector<PointArray>& arrays) {
  const size_t n = xyz.size() / 3;
  for (const auto& a : arrays)
    if (a.values.size() != n * static_cast<size_t>(a.components))
      throw std::logic_error("VTK array " + a.name + " has the wrong size");
  output::AtomicFile file(path);
  std::ostream& out = file.stream();
  out << kHeader
      << "<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n<PolyData>\n"
      << "<Piece NumberOfPoints=\"" << n << "\" NumberOfVerts=\"0\" NumberOfLines=\"0\" NumberOfStrips=\"0\" "
      << "NumberOfPolys=\"" << triangles.size() << "\">\n";
  out << "<PointData>\n";
  for (const auto& a : arrays) float_array(out, a.name, a.components, a.values);
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
                      const std::vector<PointArray>& cell_arrays) {
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
      << "<VTKFile type=\"ImageData\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      << "<ImageData WholeExtent=\"" << extent << "\" Origin=\"0 0 0\" Spacing=\"" << h << " " << h << " " << h
      << "\">\n<Piece Extent=\"" << extent << "\">\n<CellData>\n";
  for (const auto& a : cell_arrays) float_array(out, a.name, a.components, a.values);
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
