#include "full3d/reference/duct_fft.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "common/errors.hpp"
#include "full3d/operators.hpp"

namespace swim::full3d::reference {

namespace {

constexpr double kPi = std::numbers::pi;

// Boundary treatment of one array direction, and the r2r kinds that diagonalise
// the 3-point second difference under it.
enum class Bc { Periodic, DirichletCentred, DirichletFace, NeumannCentred };

struct DirSpec {
  int n = 0;          // transformed length
  int first = 0;      // first stored index transformed (1 skips a wall face)
  fftw_r2r_kind fwd{}, bwd{};
  double logical = 1; // FFTW logical size N
  std::vector<double> lambda;  // eigenvalues of -(second difference), 1/m^2
};

DirSpec make_dir(Bc bc, int ncells, double h) {
  DirSpec s;
  const double c = 4.0 / (h * h);
  switch (bc) {
    case Bc::Periodic:
      s.n = ncells; s.fwd = FFTW_R2HC; s.bwd = FFTW_HC2R; s.logical = ncells;
      for (int m = 0; m < s.n; ++m) s.lambda.push_back(c * std::pow(std::sin(kPi * m / ncells), 2));
      break;
    case Bc::DirichletCentred:
      s.n = ncells; s.fwd = FFTW_RODFT10; s.bwd = FFTW_RODFT01; s.logical = 2.0 * ncells;
      for (int m = 0; m < s.n; ++m) s.lambda.push_back(c * std::pow(std::sin(kPi * (m + 1) / (2.0 * ncells)), 2));
      break;
    case Bc::DirichletFace:
      s.n = ncells - 1; s.first = 1; s.fwd = FFTW_RODFT00; s.bwd = FFTW_RODFT00; s.logical = 2.0 * ncells;
      for (int m = 0; m < s.n; ++m) s.lambda.push_back(c * std::pow(std::sin(kPi * (m + 1) / (2.0 * ncells)), 2));
      break;
    case Bc::NeumannCentred:
      s.n = ncells; s.fwd = FFTW_REDFT10; s.bwd = FFTW_REDFT01; s.logical = 2.0 * ncells;
      for (int m = 0; m < s.n; ++m) s.lambda.push_back(c * std::pow(std::sin(kPi * m / (2.0 * ncells)), 2));
      break;
  }
  return s;
}

// Solves (alpha + beta * Lambda) x = r for one staggered array (Lambda = -L with
// its boundary conditions) by forward r2r transform, diagonal scaling, inverse.
// Modes with alpha + beta*Lambda == 0 (the pressure constant) are set to zero.
class DiagonalSolver {
 public:
  DiagonalSolver(std::array<int, 3> array_dims, std::array<DirSpec, 3> dirs, const FftOptions& opt)
      : dims_(array_dims), dirs_(std::move(dirs)),
        buf_(std::size_t(dirs_[0].n) * dirs_[1].n * dirs_[2].n) {
    const std::array<int, 3> nzyx = {dirs_[2].n, dirs_[1].n, dirs_[0].n};
    fwd_ = plan_r2r_3d(nzyx, buf_.data(), buf_.data(), {dirs_[2].fwd, dirs_[1].fwd, dirs_[0].fwd}, opt);
    bwd_ = plan_r2r_3d(nzyx, buf_.data(), buf_.data(), {dirs_[2].bwd, dirs_[1].bwd, dirs_[0].bwd}, opt);
    norm_ = dirs_[0].logical * dirs_[1].logical * dirs_[2].logical;
  }

  void solve(const std::vector<double>& r, std::vector<double>& x, double alpha, double beta) {
    const int n0 = dirs_[0].n, n1 = dirs_[1].n, n2 = dirs_[2].n;
    const int f1 = dirs_[1].first, f2 = dirs_[2].first;  // x is periodic: no skipped face
    const double* in = r.data();
    double* b = buf_.data();
    for (int k = 0; k < n2; ++k)
      for (int j = 0; j < n1; ++j)
        std::copy_n(in + MacGrid::index(dims_, 0, j + f1, k + f2), n0, b + (std::size_t(k) * n1 + j) * n0);
    fwd_.execute();
    const std::vector<double>& inv = inverse_denominators(alpha, beta);
    const std::size_t nn = inv.size();
    for (std::size_t m = 0; m < nn; ++m) b[m] *= inv[m];
    bwd_.execute();
    if (x.size() != r.size()) x.assign(r.size(), 0.0);
    double* out = x.data();
    if (f1 || f2) std::fill(x.begin(), x.end(), 0.0);  // wall faces
    for (int k = 0; k < n2; ++k)
      for (int j = 0; j < n1; ++j)
        std::copy_n(b + (std::size_t(k) * n1 + j) * n0, n0, out + MacGrid::index(dims_, 0, j + f1, k + f2));
  }

 private:
  // 1 / ((alpha + beta Lambda) N) per mode (0 for a zero denominator); two (alpha, beta)
  // pairs are cached (the midpoint IB scheme alternates dt/2 and dt).
  const std::vector<double>& inverse_denominators(double alpha, double beta) {
    for (auto& c : cache_)
      if (!c.inv.empty() && c.alpha == alpha && c.beta == beta) return c.inv;
    Cached& c = cache_[next_];
    next_ = 1 - next_;
    const int n0 = dirs_[0].n, n1 = dirs_[1].n, n2 = dirs_[2].n;
    c.alpha = alpha;
    c.beta = beta;
    c.inv.resize(std::size_t(n0) * n1 * n2);
    for (int k = 0; k < n2; ++k)
      for (int j = 0; j < n1; ++j) {
        const double lzy = dirs_[2].lambda[k] + dirs_[1].lambda[j];
        for (int i = 0; i < n0; ++i) {
          const double den = (alpha + beta * (lzy + dirs_[0].lambda[i])) * norm_;
          c.inv[(std::size_t(k) * n1 + j) * n0 + i] = den != 0.0 ? 1.0 / den : 0.0;
        }
      }
    return c.inv;
  }
  struct Cached {
    double alpha = 0, beta = 0;
    std::vector<double> inv;
  };
  std::array<Cached, 2> cache_;
  int next_ = 0;

  std::array<int, 3> dims_;
  std::array<DirSpec, 3> dirs_;
  FftwBuffer buf_;
  FftwPlan fwd_, bwd_;
  double norm_ = 1.0;
};

void require_duct(const MacGrid& g, const char* what) {
  if (g.boundary() != GridBoundary::SquareDuct)
    throw InputError("container", to_string(g.boundary()), std::string(what) + " needs a square_duct grid");
}

}  // namespace

struct DuctFft::Impl {
  MacGrid grid;
  std::vector<DiagonalSolver> helmholtz;  // one per velocity component
  std::unique_ptr<DiagonalSolver> poisson;
  double lambda_min = 0.0;
  ScalarField div, phi;
  VectorField gphi;

  Impl(const MacGrid& g, const FftOptions& fft) : grid(g), div(g), phi(g), gphi(g) {
    require_duct(g, "the duct transforms (reference::DuctFft)");
    const int nx = g.nx(), ny = g.ny(), nz = g.nz();
    const double h = g.h();
    helmholtz.reserve(3);
    for (int c = 0; c < 3; ++c)
      helmholtz.emplace_back(g.dims(c),
                             std::array<DirSpec, 3>{make_dir(Bc::Periodic, nx, h),
                                                    make_dir(c == 1 ? Bc::DirichletFace : Bc::DirichletCentred, ny, h),
                                                    make_dir(c == 2 ? Bc::DirichletFace : Bc::DirichletCentred, nz, h)},
                             fft);
    poisson = std::make_unique<DiagonalSolver>(
        g.dims(3),
        std::array<DirSpec, 3>{make_dir(Bc::Periodic, nx, h), make_dir(Bc::NeumannCentred, ny, h),
                               make_dir(Bc::NeumannCentred, nz, h)},
        fft);
    const double c4 = 4.0 / (h * h);
    lambda_min = std::min(c4 * std::pow(std::sin(kPi / (2.0 * ny)), 2), c4 * std::pow(std::sin(kPi / (2.0 * nz)), 2));
    if (nx > 1) lambda_min = std::min(lambda_min, c4 * std::pow(std::sin(kPi / nx), 2));
  }
};

DuctFft::DuctFft(const MacGrid& g, const FftOptions& fft) : impl_(std::make_unique<Impl>(g, fft)) {}
DuctFft::~DuctFft() = default;
DuctFft::DuctFft(DuctFft&&) noexcept = default;
DuctFft& DuctFft::operator=(DuctFft&&) noexcept = default;

void DuctFft::helmholtz(const VectorField& r, VectorField& x, double alpha, double mu) {
  for (int c = 0; c < 3; ++c) impl_->helmholtz[c].solve(r.c[c], x.c[c], alpha, mu);
}

void DuctFft::poisson(const ScalarField& r, ScalarField& x) { impl_->poisson->solve(r.v, x.v, 0.0, 1.0); }

const ScalarField& DuctFft::project(VectorField& u) {
  Impl& m = *impl_;
  divergence(m.grid, u, m.div);
  poisson(m.div, m.phi);  // (-DG)^{-1} Du
  for (double& x : m.phi.v) x = -x;
  gradient(m.grid, m.phi, m.gphi);
  u.axpy(-1.0, m.gphi);
  zero_wall_faces(m.grid, u);
  return m.phi;
}

double DuctFft::lambda_min() const { return impl_->lambda_min; }

PressureCorrectionStep::PressureCorrectionStep(const MacGrid& g, const FluidParams& fluid, const FftOptions& fft)
    : grid_(g), fluid_(fluid), fft_(g, fft), p_(g), div_(g),
      b_(g), gp_(g) {
  if (!(fluid.rho > 0.0) || !(fluid.mu > 0.0))
    throw InputError("fluid", std::to_string(fluid.rho) + " kg/m^3, " + std::to_string(fluid.mu) + " Pa s",
                     "a positive density and dynamic viscosity");
}

StokesStats PressureCorrectionStep::step(VectorField& u, const VectorField& f, double dt) {
  if (!(dt > 0.0) || !std::isfinite(dt)) throw InputError("dt", std::to_string(dt), "a positive time step in s");
  const double alpha = fluid_.rho / dt;
  gradient(grid_, p_, gp_);
  for (int c = 0; c < 3; ++c)
    for (std::size_t m = 0; m < b_.c[c].size(); ++m) b_.c[c][m] = alpha * u.c[c][m] + f.c[c][m] - gp_.c[c][m];
  zero_wall_faces(grid_, b_);
  fft_.helmholtz(b_, u, alpha, fluid_.mu);
  const ScalarField& phi = fft_.project(u);
  for (std::size_t m = 0; m < p_.v.size(); ++m) p_.v[m] += alpha * phi.v[m];
  StokesStats st;
  divergence(grid_, u, div_);
  st.max_divergence = div_.max_abs();
  return st;
}

}  // namespace swim::full3d::reference
