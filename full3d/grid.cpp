#include "full3d/grid.hpp"

#include <algorithm>
#include <cmath>

#include "common/errors.hpp"

namespace swim::full3d {

std::string to_string(GridBoundary boundary) {
  return boundary == GridBoundary::PeriodicBox ? "periodic_box" : "square_duct";
}

GridBoundary grid_boundary_from_string(const std::string& key, const std::string& value) {
  if (value == "periodic_box") return GridBoundary::PeriodicBox;
  if (value == "square_duct") return GridBoundary::SquareDuct;
  throw InputError(key, value, "one of periodic_box, square_duct");
}

MacGrid::MacGrid(int nx, int ny, int nz, double h, GridBoundary boundary) : n_{nx, ny, nz}, h_(h), boundary_(boundary) {
  const int nmin = boundary == GridBoundary::SquareDuct ? 2 : 1;
  const char* names[3] = {"grid.nx", "grid.ny", "grid.nz"};
  for (int d = 0; d < 3; ++d) {
    const int lo = d == 0 ? 1 : nmin;
    if (n_[d] < lo) throw InputError(names[d], std::to_string(n_[d]), "an integer >= " + std::to_string(lo));
  }
  if (!(h > 0.0) || !std::isfinite(h)) throw InputError("grid.h", std::to_string(h), "a positive cell size in m");
}

void VectorField::fill(double value) {
  for (auto& a : c) std::fill(a.begin(), a.end(), value);
}

void VectorField::axpy(double a, const VectorField& x) {
  for (int d = 0; d < 3; ++d)
    for (std::size_t n = 0; n < c[d].size(); ++n) c[d][n] += a * x.c[d][n];
}

double VectorField::max_abs() const {
  double m = 0.0;
  for (const auto& a : c)
    for (double x : a) m = std::max(m, std::abs(x));
  return m;
}

bool VectorField::all_finite() const {
  for (const auto& a : c)
    for (double x : a)
      if (!std::isfinite(x)) return false;
  return true;
}

double ScalarField::max_abs() const {
  double m = 0.0;
  for (double x : v) m = std::max(m, std::abs(x));
  return m;
}

}  // namespace swim::full3d
