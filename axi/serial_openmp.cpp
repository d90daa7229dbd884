#include "axi/serial_openmp.hpp"

#include <dlfcn.h>

namespace swim::axi {

namespace {
thread_local int t_depth = 0;
thread_local long t_inline = 0;

using Region = void (*)(void*);
using Parallel = void (*)(Region, void*, unsigned, unsigned);

/// libgomp's own entry point (the next definition after this executable's).
Parallel libgomp_parallel() {
  static const Parallel p = reinterpret_cast<Parallel>(dlsym(RTLD_NEXT, "GOMP_parallel"));
  return p;
}
}  // namespace

SerialOpenMp::SerialOpenMp() { ++t_depth; }
SerialOpenMp::~SerialOpenMp() { --t_depth; }
long SerialOpenMp::inline_regions() { return t_inline; }

}  // namespace swim::axi

/// What GCC calls for `#pragma omp parallel` (libgomp's ABI, GOMP_4.0): inline under a
/// SerialOpenMp guard, libgomp's otherwise. Without libgomp in the process there is no team
/// to start, and the region runs inline as well.
extern "C" void GOMP_parallel(void (*fn)(void*), void* data, unsigned num_threads, unsigned flags) {
  using namespace swim::axi;
  if (t_depth == 0)
    if (const Parallel p = libgomp_parallel()) {
      p(fn, data, num_threads, flags);
      return;
    }
  ++t_inline;
  fn(data);
}
