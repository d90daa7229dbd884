// Helpers shared by the 3D tests: a loop over every MAC face of a grid, random node forces,
// and the largest difference between two face fields.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <random>

#include "full3d/grid.hpp"

namespace swim::full3d::testing {

/// One face of the MAC grid: component c, indices (i, j, k), storage index id, position x (m).
struct Face {
  int c, i, j, k;
  std::size_t id;
  std::array<double, 3> x;
};

/// Calls f(face) for every face of every component, x fastest.
template <class F>
void for_each_face(const MacGrid& g, F&& f) {
  for (int c = 0; c < 3; ++c) {
    const auto d = g.dims(c);
    for (int k = 0; k < d[2]; ++k)
      for (int j = 0; j < d[1]; ++j)
        for (int i = 0; i < d[0]; ++i) f(Face{c, i, j, k, MacGrid::index(d, i, j, k), g.position(c, i, j, k)});
  }
}

/// n node forces with components uniform in [-1, 1].
inline Eigen::Matrix3Xd random_forces(int n, std::mt19937& rng) {
  std::uniform_real_distribution<double> U(-1, 1);
  Eigen::Matrix3Xd F(3, n);
  for (int k = 0; k < n; ++k)
    for (int d = 0; d < 3; ++d) F(d, k) = U(rng);
  return F;
}

/// max over all faces of |a - b|.
inline double max_abs_diff(const VectorField& a, const VectorField& b) {
  double m = 0.0;
  for (int c = 0; c < 3; ++c)
    for (std::size_t i = 0; i < a.c[c].size(); ++i) m = std::max(m, std::abs(a.c[c][i] - b.c[c][i]));
  return m;
}

}  // namespace swim::full3d::testing
