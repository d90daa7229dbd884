// OpenMP regions run inline on the calling thread, for the sparse factorisations.
//
// CHOLMOD's supernodal factorisation (Debian's build) opens several OpenMP parallel regions
// per supernode, a few thousand supernodes per factorisation of the fitted Stokes system.
// The product calls it with no active parallel level, so every region is a team of one, but
// libgomp still allocates, clears and frees a team for each and wakes its barrier with a
// futex system call: about 34 000 system calls per factorisation at 24 cells across, and half
// of each factorisation's time (docs/performance.md, "OpenMP regions inline").
//
// While a SerialOpenMp guard lives on a thread, the OpenMP regions that thread starts run
// inline: the region's body is called once, outside any team, as the sequential program
// would run it (omp_get_num_threads() = 1, omp_get_thread_num() = 0 inside it; a loop split
// by those covers its whole range). The entry point libgomp gives compiled regions
// (GOMP_parallel) is defined by this library and forwards to libgomp's own everywhere else,
// so other threads and other regions are unchanged. Only what runs under a guard is affected,
// and it must be correct on one thread, as any OpenMP region must be (the runtime may always
// give a team of one); inside it omp_get_level() is 0, not 1.
#pragma once

namespace swim::axi {

/// Regions started on this thread while it lives run inline (nestable).
class SerialOpenMp {
 public:
  SerialOpenMp();
  ~SerialOpenMp();
  SerialOpenMp(const SerialOpenMp&) = delete;
  SerialOpenMp& operator=(const SerialOpenMp&) = delete;

  /// Regions run inline on this thread so far (all guards; for the tests: it stays 0 when the
  /// libraries' regions do not reach this library's entry point).
  static long inline_regions();
};

}  // namespace swim::axi
