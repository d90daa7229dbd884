// Serial kernels installed on the SUNDIALS objects of the reduced 1D tier (sun::make_vector,
// sun::make_band_matrix), compiled with the project's optimisation flags.
#include "reduced1d/serial_kernels.hpp"

#include <sunmatrix/sunmatrix_band.h>

#include <cmath>
#include <cstring>

#include "common/dot.hpp"
#include "reduced1d/v4.hpp"

namespace swim::reduced1d::sun {

namespace fast {
using v4::V4;
using v4::load4;
using v4::store4;
using v4::hsum;
inline double* d(N_Vector v) { return NV_DATA_S(v); }
inline sunindextype len(N_Vector v) { return NV_LENGTH_S(v); }
void linearsum(double a, N_Vector x, double b, N_Vector y, N_Vector z) {
  const double *X = d(x), *Y = d(y);
  double* Z = d(z);
  const sunindextype n = len(x);
  for (sunindextype i = 0; i < n; ++i) Z[i] = a * X[i] + b * Y[i];
}
void constant(double c, N_Vector z) {
  double* Z = d(z);
  const sunindextype n = len(z);
  for (sunindextype i = 0; i < n; ++i) Z[i] = c;
}
void prod(N_Vector x, N_Vector y, N_Vector z) {
  const double *X = d(x), *Y = d(y);
  double* Z = d(z);
  for (sunindextype i = 0, n = len(x); i < n; ++i) Z[i] = X[i] * Y[i];
}
void div(N_Vector x, N_Vector y, N_Vector z) {
  const double *X = d(x), *Y = d(y);
  double* Z = d(z);
  for (sunindextype i = 0, n = len(x); i < n; ++i) Z[i] = X[i] / Y[i];
}
void scale(double c, N_Vector x, N_Vector z) {
  const double* X = d(x);
  double* Z = d(z);
  for (sunindextype i = 0, n = len(x); i < n; ++i) Z[i] = c * X[i];
}
void abs(N_Vector x, N_Vector z) {
  const double* X = d(x);
  double* Z = d(z);
  for (sunindextype i = 0, n = len(x); i < n; ++i) Z[i] = std::abs(X[i]);
}
void inv(N_Vector x, N_Vector z) {
  const double* X = d(x);
  double* Z = d(z);
  for (sunindextype i = 0, n = len(x); i < n; ++i) Z[i] = 1.0 / X[i];
}
void addconst(N_Vector x, double b, N_Vector z) {
  const double* X = d(x);
  double* Z = d(z);
  for (sunindextype i = 0, n = len(x); i < n; ++i) Z[i] = X[i] + b;
}
double dotprod(N_Vector x, N_Vector y) {
  const double *X = d(x), *Y = d(y);
  double s = 0;
  for (sunindextype i = 0, n = len(x); i < n; ++i) s += X[i] * Y[i];
  return s;
}
double maxnorm(N_Vector x) {
  const double* X = d(x);
  double m = 0;
  for (sunindextype i = 0, n = len(x); i < n; ++i) m = std::max(m, std::abs(X[i]));
  return m;
}
// The weighted sums of squares (IDA and CVODE take several norms per step: the error test,
// the Newton corrections) in two 4-wide partial sums: a single running sum is a chain of
// dependent additions, four cycles each. The order is fixed, so results are reproducible.
double wsqrsum(N_Vector x, N_Vector w) {
  const double *X = d(x), *W = d(w);
  const sunindextype n = len(x);
  V4 s0{}, s1{};
  sunindextype i = 0;
  for (; i + 8 <= n; i += 8) {
    const V4 p0 = load4(X + i) * load4(W + i), p1 = load4(X + i + 4) * load4(W + i + 4);
    s0 += p0 * p0;
    s1 += p1 * p1;
  }
  double s = hsum(s0 + s1);
  for (; i < n; ++i) {
    const double p = X[i] * W[i];
    s += p * p;
  }
  return s;
}
double wrmsnorm(N_Vector x, N_Vector w) { return std::sqrt(wsqrsum(x, w) / double(len(x))); }
double wsqrsummask(N_Vector x, N_Vector w, N_Vector id) {
  const double *X = d(x), *W = d(w), *I = d(id);
  const sunindextype n = len(x);
  V4 s0{}, s1{};
  sunindextype i = 0;
  for (; i + 8 <= n; i += 8) {  // masked entries select 0 (not a product: they may be infinite)
    V4 p0 = load4(X + i) * load4(W + i), p1 = load4(X + i + 4) * load4(W + i + 4);
    p0 = load4(I + i) > 0.0 ? p0 : V4{};
    p1 = load4(I + i + 4) > 0.0 ? p1 : V4{};
    s0 += p0 * p0;
    s1 += p1 * p1;
  }
  double s = hsum(s0 + s1);
  for (; i < n; ++i)
    if (I[i] > 0.0) {
      const double p = X[i] * W[i];
      s += p * p;
    }
  return s;
}
double wrmsnormmask(N_Vector x, N_Vector w, N_Vector id) {
  return std::sqrt(wsqrsummask(x, w, id) / double(len(x)));
}
double minval(N_Vector x) {
  const double* X = d(x);
  double m = X[0];
  for (sunindextype i = 1, n = len(x); i < n; ++i) m = std::min(m, X[i]);
  return m;
}
int linearcombination(int nv, double* c, N_Vector* X, N_Vector z) {
  double* Z = d(z);
  const sunindextype n = len(z);
  if (nv == 1) {
    scale(c[0], X[0], z);
    return 0;
  }
  // One pass over the vectors with the sum in registers (z may be X[0]: each entry is read
  // before it is written), the terms added in the order of the vectors as the
  // reference kernel does; IDA's predictor and interpolation combine up to 6 vectors.
  constexpr int kMax = 8;
  if (nv > kMax) {
    const double* X0 = d(X[0]);
    const double* X1 = d(X[1]);
    for (sunindextype i = 0; i < n; ++i) Z[i] = c[0] * X0[i] + c[1] * X1[i];
    for (int k = 2; k < nv; ++k) {
      const double* Xk = d(X[k]);
      const double ck = c[k];
      for (sunindextype i = 0; i < n; ++i) Z[i] += ck * Xk[i];
    }
    return 0;
  }
  const double* P[kMax];
  for (int k = 0; k < nv; ++k) P[k] = d(X[k]);
  sunindextype i = 0;
  for (; i + 4 <= n; i += 4) {
    V4 zi = c[0] * load4(P[0] + i) + c[1] * load4(P[1] + i);
    for (int k = 2; k < nv; ++k) zi += c[k] * load4(P[k] + i);
    store4(Z + i, zi);
  }
  for (; i < n; ++i) {
    double zi = c[0] * P[0][i] + c[1] * P[1][i];
    for (int k = 2; k < nv; ++k) zi += c[k] * P[k][i];
    Z[i] = zi;
  }
  return 0;
}
int scaleaddmulti(int nv, double* a, N_Vector x, N_Vector* Y, N_Vector* Z) {
  const double* X = d(x);
  const sunindextype n = len(x);
  for (int k = 0; k < nv; ++k) {
    const double* Yk = d(Y[k]);
    double* Zk = d(Z[k]);
    const double ak = a[k];
    for (sunindextype i = 0; i < n; ++i) Zk[i] = ak * X[i] + Yk[i];
  }
  return 0;
}
int dotprodmulti(int nv, N_Vector x, N_Vector* Y, double* out) {
  for (int k = 0; k < nv; ++k) out[k] = dotprod(x, Y[k]);
  return 0;
}
// SUNMatZero for a band matrix (the integrators zero it before every Jacobian fill): one
// memset of its storage instead of the element loop.
int band_zero(SUNMatrix A) {
  std::memset(SM_DATA_B(A), 0, sizeof(realtype) * std::size_t(SM_LDATA_B(A)));
  return SUNMAT_SUCCESS;
}
}  // namespace fast

void install_vector_kernels(N_Vector v) {
  N_Vector_Ops o = v->ops;  // clones copy this table
  o->nvlinearsum = fast::linearsum;
  o->nvconst = fast::constant;
  o->nvprod = fast::prod;
  o->nvdiv = fast::div;
  o->nvscale = fast::scale;
  o->nvabs = fast::abs;
  o->nvinv = fast::inv;
  o->nvaddconst = fast::addconst;
  o->nvdotprod = fast::dotprod;
  o->nvdotprodlocal = fast::dotprod;
  o->nvmaxnorm = fast::maxnorm;
  o->nvmaxnormlocal = fast::maxnorm;
  o->nvwrmsnorm = fast::wrmsnorm;
  o->nvwrmsnormmask = fast::wrmsnormmask;
  o->nvwsqrsumlocal = fast::wsqrsum;
  o->nvwsqrsummasklocal = fast::wsqrsummask;
  o->nvmin = fast::minval;
  o->nvminlocal = fast::minval;
  o->nvlinearcombination = fast::linearcombination;
  o->nvscaleaddmulti = fast::scaleaddmulti;
  o->nvdotprodmulti = fast::dotprodmulti;
}

void install_band_kernels(SUNMatrix A) { A->ops->zero = fast::band_zero; }

}  // namespace swim::reduced1d::sun
