// RAII wrappers around FFTW3 (double precision).
//
//   FftwBuffer  fftw_malloc'ed, SIMD-aligned array of doubles (move-only).
//   FftwPlan    owns an fftw_plan; created once, executed many times, destroyed
//               with fftw_destroy_plan (move-only).
//
// Planning goes through the functions below, which serialise the (non
// thread-safe) FFTW planner behind one mutex and take the thread count
// explicitly. fftw_init_threads() is called once per process (std::call_once);
// that is FFTW's own global state, the only global touched here.
// FFTW computes unnormalised transforms; callers divide by the logical size N
// (product over dimensions: n for R2HC/HC2R and complex DFTs, 2n for
// REDFT10/01 and RODFT10/01, 2(n+1) for RODFT00 of n points).
#pragma once

#include <fftw3.h>

#include <array>
#include <cstddef>

namespace swim::full3d {

enum class PlanRigor { Estimate, Measure };

struct FftOptions {
  int threads = 1;                        ///< FFTW threads per plan (>= 1)
  PlanRigor rigor = PlanRigor::Estimate;  ///< FFTW_ESTIMATE or FFTW_MEASURE
  /// Estimate plans are made with FFTW_NO_BUFFERING unless this is set: some sizes (a large
  /// prime factor in a batched real transform) have no plan without buffering.
  bool allow_buffering = false;
};

class FftwBuffer {
 public:
  FftwBuffer() = default;
  explicit FftwBuffer(std::size_t n_doubles);
  ~FftwBuffer();
  FftwBuffer(FftwBuffer&& o) noexcept;
  FftwBuffer& operator=(FftwBuffer&& o) noexcept;
  FftwBuffer(const FftwBuffer&) = delete;
  FftwBuffer& operator=(const FftwBuffer&) = delete;

  double* data() { return p_; }
  const double* data() const { return p_; }
  fftw_complex* complex() { return reinterpret_cast<fftw_complex*>(p_); }
  std::size_t size() const { return n_; }
  double& operator[](std::size_t i) { return p_[i]; }
  double operator[](std::size_t i) const { return p_[i]; }

 private:
  double* p_ = nullptr;
  std::size_t n_ = 0;
};

class FftwPlan {
 public:
  FftwPlan() = default;
  /// Takes ownership; throws std::runtime_error if p is null (planning failed).
  explicit FftwPlan(fftw_plan p);
  ~FftwPlan();
  FftwPlan(FftwPlan&& o) noexcept;
  FftwPlan& operator=(FftwPlan&& o) noexcept;
  FftwPlan(const FftwPlan&) = delete;
  FftwPlan& operator=(const FftwPlan&) = delete;

  void execute() const { fftw_execute(p_); }
  /// New-array execution (arrays must be FftwBuffer-aligned, same layout as planned).
  void execute_r2c(double* in, fftw_complex* out) const { fftw_execute_dft_r2c(p_, in, out); }
  void execute_c2r(fftw_complex* in, double* out) const { fftw_execute_dft_c2r(p_, in, out); }
  void execute_r2r(double* in, double* out) const { fftw_execute_r2r(p_, in, out); }
  bool valid() const { return p_ != nullptr; }

 private:
  fftw_plan p_ = nullptr;
};

/// Initialises FFTW threads once per process; returns false if unavailable.
bool fftw_threads_init_once();

/// The smallest n >= min_n with n - min_n even whose prime factors are all <= 7. FFTW has
/// straight-line codelets for such sizes; a larger prime factor (34 = 2 x 17) takes its
/// generic O(p^2) algorithm, which also allocates scratch on every execution: a 34 x 34
/// DCT-II is about 2 x slower than a 36 x 36 one.
int fft_friendly_size(int min_n);

/// Plans on arrays of logical shape n = {n0, n1, n2}, n2 contiguous (C order).
FftwPlan plan_r2r_3d(std::array<int, 3> n, double* in, double* out, std::array<fftw_r2r_kind, 3> kinds,
                     const FftOptions& opt);
FftwPlan plan_r2c_3d(std::array<int, 3> n, double* in, fftw_complex* out, const FftOptions& opt);
FftwPlan plan_c2r_3d(std::array<int, 3> n, fftw_complex* in, double* out, const FftOptions& opt);
/// Batched 1D real transforms of length n (fftw_plan_many_dft_r2c / _c2r): `howmany`
/// sequences, element stride and distance between sequences given separately for
/// input and output (in units of the array element).
FftwPlan plan_many_r2c_1d(int n, int howmany, double* in, int istride, int idist, fftw_complex* out, int ostride,
                          int odist, const FftOptions& opt);
FftwPlan plan_many_c2r_1d(int n, int howmany, fftw_complex* in, int istride, int idist, double* out, int ostride,
                          int odist, const FftOptions& opt);
/// Advanced-interface real-to-real plan (fftw_plan_many_r2r): `howmany` rank-`rank`
/// transforms of logical sizes n[0..rank-1] (the last contiguous), kinds[d] along
/// dimension d, stored inside arrays of dimensions inembed / onembed (nullptr: n) with
/// element strides istride / ostride and distances idist / odist between transforms.
FftwPlan plan_many_r2r(int rank, const int* n, int howmany, double* in, const int* inembed, int istride, int idist,
                       double* out, const int* onembed, int ostride, int odist, const fftw_r2r_kind* kinds,
                       const FftOptions& opt);

}  // namespace swim::full3d
