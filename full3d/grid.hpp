// Uniform MAC (marker-and-cell, staggered) grid of the 3D tier.
//
// nx * ny * nz cubic cells of side h. The swimmer axis is x, which is always
// periodic with period Lx = nx h. Unknowns (x fastest in memory):
//
//   u (x-velocity) on x-faces   at ( i h,       (j+1/2) h, (k+1/2) h )
//   v (y-velocity) on y-faces   at ((i+1/2) h,   j h,      (k+1/2) h )
//   w (z-velocity) on z-faces   at ((i+1/2) h,  (j+1/2) h,  k h      )
//   p (pressure)   at centres   at ((i+1/2) h,  (j+1/2) h, (k+1/2) h )
//
// Boundaries of the grid (GridBoundary; the scene's container shape maps onto one: box ->
// PeriodicBox, duct and cylinder -> SquareDuct, the cylinder immersed inside the duct):
//   PeriodicBox  periodic in x, y and z; every component has nx*ny*nz values.
//   SquareDuct   periodic in x, no-slip walls at y = 0, Ly and z = 0, Lz.
//                v has ny+1 face layers in y (j = 0 and j = ny lie on the walls
//                and are held at zero), w has nz+1 layers in z likewise. The
//                tangential components are half a cell from the walls; their
//                no-slip condition is the ghost-cell rule u_ghost = -u_interior.
//
// Storage is one contiguous std::vector<double> per component.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

namespace swim::full3d {

enum class GridBoundary { PeriodicBox, SquareDuct };

std::string to_string(GridBoundary boundary);
/// Parses "periodic_box" / "square_duct"; throws swim::InputError(key, value, allowed).
GridBoundary grid_boundary_from_string(const std::string& key, const std::string& value);

class MacGrid {
 public:
  /// Throws swim::InputError for non-positive sizes, h <= 0, or (duct) ny, nz < 2.
  MacGrid(int nx, int ny, int nz, double h, GridBoundary boundary);

  int nx() const { return n_[0]; }
  int ny() const { return n_[1]; }
  int nz() const { return n_[2]; }
  int n(int dir) const { return n_[dir]; }
  double h() const { return h_; }
  GridBoundary boundary() const { return boundary_; }
  bool periodic(int dir) const { return dir == 0 || boundary_ == GridBoundary::PeriodicBox; }
  double length(int dir) const { return n_[dir] * h_; }
  std::size_t cells() const { return std::size_t(n_[0]) * n_[1] * n_[2]; }

  /// Array dimensions {Nx, Ny, Nz} of velocity component c (0,1,2) or of the
  /// pressure (c = 3).
  std::array<int, 3> dims(int c) const {
    std::array<int, 3> d = n_;
    if (c < 3 && !periodic(c)) d[c] += 1;
    return d;
  }
  std::size_t size(int c) const {
    const auto d = dims(c);
    return std::size_t(d[0]) * d[1] * d[2];
  }
  /// Linear index of (i,j,k) in an array of dimensions d (x fastest).
  static std::size_t index(const std::array<int, 3>& d, int i, int j, int k) {
    return (std::size_t(k) * d[1] + j) * d[0] + i;
  }
  /// Staggering offset (in cells) of component c (0..2, or 3 = pressure) along dir:
  /// 0 on the component's own face direction, 1/2 otherwise.
  static double offset(int c, int dir) { return c == dir ? 0.0 : 0.5; }
  /// Physical position of node (i,j,k) of component c.
  std::array<double, 3> position(int c, int i, int j, int k) const {
    return {(i + offset(c, 0)) * h_, (j + offset(c, 1)) * h_, (k + offset(c, 2)) * h_};
  }
  /// True when node index `idx` along dir of component c lies on a wall (held at zero).
  bool on_wall(int c, int dir, int idx) const {
    return !periodic(dir) && c == dir && (idx == 0 || idx == n_[dir]);
  }

 private:
  std::array<int, 3> n_;
  double h_;
  GridBoundary boundary_;
};

/// Velocity on the MAC faces: three contiguous arrays sized by MacGrid::dims(c).
struct VectorField {
  VectorField() = default;
  explicit VectorField(const MacGrid& g)
      : c{std::vector<double>(g.size(0), 0.0), std::vector<double>(g.size(1), 0.0),
          std::vector<double>(g.size(2), 0.0)} {}
  std::array<std::vector<double>, 3> c;
  void fill(double value);
  /// this += a * x
  void axpy(double a, const VectorField& x);
  double max_abs() const;
  bool all_finite() const;
};

/// Cell-centred scalar (pressure, divergence).
struct ScalarField {
  ScalarField() = default;
  explicit ScalarField(const MacGrid& g) : v(g.cells(), 0.0) {}
  std::vector<double> v;
  double max_abs() const;
};

}  // namespace swim::full3d
