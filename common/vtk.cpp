#include "common/vtk.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>

#include "common/atomic_file.hpp"
#include "common/errors.hpp"

namespace swim::vtk {

namespace {
void put_values(std::ostream& out, const std::vector<double>& v, const std::string& what) {
  char b[32];
  for (size_t i = 0; i < v.size(); ++i) {
    if (!std::isfinite(v[i]))
      throw NumericalError("non-finite value in VTK array '" + what + "'", "reduce the time step");
    std::snprintf(b, sizeof b, "%.9g", v[i]);
    out << b << ((i + 1) % 9 == 0 ? "\n" : " ");
  }
  out << "\n";
}
}  // namespace

void write_polydata(const std::string& path, const std::vector<double>& xyz,
                    const std::vector<std::array<int, 3>>& triangles, const std::vector<PointArray>& arrays) {
  const size_t n = xyz.size() / 3;
  output::AtomicFile file(path);
  std::ostream& out = file.stream();
  out << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n<PolyData>\n"
      << "<Piece NumberOfPoints=\"" << n << "\" NumberOfVerts=\"0\" NumberOfLines=\"0\" NumberOfStrips=\"0\" "
      << "NumberOfPolys=\"" << triangles.size() << "\">\n";
  out << "<PointData>\n";
  for (const auto& a : arrays) {
    if (a.values.size() != n * static_cast<size_t>(a.components))
      throw std::logic_error("VTK array " + a.name + " has the wrong size");
    out << "<DataArray type=\"Float64\" Name=\"" << a.name << "\" NumberOfComponents=\"" << a.components
        << "\" format=\"ascii\">\n";
    put_values(out, a.values, a.name);
    out << "</DataArray>\n";
  }
  out << "</PointData>\n<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  put_values(out, xyz, "Points");
  out << "</DataArray>\n</Points>\n<Polys>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (const auto& t : triangles) out << t[0] << " " << t[1] << " " << t[2] << "\n";
  out << "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  for (size_t k = 0; k < triangles.size(); ++k) out << 3 * (k + 1) << ((k + 1) % 12 == 0 ? "\n" : " ");
  out << "\n</DataArray>\n</Polys>\n</Piece>\n</PolyData>\n</VTKFile>\n";
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
