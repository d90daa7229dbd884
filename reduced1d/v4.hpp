// Four doubles as one AVX register (GCC/Clang vector extension), for the 1D tier's block
// kernels (linear_solvers.cpp), vector kernels (serial_kernels.cpp) and residual rows
// (force_model.cpp): left to itself the compiler fully unrolls their 4- to 16-element loops
// into scalar operations. Loads and stores go through memcpy (no alignment or aliasing
// assumptions); a - f * b contracts to a fused multiply-add as scalar code does.
#pragma once

#include <cmath>
#include <cstring>

#if defined(__AVX2__) && defined(__FMA__) && defined(__GLIBC__)
// glibc's vector logarithm (libmvec, the AVX2 variant of the x86-64 vector ABI): four
// natural logarithms in one call, within 1 ulp of the scalar std::log (1e6 arguments in
// (0.2, 1), the confined closure's range) at a quarter of its time.
extern "C" __attribute__((const)) double __attribute__((vector_size(32))) _ZGVdN4v_log(
    double __attribute__((vector_size(32))));
#define SWIM_HAVE_VECTOR_LOG 1
#endif

namespace swim::reduced1d::v4 {

using V4 = double __attribute__((vector_size(32)));
inline V4 load4(const double* p) {
  V4 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline void store4(double* p, V4 v) { std::memcpy(p, &v, sizeof v); }
/// The sum of the four lanes, pairwise.
inline double hsum(V4 v) { return (v[0] + v[1]) + (v[2] + v[3]); }

/// y[i] = log(x[i]) for i < n, four at a time where the build has glibc's vector logarithm
/// (x and y may be the same array).
inline void log_n(const double* x, double* y, int n) {
  int i = 0;
#ifdef SWIM_HAVE_VECTOR_LOG
  for (; i + 4 <= n; i += 4) store4(y + i, _ZGVdN4v_log(load4(x + i)));
  if (i < n) {  // the tail through the same kernel, so that every value comes from one routine
    double t[4] = {1.0, 1.0, 1.0, 1.0};
    for (int k = i; k < n; ++k) t[k - i] = x[k];
    const V4 l = _ZGVdN4v_log(load4(t));
    for (int k = i; k < n; ++k) y[k] = l[k - i];
  }
#else
  for (; i < n; ++i) y[i] = std::log(x[i]);
#endif
}

}  // namespace swim::reduced1d::v4
