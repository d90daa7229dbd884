// VTK output for ParaView: triangulated surfaces as XML PolyData (.vtp) and a .pvd time
// collection that lists one file per output frame.
#pragma once

#include <array>
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
