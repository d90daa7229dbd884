#include "full3d/wall_stabilizer.hpp"

#include <cmath>
#include <complex>
#include <stdexcept>

#include "common/errors.hpp"
#include "full3d/fft.hpp"
#include "full3d/packed_cholesky.hpp"

extern "C" {
// LAPACK, Fortran interface (the hidden length of the one-character UPLO argument last)
void dpbtrf_(const char* uplo, const int* n, const int* kd, double* ab, const int* ldab, int* info,
             std::size_t uplo_len);
void dpbtrs_(const char* uplo, const int* n, const int* kd, const int* nrhs, const double* ab, const int* ldab,
             double* b, const int* ldb, int* info, std::size_t uplo_len);
}

namespace swim::full3d {

namespace {
/// Factorisations kept (one per step size; the adaptive ladder visits a few dozen at most).
constexpr std::size_t kCacheSize = 64;
/// Half-width of the band of the stiffness S^T Lt S.
constexpr int kBand = 3;
/// The filter's power q: P = (I + Lg / (q l_h))^q, the half-width of its band.
constexpr int kFilter = 8;
/// Lower band storage (LAPACK's): column j holds A(j + d, j) in row d.
using Band = Eigen::MatrixXd;
double band_at(const Band& a, int i, int j) {
  if (i < j) std::swap(i, j);
  const int d = i - j;
  return d < a.rows() && i < a.cols() ? a(d, j) : 0.0;
}
/// The symmetric product a b of two commuting symmetric band matrices (powers of one matrix).
Band band_product(const Band& a, const Band& b) {
  const int n = int(a.cols()), p = int(a.rows()) - 1, q = int(b.rows()) - 1, w = p + q;
  Band c = Band::Zero(w + 1, n);
  for (int j = 0; j < n; ++j)
    for (int d = 0; d <= w && j + d < n; ++d) {
      const int i = j + d;
      double s = 0.0;
      for (int k = std::max(0, i - p); k <= std::min(n - 1, i + p); ++k) s += band_at(a, i, k) * band_at(b, k, j);
      c(d, j) = s;
    }
  return c;
}
/// y = a x for a symmetric band matrix a and the columns of x.
void band_multiply(const Band& a, const Eigen::MatrixXd& x, Eigen::MatrixXd& y) {
  const int n = int(a.cols()), w = int(a.rows()) - 1;
  y.setZero(x.rows(), x.cols());
  for (int j = 0; j < n; ++j) {
    y.row(j) += a(0, j) * x.row(j);
    for (int d = 1; d <= w && j + d < n; ++d) {
      y.row(j + d) += a(d, j) * x.row(j);
      y.row(j) += a(d, j) * x.row(j + d);
    }
  }
}
void cholesky(Band& a) {
  const int n = int(a.cols()), kd = int(a.rows()) - 1, ld = int(a.rows());
  int info = 0;
  dpbtrf_("L", &n, &kd, a.data(), &ld, &info, 1);
  if (info != 0) throw LapackError("dpbtrf", info);
}
void cholesky_solve(const Band& l, Eigen::MatrixXd& b) {
  const int n = int(l.cols()), kd = int(l.rows()) - 1, ld = int(l.rows()), nrhs = int(b.cols());
  int info = 0;
  dpbtrs_("L", &n, &kd, &nrhs, l.data(), &ld, b.data(), &n, &info, 1);
  if (info != 0) throw LapackError("dpbtrs", info);
}
/// Right-hand sides per mode: three components, real and imaginary parts.
constexpr int kRhs = 6;
}  // namespace

WallStabilization wall_stabilization_from(const std::string& name) {
  if (name == "none") return WallStabilization::None;
  if (name == "bending") return WallStabilization::Bending;
  throw InputError("full3d.wall_stabilization", name, "one of none, bending");
}

std::string to_string(WallStabilization w) { return w == WallStabilization::Bending ? "bending" : "none"; }

/// The transforms' buffers and plans: node values in [component][ring][node] order and their
/// half spectra in [component][ring][mode].
struct WallStabilizer::Impl {
  FftwBuffer real, spec;
  FftwPlan forward, inverse;
  Eigen::VectorXcd twist;  ///< exp(-i m pi / n_theta): the odd rings' half-step offset
};

struct WallStabilizer::Factor {
  std::vector<Eigen::MatrixXd> band;  ///< per mode, the Cholesky factor of P_m + dt K_m
};

WallStabilizer::WallStabilizer(const CylinderMesh& mesh, double h, double mu, double D, WallStabilization kind,
                               double factor)
    : kind_(kind), n_theta_(mesh.n_theta), n_rings_(mesh.n_rings), impl_(std::make_unique<Impl>()) {
  if (kind == WallStabilization::None) throw std::invalid_argument("WallStabilizer: kind none has no operator");
  if (!(h > 0.0 && mu > 0.0 && factor > 0.0 && D >= 0.0))
    throw std::invalid_argument("WallStabilizer: h, mu and factor must be positive, D non-negative");
  if (n_theta_ < 3 || n_rings_ < 2 || mesh.nodes() != n_theta_ * n_rings_ || mesh.edges.empty())
    throw std::invalid_argument("WallStabilizer: the mesh is not a stack of rings");
  n_modes_ = n_theta_ / 2 + 1;
  const double area = mesh.node_area.mean();
  const double edge = mesh.rest_length.mean();
  const double lap = 2.0 / (3.0 * edge * edge);  // -laplacian ~ lap * Lg on a triangular lattice of edge a
  m0_ = factor * h / (4.0 * mu * area);
  kappa_b_ = area * lap * lap * D;
  l_h_ = 1.5 * (edge / h) * (edge / h);
  const double scale = m0_ * kappa_b_ / l_h_;
  // per mode, Lg_m (tridiagonal), the filter P_m and the stiffness K_m
  stiff_.resize(std::size_t(n_modes_));
  filter_.resize(std::size_t(n_modes_));
  filter_chol_.resize(std::size_t(n_modes_));
  const int n = n_rings_;
  const double c = 1.0 / (kFilter * l_h_);
  for (int m = 0; m < n_modes_; ++m) {
    Band L = Band::Zero(2, n);
    for (int r = 0; r < n; ++r) L(0, r) = (r == 0 || r == n - 1 ? 4.0 : 6.0) - 2.0 * std::cos(2.0 * M_PI * m / n_theta_);
    for (int r = 0; r + 1 < n; ++r) L(1, r) = -2.0 * std::cos(M_PI * m / n_theta_);
    // K_m = S^T Lt S: S the interior rings' rows of Lg_m (every column), Lt its interior block
    // (rings 1 .. n - 2): Lg_m^3 inside, and a field linear along the axis has S f = 0 (the
    // free ends: no second difference, no bending)
    auto interior = [&](int p) { return p >= 1 && p <= n - 2; };
    Band k3 = Band::Zero(kBand + 1, n);
    for (int j = 0; j < n; ++j)
      for (int d = 0; d <= kBand && j + d < n; ++d) {
        const int i = j + d;
        double sum = 0.0;
        for (int p = i - 1; p <= i + 1; ++p)
          for (int q = j - 1; q <= j + 1; ++q)
            if (interior(p) && interior(q)) sum += band_at(L, p, i) * band_at(L, p, q) * band_at(L, q, j);
        k3(d, j) = scale * sum;
      }
    stiff_[std::size_t(m)] = std::move(k3);
    // P_m = (I + c Lg_m)^q
    Band one = c * L;
    one.row(0).array() += 1.0;
    Band P = one;
    for (int k = 1; k < kFilter; ++k) P = band_product(P, one);
    filter_[std::size_t(m)] = P;
    cholesky(P);
    filter_chol_[std::size_t(m)] = std::move(P);
  }
  // batched real transforms of length n_theta: 3 n_rings sequences
  Impl& t = *impl_;
  t.real = FftwBuffer(std::size_t(3 * n_rings_ * n_theta_));
  t.spec = FftwBuffer(std::size_t(2 * 3 * n_rings_ * n_modes_));
  FftOptions o;
  o.rigor = PlanRigor::Estimate;
  o.allow_buffering = true;
  t.forward = plan_many_r2c_1d(n_theta_, 3 * n_rings_, t.real.data(), 1, n_theta_, t.spec.complex(), 1, n_modes_, o);
  t.inverse = plan_many_c2r_1d(n_theta_, 3 * n_rings_, t.spec.complex(), 1, n_modes_, t.real.data(), 1, n_theta_, o);
  t.twist.resize(n_modes_);
  for (int m = 0; m < n_modes_; ++m) t.twist[m] = std::polar(1.0, -M_PI * m / n_theta_);
}

WallStabilizer::~WallStabilizer() = default;

const WallStabilizer::Factor& WallStabilizer::factor(double dt) const {
  if (auto it = cache_.find(dt); it != cache_.end()) return *it->second;
  auto f = std::make_shared<Factor>();
  f->band.resize(filter_.size());
  for (std::size_t m = 0; m < filter_.size(); ++m) {
    Band a = filter_[m];
    a.topRows(kBand + 1) += dt * stiff_[m];
    cholesky(a);
    f->band[m] = std::move(a);
  }
  if (cache_.size() >= kCacheSize) cache_.erase(cache_.begin());
  ++factorizations_;
  return *cache_.emplace(dt, std::move(f)).first->second;
}

template <class F>
void WallStabilizer::in_modes(Eigen::Matrix3Xd& x, F&& per_mode) const {
  Impl& t = *impl_;
  const int nr = n_rings_, nt = n_theta_, nm = n_modes_;
  double* re = t.real.data();
  for (int r = 0; r < nr; ++r)
    for (int i = 0; i < nt; ++i)
      for (int c = 0; c < 3; ++c) re[(c * nr + r) * nt + i] = x(c, r * nt + i);
  t.forward.execute();
  auto* z = reinterpret_cast<std::complex<double>*>(t.spec.complex());
  Eigen::MatrixXd rhs(nr, kRhs);
  for (int m = 0; m < nm; ++m) {
    const std::complex<double> tw = t.twist[m];
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < nr; ++r) {
        std::complex<double> v = z[(c * nr + r) * nm + m];
        if (r % 2) v *= tw;  // the coefficient of exp(i m phi) at the odd rings' own angles
        rhs(r, 2 * c) = v.real();
        rhs(r, 2 * c + 1) = v.imag();
      }
    per_mode(m, rhs);
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < nr; ++r) {
        std::complex<double> v(rhs(r, 2 * c), rhs(r, 2 * c + 1));
        if (r % 2) v *= std::conj(tw);
        z[(c * nr + r) * nm + m] = v;
      }
  }
  t.inverse.execute();
  const double inv = 1.0 / nt;
  for (int r = 0; r < nr; ++r)
    for (int i = 0; i < nt; ++i)
      for (int c = 0; c < 3; ++c) x(c, r * nt + i) = re[(c * nr + r) * nt + i] * inv;
}

void WallStabilizer::apply(double dt, Eigen::Matrix3Xd& dX) const {
  if (!(dt > 0.0)) throw std::invalid_argument("WallStabilizer::apply: dt must be positive");
  if (dX.cols() != n_theta_ * n_rings_) throw std::invalid_argument("WallStabilizer::apply: wrong number of nodes");
  const Factor& f = factor(dt);
  Eigen::MatrixXd y;
  in_modes(dX, [&](int m, Eigen::MatrixXd& b) {  // (P + dt K) y = P b
    band_multiply(filter_[std::size_t(m)], b, y);
    cholesky_solve(f.band[std::size_t(m)], y);
    b = y;
  });
}

Eigen::Matrix3Xd WallStabilizer::rate(const Eigen::Matrix3Xd& x) const {
  if (x.cols() != n_theta_ * n_rings_) throw std::invalid_argument("WallStabilizer::rate: wrong number of nodes");
  Eigen::Matrix3Xd out = x;
  Eigen::MatrixXd y;
  in_modes(out, [&](int m, Eigen::MatrixXd& b) {  // P^{-1} K b
    band_multiply(stiff_[std::size_t(m)], b, y);
    cholesky_solve(filter_chol_[std::size_t(m)], y);
    b = y;
  });
  return out;
}

}  // namespace swim::full3d
