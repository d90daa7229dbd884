// Four doubles as one AVX register (GCC/Clang vector extension), for the 1D tier's block
// kernels (linear_solvers.cpp), vector kernels (serial_kernels.cpp) and residual rows
// (force_model.cpp): left to itself the compiler fully unrolls their 4- to 16-element loops
// into scalar operations. Loads and stores go through memcpy (no alignment or aliasing
// assumptions); a - f * b contracts to a fused multiply-add as scalar code does.
#pragma once

#include <cstring>

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

}  // namespace swim::reduced1d::v4
