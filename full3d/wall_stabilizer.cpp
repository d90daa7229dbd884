#include "full3d/wall_stabilizer.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#include "common/errors.hpp"
#include "full3d/fft.hpp"
#include "full3d/parallel.hpp"

namespace swim::full3d {

namespace {
/// The filter's power q: P = (I + Lf / (q l_h))^q.
constexpr int kFilter = 8;
/// Right-hand sides per mode: three components, real and imaginary parts.
constexpr int kRhs = 6;
/// Eigen-decomposition of a symmetric matrix (its symmetric part), eigenvalues clamped at 0
/// (the operators are positive semi-definite; round-off leaves tiny negative values).
void symmetric_eigen(const Eigen::MatrixXd& a, Eigen::MatrixXd& vectors, Eigen::VectorXd& values) {
  const Eigen::MatrixXd sym = 0.5 * (a + a.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(sym);
  if (es.info() != Eigen::Success) throw std::runtime_error("WallStabilizer: eigen-decomposition failed");
  vectors = es.eigenvectors();
  values = es.eigenvalues().cwiseMax(0.0);
}
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

WallStabilizer::WallStabilizer(const CylinderMesh& mesh, double h, double mu, double D, WallStabilization kind,
                               double factor, int threads)
    : kind_(kind), threads_(std::max(1, threads)), n_theta_(mesh.n_theta), n_rings_(mesh.n_rings),
      impl_(std::make_unique<Impl>()) {
  if (kind == WallStabilization::None) throw std::invalid_argument("WallStabilizer: kind none has no operator");
  if (!(h > 0.0 && mu > 0.0 && factor > 0.0 && D >= 0.0))
    throw std::invalid_argument("WallStabilizer: h, mu and factor must be positive, D non-negative");
  if (n_theta_ < 3 || n_rings_ < 3 || mesh.nodes() != n_theta_ * n_rings_ || mesh.edges.empty())
    throw std::invalid_argument("WallStabilizer: the mesh is not a stack of rings");
  n_modes_ = n_theta_ / 2 + 1;
  const double area = mesh.node_area.mean();
  const double edge = mesh.rest_length.mean();
  const double lap = 2.0 / (3.0 * edge * edge);  // -laplacian ~ lap * Lg on a triangular lattice of edge a
  m0_ = factor * h / (4.0 * mu * area);
  kappa_b_ = area * lap * lap * D;
  l_h_ = 1.5 * (edge / h) * (edge / h);
  const double scale = m0_ * kappa_b_ / l_h_;
  const int n = n_rings_;
  const double c = 1.0 / (kFilter * l_h_);
  vectors_.resize(std::size_t(n_modes_));
  rates_.resize(std::size_t(n_modes_));
  parallel_blocks(n_modes_, threads, [&](long begin, long end, int) {
    for (long m = begin; m < end; ++m) {
      // Lg_m (tridiagonal), S its rows of the rings off the ends (1 .. n - 2), Lt their block
      Eigen::MatrixXd L = Eigen::MatrixXd::Zero(n, n);
      for (int r = 0; r < n; ++r) L(r, r) = (r == 0 || r == n - 1 ? 4.0 : 6.0) - 2.0 * std::cos(2.0 * M_PI * m / n_theta_);
      for (int r = 0; r + 1 < n; ++r) L(r, r + 1) = L(r + 1, r) = -2.0 * std::cos(M_PI * m / n_theta_);
      const Eigen::MatrixXd S = L.middleRows(1, n - 2);
      Eigen::MatrixXd K = S.transpose() * (L.block(1, 1, n - 2, n - 2) * S);
      Eigen::MatrixXd S2 = S.transpose() * S;
      // the end rings' own bending along them, E = (3/2) R (R the ring's second difference,
      // in Lg's units): the free rims' modes that S does not see (its null space holds, per
      // mode m > 0, a pair decaying from each end), zero on a field constant on the ring
      const double e = 1.5 * (2.0 - 2.0 * std::cos(2.0 * M_PI * m / n_theta_));
      for (int r : {0, n - 1}) {
        K(r, r) += e * e * e;
        S2(r, r) += e * e;
      }
      K *= scale;
      // the filter's Laplacian Lf = (S^T S + E^T E)^{1/2}: Lg in the interior, zero on a field linear
      // along the axis; P^{-1/2} = (I + Lf / (q l_h))^{-q/2}
      Eigen::MatrixXd W;
      Eigen::VectorXd s2;
      symmetric_eigen(S2, W, s2);
      const Eigen::VectorXd g = (1.0 + c * s2.cwiseSqrt().array()).pow(-0.5 * kFilter).matrix();
      const Eigen::MatrixXd Ph = W * g.asDiagonal() * W.transpose();
      // B_m = P^{-1/2} K P^{-1/2} = U diag(sigma) U^T
      symmetric_eigen(Ph * K * Ph, vectors_[std::size_t(m)], rates_[std::size_t(m)]);
    }
  });
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

double WallStabilizer::largest_rate() const {
  double r = 0.0;
  for (const auto& v : rates_) r = std::max(r, v.maxCoeff());
  return r;
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
  // the modes are independent (each writes its own column of the spectra): blocks of modes
  // over the threads, the same operations in the same order whatever their number
  parallel_blocks(nm, threads_, [&](long m_begin, long m_end, int) {
    Eigen::MatrixXd rhs(nr, kRhs);
    for (long m = m_begin; m < m_end; ++m) {
      const std::complex<double> tw = t.twist[m];
      for (int c = 0; c < 3; ++c)
        for (int r = 0; r < nr; ++r) {
          std::complex<double> v = z[(c * nr + r) * nm + m];
          if (r % 2) v *= tw;  // the coefficient of exp(i m phi) at the odd rings' own angles
          rhs(r, 2 * c) = v.real();
          rhs(r, 2 * c + 1) = v.imag();
        }
      per_mode(int(m), rhs);
      for (int c = 0; c < 3; ++c)
        for (int r = 0; r < nr; ++r) {
          std::complex<double> v(rhs(r, 2 * c), rhs(r, 2 * c + 1));
          if (r % 2) v *= std::conj(tw);
          z[(c * nr + r) * nm + m] = v;
        }
    }
  });
  t.inverse.execute();
  const double inv = 1.0 / nt;
  for (int r = 0; r < nr; ++r)
    for (int i = 0; i < nt; ++i)
      for (int c = 0; c < 3; ++c) x(c, r * nt + i) = re[(c * nr + r) * nt + i] * inv;
}

template <class G>
void WallStabilizer::spectral(Eigen::Matrix3Xd& x, G&& gain) const {
  if (x.cols() != n_theta_ * n_rings_) throw std::invalid_argument("WallStabilizer: wrong number of nodes");
  in_modes(x, [&](int m, Eigen::MatrixXd& b) {  // U diag(gain(sigma)) U^T b
    const Eigen::MatrixXd& U = vectors_[std::size_t(m)];
    const Eigen::VectorXd& sigma = rates_[std::size_t(m)];
    Eigen::MatrixXd y = U.transpose() * b;
    for (Eigen::Index i = 0; i < y.rows(); ++i) y.row(i) *= gain(sigma[i]);
    b.noalias() = U * y;
  });
}

void WallStabilizer::apply_root(double dt, Eigen::Matrix3Xd& x) const {
  if (!(dt > 0.0)) throw std::invalid_argument("WallStabilizer::apply_root: dt must be positive");
  spectral(x, [dt](double sigma) { return 1.0 / std::sqrt(1.0 + dt * sigma); });
}

void WallStabilizer::apply(double dt, Eigen::Matrix3Xd& x) const {
  if (!(dt > 0.0)) throw std::invalid_argument("WallStabilizer::apply: dt must be positive");
  spectral(x, [dt](double sigma) { return 1.0 / (1.0 + dt * sigma); });
}

Eigen::Matrix3Xd WallStabilizer::rate(const Eigen::Matrix3Xd& x) const {
  Eigen::Matrix3Xd out = x;
  spectral(out, [](double sigma) { return sigma; });
  return out;
}

}  // namespace swim::full3d
