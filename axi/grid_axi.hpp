// The axisymmetric tier's staggered (r, x) grid.
//
// The container is the rigid cylinder r < Rc, periodic along the axis x with period P.
// Cells are squares of side h: nr = Rc / h cells across the radius, nx = P / h along the
// axis. The unknowns sit on a MAC arrangement in the meridian plane:
//
//   u  (radial velocity)  at (r_face(i), x_cell(j)), i = 0..nr   (rows 0 and nr: axis and wall, u = 0)
//   w  (axial velocity)   at (r_cell(i), x_face(j)), i = 0..nr-1
//   p  (pressure)         at (r_cell(i), x_cell(j)), i = 0..nr-1
//
// with r_face(i) = i h, r_cell(i) = (i + 1/2) h, x_face(j) = j h, x_cell(j) = (j + 1/2) h.
// Force densities (N/m^3) share the layout of the velocity component they drive. Every
// field is one contiguous array with the axial index fastest: value(i, j) = a[i * nx + j].
#pragma once

#include <cstddef>

namespace swim::axi {

struct AxiGrid {
  int nr = 0;       ///< cells across the radius (nr h = Rc)
  int nx = 0;       ///< cells along the periodic axis (nx h = P)
  double h = 0.0;   ///< cell size, m

  double radius() const { return nr * h; }
  double period() const { return nx * h; }
  double r_face(int i) const { return i * h; }
  double r_cell(int i) const { return (i + 0.5) * h; }
  double x_face(int j) const { return j * h; }
  double x_cell(int j) const { return (j + 0.5) * h; }

  /// Sizes of the three arrays.
  std::size_t u_size() const { return std::size_t(nr + 1) * nx; }
  std::size_t w_size() const { return std::size_t(nr) * nx; }
  std::size_t p_size() const { return std::size_t(nr) * nx; }
  std::size_t at(int i, int j) const { return std::size_t(i) * nx + j; }
};

}  // namespace swim::axi
