// VTK output for ParaView: triangulated surfaces as XML PolyData (.vtp), cell fields on a
// uniform grid as XML ImageData (.vti), and a .pvd time collection that lists one file per
// output frame. Arrays are written inline in VTK's "binary" format, compressed with zlib
// (compressor="vtkZLibDataCompressor", header_type="UInt32"): per array, the base64 of the
// header [number of blocks, block size, size of a partial last block (0: none), compressed
// size of each block], then the base64 of the zlib streams of the blocks (32 KiB of values
// each). Fields and points are Float32, connectivity, offsets and integer fields Int32. A
// frame written at a time carries it as the FieldData array TimeValue (Float64), which
// ParaView and VTK read as the dataset's time.
#pragma once

#include <array>
#include <cstddef>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace swim::vtk {

/// A point-data array: `components` values per point (1 scalar, 3 vector), contiguous.
struct PointArray {
  std::string name;
  int components = 1;
  std::vector<double> values;
  bool integer = false;  ///< written as Int32 (the values are whole numbers: indices, masks)
};

/// Write a triangulated surface. `xyz` holds 3 coordinates per point; `triangles` holds
/// point indices. time_s (finite): the frame's time, written as FieldData TimeValue. Throws
/// NumericalError when a value is not finite.
void write_polydata(const std::string& path, const std::vector<double>& xyz,
                    const std::vector<std::array<int, 3>>& triangles, const std::vector<PointArray>& arrays = {},
                    double time_s = std::numeric_limits<double>::quiet_NaN());

/// Cell data on nx x ny x nz cells of size `spacing` (m), origin 0; arrays of nx*ny*nz
/// tuples, x fastest. Throws NumericalError when a value is not finite.
void write_image_data(const std::string& path, std::array<int, 3> cells, double spacing,
                      const std::vector<PointArray>& cell_arrays,
                      double time_s = std::numeric_limits<double>::quiet_NaN());

/// Base64 (RFC 4648, with padding) of n bytes.
std::string base64(const unsigned char* p, std::size_t n);
/// One inline binary DataArray body, zlib-compressed: base64 of the UInt32 header (blocks,
/// block size, partial last block size, compressed sizes), then base64 of the compressed blocks.
std::string encode_block(const void* data, std::size_t bytes);
/// The uncompressed size of a block (the last may be partial).
inline constexpr std::size_t kBlockBytes = 32768;
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
