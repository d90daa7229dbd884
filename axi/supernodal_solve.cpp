#include "axi/supernodal_solve.hpp"

#include <stdexcept>
#include <string>

namespace swim::axi {

void supernodal_llt_solve(const cholmod_factor& L, Eigen::VectorXd& x, Eigen::VectorXd& work, const int* perm) {
  if (!L.is_super || !L.is_ll || L.xtype != CHOLMOD_REAL || L.itype != CHOLMOD_INT || L.dtype != CHOLMOD_DOUBLE ||
      L.x == nullptr)
    throw std::invalid_argument("supernodal_llt_solve: the factor is not a numerical supernodal LL^T factor "
                                "with int indices and double values");
  const int n = int(L.n);
  if (x.size() != n)
    throw std::invalid_argument("supernodal_llt_solve: the right-hand side has " + std::to_string(x.size()) +
                                " entries, the factor " + std::to_string(n));
  const int nsuper = int(L.nsuper);
  const int* super = static_cast<const int*>(L.super);
  const int* lpi = static_cast<const int*>(L.pi);
  const int* lpx = static_cast<const int*>(L.px);
  const int* ls = static_cast<const int*>(L.s);
  if (perm == nullptr) perm = static_cast<const int*>(L.Perm);
  const double* lx = static_cast<const double*>(L.x);
  const int maxe = int(L.maxesize);
  if (work.size() < n + maxe) work.resize(n + maxe);
  double* y = work.data();
  double* e = work.data() + n;
  using Col = Eigen::Map<const Eigen::VectorXd>;
  using Vec = Eigen::Map<Eigen::VectorXd>;

  for (int k = 0; k < n; ++k) y[k] = x[perm ? perm[k] : k];

  // L w = y: per supernode, x1 <- L1^-1 x1 and the rows below less L2 x1, column by column
  for (int s = 0; s < nsuper; ++s) {
    const int k1 = super[s], nscol = super[s + 1] - k1;
    const int nsrow = lpi[s + 1] - lpi[s], nsrow2 = nsrow - nscol;
    const int* rows = ls + lpi[s] + nscol;
    const double* panel = lx + lpx[s];
    Vec below(e, nsrow2);
    below.setZero();
    for (int j = 0; j < nscol; ++j) {
      const double* col = panel + std::ptrdiff_t(j) * nsrow;
      const double yj = y[k1 + j] / col[j];
      y[k1 + j] = yj;
      const int rest = nscol - j - 1;
      if (rest > 0) Vec(y + k1 + j + 1, rest) -= yj * Col(col + j + 1, rest);
      if (nsrow2 > 0) below -= yj * Col(col + nscol, nsrow2);
    }
    for (int i = 0; i < nsrow2; ++i) y[rows[i]] += e[i];
  }

  // L^T v = w: per supernode from the last, x1 <- L1^-T (x1 - L2^T x(rows below))
  for (int s = nsuper - 1; s >= 0; --s) {
    const int k1 = super[s], nscol = super[s + 1] - k1;
    const int nsrow = lpi[s + 1] - lpi[s], nsrow2 = nsrow - nscol;
    const int* rows = ls + lpi[s] + nscol;
    const double* panel = lx + lpx[s];
    for (int i = 0; i < nsrow2; ++i) e[i] = y[rows[i]];
    const Col below(e, nsrow2);
    for (int j = nscol - 1; j >= 0; --j) {
      const double* col = panel + std::ptrdiff_t(j) * nsrow;
      double v = y[k1 + j];
      const int rest = nscol - j - 1;
      if (rest > 0) v -= Col(col + j + 1, rest).dot(Col(y + k1 + j + 1, rest));
      if (nsrow2 > 0) v -= Col(col + nscol, nsrow2).dot(below);
      y[k1 + j] = v / col[j];
    }
  }

  for (int k = 0; k < n; ++k) x[perm ? perm[k] : k] = y[k];
}

}  // namespace swim::axi
