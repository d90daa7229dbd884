#include "full3d/fft.hpp"

#include <fftw3.h>

#include <algorithm>
#include <mutex>
#include <stdexcept>
#include <utility>

namespace swim::full3d {

FftwBuffer::FftwBuffer(std::size_t n_doubles) : n_(n_doubles) {
  if (n_ > 0) {
    p_ = fftw_alloc_real(n_);
    if (!p_) throw std::bad_alloc();
    for (std::size_t i = 0; i < n_; ++i) p_[i] = 0.0;
  }
}
FftwBuffer::~FftwBuffer() {
  if (p_) fftw_free(p_);
}
FftwBuffer::FftwBuffer(FftwBuffer&& o) noexcept : p_(std::exchange(o.p_, nullptr)), n_(std::exchange(o.n_, 0)) {}
FftwBuffer& FftwBuffer::operator=(FftwBuffer&& o) noexcept {
  if (this != &o) {
    if (p_) fftw_free(p_);
    p_ = std::exchange(o.p_, nullptr);
    n_ = std::exchange(o.n_, 0);
  }
  return *this;
}

namespace {
std::mutex& planner_mutex() {
  static std::mutex m;  // FFTW's planner is not thread-safe
  return m;
}
// FFTW_NO_BUFFERING keeps the estimate planner off its buffered solvers, which allocate
// scratch on every execution (the odd-size RODFT00 rows of the cross sections: 38
// allocations per batched execution, 1.4 x slower).
unsigned flags_of(const FftOptions& opt) {
  return opt.rigor == PlanRigor::Measure ? FFTW_MEASURE
                                         : FFTW_ESTIMATE | (opt.allow_buffering ? 0u : unsigned(FFTW_NO_BUFFERING));
}
void set_threads_locked(const FftOptions& opt) {
  if (fftw_threads_init_once()) fftw_plan_with_nthreads(opt.threads > 0 ? opt.threads : 1);
}
}  // namespace

FftwPlan::FftwPlan(fftw_plan p) : p_(p) {
  if (!p_) throw std::runtime_error("FFTW planning failed");
}
FftwPlan::~FftwPlan() {
  if (p_) {
    std::lock_guard<std::mutex> lock(planner_mutex());
    fftw_destroy_plan(p_);
  }
}
FftwPlan::FftwPlan(FftwPlan&& o) noexcept : p_(std::exchange(o.p_, nullptr)) {}
FftwPlan& FftwPlan::operator=(FftwPlan&& o) noexcept {
  if (this != &o) {
    if (p_) {
      std::lock_guard<std::mutex> lock(planner_mutex());
      fftw_destroy_plan(p_);
    }
    p_ = std::exchange(o.p_, nullptr);
  }
  return *this;
}

bool fftw_threads_init_once() {
  static std::once_flag once;
  static bool ok = false;
  std::call_once(once, [] { ok = fftw_init_threads() != 0; });
  return ok;
}

FftwPlan plan_r2r_3d(std::array<int, 3> n, double* in, double* out, std::array<fftw_r2r_kind, 3> kinds,
                     const FftOptions& opt) {
  std::lock_guard<std::mutex> lock(planner_mutex());
  set_threads_locked(opt);
  return FftwPlan(fftw_plan_r2r_3d(n[0], n[1], n[2], in, out, kinds[0], kinds[1], kinds[2], flags_of(opt)));
}

FftwPlan plan_r2c_3d(std::array<int, 3> n, double* in, fftw_complex* out, const FftOptions& opt) {
  std::lock_guard<std::mutex> lock(planner_mutex());
  set_threads_locked(opt);
  return FftwPlan(fftw_plan_dft_r2c_3d(n[0], n[1], n[2], in, out, flags_of(opt)));
}

FftwPlan plan_c2r_3d(std::array<int, 3> n, fftw_complex* in, double* out, const FftOptions& opt) {
  std::lock_guard<std::mutex> lock(planner_mutex());
  set_threads_locked(opt);
  return FftwPlan(fftw_plan_dft_c2r_3d(n[0], n[1], n[2], in, out, flags_of(opt)));
}

FftwPlan plan_many_r2c_1d(int n, int howmany, double* in, int istride, int idist, fftw_complex* out, int ostride,
                          int odist, const FftOptions& opt) {
  std::lock_guard<std::mutex> lock(planner_mutex());
  set_threads_locked(opt);
  return FftwPlan(
      fftw_plan_many_dft_r2c(1, &n, howmany, in, nullptr, istride, idist, out, nullptr, ostride, odist, flags_of(opt)));
}

FftwPlan plan_many_c2r_1d(int n, int howmany, fftw_complex* in, int istride, int idist, double* out, int ostride,
                          int odist, const FftOptions& opt) {
  std::lock_guard<std::mutex> lock(planner_mutex());
  set_threads_locked(opt);
  return FftwPlan(
      fftw_plan_many_dft_c2r(1, &n, howmany, in, nullptr, istride, idist, out, nullptr, ostride, odist, flags_of(opt)));
}

FftwPlan plan_many_r2r(int rank, const int* n, int howmany, double* in, const int* inembed, int istride, int idist,
                       double* out, const int* onembed, int ostride, int odist, const fftw_r2r_kind* kinds,
                       const FftOptions& opt) {
  std::lock_guard<std::mutex> lock(planner_mutex());
  set_threads_locked(opt);
  return FftwPlan(fftw_plan_many_r2r(rank, n, howmany, in, inembed, istride, idist, out, onembed, ostride, odist,
                                     kinds, flags_of(opt)));
}

int fft_friendly_size(int min_n) {
  for (int n = std::max(min_n, 1);; n += 2) {
    int r = n;
    for (int q : {2, 3, 5, 7})
      while (r % q == 0) r /= q;
    if (r == 1) return n;
  }
}

}  // namespace swim::full3d
