// Fork-join loops of the 3D tier on an OpenMP team (libgomp keeps the team alive between
// regions, so a region costs microseconds). Every loop is statically scheduled: for a given
// thread count, the split of the index range -- and therefore the order of every
// floating-point reduction done through per-thread buffers -- is fixed, so runs (and
// resumed runs) with the same thread count are reproducible.
//
// The thread count is always passed explicitly (the scene's `full3d.threads`); nothing
// here touches the global OpenMP settings, so 1D screening threads are unaffected.
#pragma once

#include <algorithm>
#include <exception>
#include <mutex>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace swim::full3d {

/// Threads actually available for a requested count (>= 1).
inline int effective_threads(int requested) { return std::max(1, requested); }

/// Calls f(begin, end, t) once per thread t = 0..T-1 with the contiguous block [begin, end)
/// of 0..n-1 given to that thread (T = min(threads, n), blocks as equal as possible, in
/// order). The first exception thrown by any block is rethrown after the region.
template <class F>
void parallel_blocks(long n, int threads, F&& f) {
  const int T = static_cast<int>(std::max<long>(1, std::min<long>(effective_threads(threads), n)));
  if (T == 1) {
    if (n > 0) f(0L, n, 0);
    return;
  }
  std::exception_ptr err;
  std::mutex err_mutex;
#ifdef _OPENMP
#pragma omp parallel num_threads(T)
  {
    const int t = omp_get_thread_num();
#else
  for (int t = 0; t < T; ++t) {
#endif
    const long begin = n * t / T, end = n * (t + 1) / T;
    try {
      f(begin, end, t);
    } catch (...) {
      std::lock_guard<std::mutex> lock(err_mutex);
      if (!err) err = std::current_exception();
    }
  }
  if (err) std::rethrow_exception(err);
}

/// Calls f(i) for i = 0..n-1, statically split into contiguous blocks over `threads`.
template <class F>
void parallel_for(long n, int threads, F&& f) {
  parallel_blocks(n, threads, [&](long b, long e, int) {
    for (long i = b; i < e; ++i) f(i);
  });
}

/// Number of blocks parallel_blocks(n, threads, ...) uses (size of per-thread buffers).
inline int block_count(long n, int threads) {
  return static_cast<int>(std::max<long>(1, std::min<long>(effective_threads(threads), n)));
}

}  // namespace swim::full3d
