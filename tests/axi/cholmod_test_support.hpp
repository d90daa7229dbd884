// What the tests of the CHOLMOD factorisations and of the product's triangular solves share:
// CHOLMOD's supernodal Cholesky with its factor open, and a symmetric positive definite test
// matrix with the fitted Stokes system's kind of structure.
#pragma once

#include <Eigen/CholmodSupport>
#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <cmath>
#include <random>
#include <vector>

namespace swim::axi::testing {

/// CHOLMOD's supernodal LL^T (through Eigen), its factor open to the tests.
template <int UpLo>
class OpenFactor : public Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double, Eigen::ColMajor, int>, UpLo> {
 public:
  const cholmod_factor* factor() const { return this->m_cholmodFactor; }
};

/// Two unknowns per node of an ex-by-ey grid of 9-node (biquadratic) elements, every pair of
/// unknowns of an element coupled, the element blocks random positive semi-definite, plus a
/// positive diagonal. Its factor has supernodes from one column to dense separators of several
/// dozen.
inline Eigen::SparseMatrix<double, Eigen::ColMajor, int> spd_element_matrix(int ex, int ey, std::mt19937& rng) {
  const int nx = 2 * ex + 1, ny = 2 * ey + 1, n = 2 * nx * ny;
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < n; ++i) t.emplace_back(i, i, 1e-3 + 0.1 * std::abs(g(rng)));
  for (int a = 0; a < ex; ++a)
    for (int b = 0; b < ey; ++b) {
      std::vector<int> dof;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          for (int c = 0; c < 2; ++c) dof.push_back(2 * ((2 * a + i) * ny + 2 * b + j) + c);
      Eigen::MatrixXd G(18, 18);
      for (int i = 0; i < 18; ++i)
        for (int j = 0; j < 18; ++j) G(i, j) = g(rng);
      const Eigen::MatrixXd B = G.transpose() * G;
      for (int i = 0; i < 18; ++i)
        for (int j = 0; j < 18; ++j) t.emplace_back(dof[i], dof[j], B(i, j));
    }
  Eigen::SparseMatrix<double, Eigen::ColMajor, int> S(n, n);
  S.setFromTriplets(t.begin(), t.end());
  return S;
}

}  // namespace swim::axi::testing
