// Dot product of two contiguous arrays in four interleaved partial sums: one chain of
// dependent additions would bound the loop by the addition's latency, and the compiler may
// not reorder floating-point sums itself. The order is fixed, so results are reproducible.
#pragma once

namespace swim {

inline double dot4(const double* a, const double* b, long n) {
  double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
  long i = 0;
  for (; i + 3 < n; i += 4) {
    s0 += a[i] * b[i];
    s1 += a[i + 1] * b[i + 1];
    s2 += a[i + 2] * b[i + 2];
    s3 += a[i + 3] * b[i + 3];
  }
  for (; i < n; ++i) s0 += a[i] * b[i];
  return (s0 + s1) + (s2 + s3);
}

}  // namespace swim
