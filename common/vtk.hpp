// VTK output for ParaView: triangulated surfaces as XML PolyData (.vtp), cell fields on a
// uniform grid as XML ImageData (.vti), and a .pvd time collection that lists one file per
// output frame. Arrays are written inline in VTK's "binary" format: base64 of a UInt32
// byte count followed by the little-endian values; fields and points as Float32,
// connectivity as Int32 (about 4 x smaller than 9-digit ASCII).
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace swim::vtk {

/// A point-data array: `components` values per point (1 scalar, 3 vector), contiguous.
struct PointArray {
  std::string name;
  int components = 1;
  std::vector<double> values;
};

/// Write a triangulated surface. `xyz` holds 3 coordinates per point; `triangles` holds
/// point indices. Throws NumericalError when a value is not finite.
void write_polydata(const std::string& path, const std::vector<double>& xyz,
                    const std::vector<std::array<int, 3>>& triangles, const std::vector<PointArray>& arrays = {});

/// Cell data on nx x ny x nz cells of size `spacing` (m), origin 0; arrays of nx*ny*nz
/// tuples, x fastest. Throws NumericalError when a value is not finite.
void write_image_data(const std::string& path, std::array<int, 3> cells, double spacing,
                      const std::vector<PointArray>& cell_arrays);

/// Base64 (RFC 4648, with padding) of n bytes.
std::string base64(const unsigned char* p, std::size_t n);
/// One inline binary DataArray body: base64 of the UInt32 byte count and the bytes.
std::string encode_block(const void* data, std::size_t bytes);
/// encode_block of the values as Float32; throws NumericalError naming `what` on a non-finite value.
std::string float32_block(const std::vector<double>& v, const std::string& what);

/// A .pvd collection: add() frames as they are written, write() rewrites the index file
/// (cheap, so it can be called after every frame and survives an interrupted run).
class Collection {
 public:
  explicit Collection(std::string pvd_path) : path_(std::move(pvd_path)) {}
  void add(double time_s, const std::string& file_relative_to_pvd);
  void write() const;
  const std::vector<std::pair<double, std::string>>& frames() const { return frames_; }
  /// Drop frames later than t (used on resume from a checkpoint).
  void truncate_after(double t);

 private:
  std::string path_;
  std::vector<std::pair<double, std::string>> frames_;
};

}  // namespace swim::vtk
