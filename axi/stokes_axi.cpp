#include "axi/stokes_axi.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "common/errors.hpp"

extern "C" {
// LAPACK, Fortran interface (the hidden length of the one-character TRANS argument last)
void zgbtrf_(const int* m, const int* n, const int* kl, const int* ku, std::complex<double>* ab, const int* ldab,
             int* ipiv, int* info);
void zgbtrs_(const char* trans, const int* n, const int* kl, const int* ku, const int* nrhs,
             const std::complex<double>* ab, const int* ldab, const int* ipiv, std::complex<double>* b,
             const int* ldb, int* info, std::size_t trans_len);
}

namespace swim::axi {

namespace {

using cplx = std::complex<double>;

// Unknown / equation indices of radial index i: w_i (axial momentum of cell i), p_i
// (continuity of cell i), u_{i+1} (radial momentum of face i+1; the wall row for i = nr-1).
inline int iw(int i) { return 3 * i; }
inline int ip(int i) { return 3 * i + 1; }
inline int iu(int face) { return 3 * (face - 1) + 2; }  // face = 1..nr

// One mode's matrix in LAPACK band storage (column-major, leading dimension kLdab, the
// first kSub rows left for the fill-in of the factorisation).
class Band {
 public:
  Band(cplx* ab, int n) : ab_(ab), n_(n) {}
  void set(int row, int col, cplx v) {
    if (row < 0 || col < 0 || row >= n_ || col >= n_ || row - col > AxiStokes::kSub ||
        col - row > AxiStokes::kSuper)
      throw std::logic_error("AxiStokes: matrix entry outside the band");
    ab_[std::size_t(col) * AxiStokes::kLdab + AxiStokes::kSub + AxiStokes::kSuper + row - col] = v;
  }

 private:
  cplx* ab_;
  int n_;
};

// The scaled system of mode k (see the header): momentum rows times h^2/mu, continuity rows
// times h, pressure unknown P = p h / mu. Radius ratios are in cell units (r/h).
void assemble(Band& A, int nr, int nx, int k) {
  const double th = 2.0 * std::numbers::pi * double(k) / double(nx);
  const double s2 = 4.0 * std::sin(0.5 * th) * std::sin(0.5 * th);  // -(second difference)
  const cplx back = 1.0 - std::polar(1.0, -th);                     // a_j - a_{j-1}
  const cplx fwd = std::polar(1.0, th) - 1.0;                       // a_{j+1} - a_j
  for (int i = 0; i < nr; ++i) {
    const double rc = i + 0.5, rf0 = i, rf1 = i + 1.0;
    // axial momentum at cell i
    double diag = -(rf1 + rf0) / rc - s2;
    if (i > 0) A.set(iw(i), iw(i - 1), rf0 / rc);
    if (i + 1 < nr) A.set(iw(i), iw(i + 1), rf1 / rc);
    else diag -= rf1 / rc;  // ghost w_nr = -w_{nr-1}
    A.set(iw(i), iw(i), diag);
    A.set(iw(i), ip(i), -back);
    // continuity at cell i (the gauge row P_{nr-1} = 0 for k = 0)
    if (k == 0 && i == nr - 1) {
      A.set(ip(i), ip(i), 1.0);
    } else {
      A.set(ip(i), iw(i), fwd);
      if (i + 1 < nr) A.set(ip(i), iu(i + 1), rf1 / rc);
      if (i > 0) A.set(ip(i), iu(i), -rf0 / rc);
    }
    // radial momentum at face m = i+1 (identity row u_nr = 0 at the wall)
    const int m = i + 1;
    if (m == nr) {
      A.set(iu(m), iu(m), 1.0);
    } else {
      const double rm = m, lo = m - 0.5, hi = m + 0.5;
      A.set(iu(m), iu(m), -(hi + lo) / rm - 1.0 / (rm * rm) - s2);
      if (m + 1 < nr) A.set(iu(m), iu(m + 1), hi / rm);
      if (m - 1 > 0) A.set(iu(m), iu(m - 1), lo / rm);
      A.set(iu(m), ip(m), -1.0);
      A.set(iu(m), ip(m - 1), 1.0);
    }
  }
}

}  // namespace

AxiStokes::AxiStokes(const AxiGrid& g, double mu, const full3d::FftOptions& fft) : g_(g), mu_(mu) {
  if (g.nr < 2) throw std::invalid_argument("AxiStokes: nr must be >= 2, got " + std::to_string(g.nr));
  if (g.nx < 4 || g.nx % 2 != 0)
    throw std::invalid_argument("AxiStokes: nx must be even and >= 4, got " + std::to_string(g.nx));
  if (!(g.h > 0.0) || !std::isfinite(g.h)) throw std::invalid_argument("AxiStokes: the cell size h must be > 0");
  if (!(mu > 0.0) || !std::isfinite(mu)) throw std::invalid_argument("AxiStokes: the viscosity must be > 0");
  const int nr = g.nr, nx = g.nx;
  n_ = 3 * nr;
  nk_ = nx / 2 + 1;

  ab_.assign(std::size_t(nk_) * kLdab * n_, cplx(0.0));
  ipiv_.assign(std::size_t(nk_) * n_, 0);
  rhs_.assign(std::size_t(n_), cplx(0.0));
  for (int k = 0; k < nk_; ++k) {
    cplx* ab = ab_.data() + std::size_t(k) * kLdab * n_;
    Band A(ab, n_);
    assemble(A, nr, nx, k);
    int info = 0;
    const int kl = kSub, ku = kSuper, ld = kLdab;
    zgbtrf_(&n_, &n_, &kl, &ku, ab, &ld, ipiv_.data() + std::size_t(k) * n_, &info);
    if (info != 0)
      throw NumericalError("LAPACK zgbtrf failed (info = " + std::to_string(info) + ") on the axisymmetric Stokes "
                               "system of axial mode " + std::to_string(k) + " (nr = " + std::to_string(nr) +
                               ", nx = " + std::to_string(nx) + ")",
                           "this is a defect of the axisymmetric Stokes solver, not of the scene: report it with "
                           "the grid (axi.grid)");
  }

  // FFT workspace: rows w (nr), u faces 1..nr-1 (nr-1), p (nr).
  const int rows_f = 2 * nr - 1, rows_all = 3 * nr - 1;
  real_in_ = full3d::FftwBuffer(std::size_t(rows_f) * nx);
  real_out_ = full3d::FftwBuffer(std::size_t(rows_all) * nx);
  spec_ = full3d::FftwBuffer(std::size_t(rows_all) * nk_ * 2);
  forward_ = full3d::plan_many_r2c_1d(nx, rows_f, real_in_.data(), 1, nx, spec_.complex(), 1, nk_, fft);
  inverse_velocity_ =
      full3d::plan_many_c2r_1d(nx, rows_f, spec_.complex(), 1, nk_, real_out_.data(), 1, nx, fft);
  inverse_all_ = full3d::plan_many_c2r_1d(nx, rows_all, spec_.complex(), 1, nk_, real_out_.data(), 1, nx, fft);
}

std::size_t AxiStokes::factor_bytes() const {
  return ab_.size() * sizeof(cplx) + ipiv_.size() * sizeof(int);
}

void AxiStokes::solve(const double* fr, const double* fx, double* u, double* w, double* p) {
  const int nr = g_.nr, nx = g_.nx;
  const std::size_t row = std::size_t(nx);
  // forward transforms of fx (rows 0..nr-1) and fr (faces 1..nr-1)
  std::copy(fx, fx + std::size_t(nr) * row, real_in_.data());
  std::copy(fr + row, fr + std::size_t(nr) * row, real_in_.data() + std::size_t(nr) * row);
  forward_.execute();

  cplx* spec = reinterpret_cast<cplx*>(spec_.data());
  const std::size_t nk = std::size_t(nk_);
  cplx* sw = spec;                                 // w rows 0..nr-1
  cplx* su = spec + std::size_t(nr) * nk;          // u rows of faces 1..nr-1
  cplx* sp = spec + std::size_t(2 * nr - 1) * nk;  // p rows 0..nr-1
  const double scale = -g_.h * g_.h / mu_ / double(nx);  // momentum row scaling, FFT normalisation
  const double p_scale = mu_ / g_.h;
  const int kl = kSub, ku = kSuper, ld = kLdab, one = 1;
  for (int k = 0; k < nk_; ++k) {
    for (int i = 0; i < nr; ++i) {
      rhs_[iw(i)] = scale * sw[i * nk + k];
      rhs_[ip(i)] = 0.0;
      rhs_[iu(i + 1)] = i + 1 < nr ? scale * su[i * nk + k] : cplx(0.0);
    }
    int info = 0;
    zgbtrs_("N", &n_, &kl, &ku, &one, ab_.data() + std::size_t(k) * kLdab * n_, &ld,
            ipiv_.data() + std::size_t(k) * n_, rhs_.data(), &n_, &info, 1);
    if (info != 0)
      throw NumericalError("LAPACK zgbtrs failed (info = " + std::to_string(info) + ") in the axisymmetric Stokes "
                               "solve of axial mode " + std::to_string(k),
                           "this is a defect of the axisymmetric Stokes solver, not of the scene: report it");
    double pmean = 0.0;
    if (k == 0) {
      for (int i = 0; i < nr; ++i) pmean += rhs_[ip(i)].real();
      pmean /= nr;
    }
    for (int i = 0; i < nr; ++i) {
      sw[i * nk + k] = rhs_[iw(i)];
      sp[i * nk + k] = p_scale * (rhs_[ip(i)] - pmean);
      if (i + 1 < nr) su[i * nk + k] = rhs_[iu(i + 1)];
    }
  }

  if (p) inverse_all_.execute();
  else inverse_velocity_.execute();
  const double* out = real_out_.data();
  std::copy(out, out + std::size_t(nr) * row, w);
  std::fill(u, u + row, 0.0);
  std::copy(out + std::size_t(nr) * row, out + std::size_t(2 * nr - 1) * row, u + row);
  std::fill(u + std::size_t(nr) * row, u + std::size_t(nr + 1) * row, 0.0);
  if (p) std::copy(out + std::size_t(2 * nr - 1) * row, out + std::size_t(3 * nr - 1) * row, p);
}

void AxiStokes::solve(const std::vector<double>& fr, const std::vector<double>& fx, std::vector<double>& u,
                      std::vector<double>& w, std::vector<double>* p) {
  if (fr.size() != g_.u_size() || fx.size() != g_.w_size())
    throw std::invalid_argument("AxiStokes::solve: force arrays must have u_size() and w_size() values");
  u.resize(g_.u_size());
  w.resize(g_.w_size());
  if (p) p->resize(g_.p_size());
  solve(fr.data(), fx.data(), u.data(), w.data(), p ? p->data() : nullptr);
}

}  // namespace swim::axi
