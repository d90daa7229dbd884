#include "full3d/stokes.hpp"

#include <cmath>
#include <complex>
#include <numbers>
#include <string>
#include <vector>

#include "common/errors.hpp"
#include "full3d/operators.hpp"

namespace swim::full3d {

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
    const int f0 = dirs_[0].first, f1 = dirs_[1].first, f2 = dirs_[2].first;
    for (int k = 0; k < n2; ++k)
      for (int j = 0; j < n1; ++j)
        for (int i = 0; i < n0; ++i)
          buf_[(std::size_t(k) * n1 + j) * n0 + i] = r[MacGrid::index(dims_, i + f0, j + f1, k + f2)];
    fwd_.execute();
    for (int k = 0; k < n2; ++k)
      for (int j = 0; j < n1; ++j) {
        const double lzy = dirs_[2].lambda[k] + dirs_[1].lambda[j];
        for (int i = 0; i < n0; ++i) {
          const double den = (alpha + beta * (lzy + dirs_[0].lambda[i])) * norm_;
          double& b = buf_[(std::size_t(k) * n1 + j) * n0 + i];
          b = den != 0.0 ? b / den : 0.0;
        }
      }
    bwd_.execute();
    x.assign(r.size(), 0.0);
    for (int k = 0; k < n2; ++k)
      for (int j = 0; j < n1; ++j)
        for (int i = 0; i < n0; ++i)
          x[MacGrid::index(dims_, i + f0, j + f1, k + f2)] = buf_[(std::size_t(k) * n1 + j) * n0 + i];
  }

 private:
  std::array<int, 3> dims_;
  std::array<DirSpec, 3> dirs_;
  FftwBuffer buf_;
  FftwPlan fwd_, bwd_;
  double norm_ = 1.0;
};

double dot(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
  return s;
}

void remove_mean(std::vector<double>& a) {
  double s = 0.0;
  for (double x : a) s += x;
  s /= double(a.size());
  for (double& x : a) x -= s;
}

}  // namespace

struct StokesSolver::Impl {
  MacGrid grid;
  FluidParams fluid;
  StokesOptions opt;
  ScalarField p;

  // Periodic box
  std::array<FftwBuffer, 3> real;
  std::array<FftwBuffer, 3> spec;
  FftwBuffer pspec;
  FftwPlan r2c, c2r;

  // Square duct
  std::vector<DiagonalSolver> helmholtz;  // one per velocity component
  std::unique_ptr<DiagonalSolver> poisson;

  Impl(const MacGrid& g, const FluidParams& f, const StokesOptions& o) : grid(g), fluid(f), opt(o), p(g) {
    if (!(f.rho > 0.0)) throw InputError("fluid.rho", std::to_string(f.rho), "a positive density in kg/m^3");
    if (!(f.mu > 0.0)) throw InputError("fluid.mu", std::to_string(f.mu), "a positive dynamic viscosity in Pa s");
    const int nx = g.nx(), ny = g.ny(), nz = g.nz();
    if (g.kind() == ContainerKind::PeriodicBox) {
      const std::size_t nc = std::size_t(nz) * ny * (nx / 2 + 1);
      for (int c = 0; c < 3; ++c) {
        real[c] = FftwBuffer(g.cells());
        spec[c] = FftwBuffer(2 * nc);
      }
      pspec = FftwBuffer(2 * nc);
      r2c = plan_r2c_3d({nz, ny, nx}, real[0].data(), spec[0].complex(), o.fft);
      c2r = plan_c2r_3d({nz, ny, nx}, spec[0].complex(), real[0].data(), o.fft);
    } else {
      const double h = g.h();
      for (int c = 0; c < 3; ++c) {
        std::array<DirSpec, 3> d = {make_dir(Bc::Periodic, nx, h),
                                    make_dir(c == 1 ? Bc::DirichletFace : Bc::DirichletCentred, ny, h),
                                    make_dir(c == 2 ? Bc::DirichletFace : Bc::DirichletCentred, nz, h)};
        if (helmholtz.empty()) helmholtz.reserve(3);
        helmholtz.emplace_back(g.dims(c), std::move(d), o.fft);
      }
      poisson = std::make_unique<DiagonalSolver>(
          g.dims(3),
          std::array<DirSpec, 3>{make_dir(Bc::Periodic, nx, h), make_dir(Bc::NeumannCentred, ny, h),
                                 make_dir(Bc::NeumannCentred, nz, h)},
          o.fft);
    }
  }

  // ---- periodic box: exact Fourier projection --------------------------------
  StokesStats box_step(VectorField& u, const VectorField& f, double dt) {
    const int nx = grid.nx(), ny = grid.ny(), nz = grid.nz();
    const double h = grid.h();
    const double alpha = fluid.rho / dt;
    const std::size_t n = grid.cells();
    for (int c = 0; c < 3; ++c) {
      for (std::size_t m = 0; m < n; ++m) real[c][m] = alpha * u.c[c][m] + f.c[c][m];
      r2c.execute_r2c(real[c].data(), spec[c].complex());
    }
    const int nxh = nx / 2 + 1;
    using cd = std::complex<double>;
    std::vector<cd> gx(nxh), gy(ny), gz(nz);
    auto symbol = [h](int k, int nn) { return (1.0 - std::polar(1.0, -2.0 * kPi * k / nn)) / h; };
    for (int i = 0; i < nxh; ++i) gx[i] = symbol(i, nx);
    for (int j = 0; j < ny; ++j) gy[j] = symbol(j, ny);
    for (int k = 0; k < nz; ++k) gz[k] = symbol(k, nz);
    const double inv_n = 1.0 / double(n);
    cd* s0 = reinterpret_cast<cd*>(spec[0].complex());
    cd* s1 = reinterpret_cast<cd*>(spec[1].complex());
    cd* s2 = reinterpret_cast<cd*>(spec[2].complex());
    cd* sp = reinterpret_cast<cd*>(pspec.complex());
    for (int k = 0; k < nz; ++k)
      for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nxh; ++i) {
          const std::size_t m = (std::size_t(k) * ny + j) * nxh + i;
          const cd g[3] = {gx[i], gy[j], gz[k]};
          const double k2 = std::norm(g[0]) + std::norm(g[1]) + std::norm(g[2]);
          const cd b[3] = {s0[m], s1[m], s2[m]};
          cd ph = 0.0;
          if (k2 > 0.0) ph = (std::conj(g[0]) * b[0] + std::conj(g[1]) * b[1] + std::conj(g[2]) * b[2]) / k2;
          const double inv_beta = inv_n / (alpha + fluid.mu * k2);
          s0[m] = (b[0] - g[0] * ph) * inv_beta;
          s1[m] = (b[1] - g[1] * ph) * inv_beta;
          s2[m] = (b[2] - g[2] * ph) * inv_beta;
          sp[m] = ph * inv_n;
        }
    for (int c = 0; c < 3; ++c) {
      c2r.execute_c2r(spec[c].complex(), real[c].data());
      for (std::size_t m = 0; m < n; ++m) u.c[c][m] = real[c][m];
    }
    c2r.execute_c2r(pspec.complex(), real[0].data());
    for (std::size_t m = 0; m < n; ++m) p.v[m] = real[0][m];
    StokesStats st;
    ScalarField div(grid);
    divergence(grid, u, div);
    st.max_divergence = div.max_abs();
    return st;
  }

  // ---- square duct -------------------------------------------------------------
  void apply_Ainv(const VectorField& r, VectorField& x, double alpha) {
    for (int c = 0; c < 3; ++c) helmholtz[c].solve(r.c[c], x.c[c], alpha, fluid.mu);
  }
  // S q = -D A^{-1} G q
  void apply_S(const ScalarField& q, ScalarField& out, double alpha, VectorField& w1, VectorField& w2) {
    gradient(grid, q, w1);
    apply_Ainv(w1, w2, alpha);
    divergence(grid, w2, out);
    for (double& x : out.v) x = -x;
  }
  // M^{-1} r = mu r + alpha (-DG)^{-1} r
  void apply_M(const ScalarField& r, ScalarField& z, double alpha) {
    poisson->solve(r.v, z.v, 0.0, 1.0);
    for (std::size_t m = 0; m < z.v.size(); ++m) z.v[m] = alpha * z.v[m] + fluid.mu * r.v[m];
    remove_mean(z.v);
  }
  // Makes u exactly discrete-divergence-free: u -= G phi with D G phi = D u. Returns phi.
  void project(VectorField& u, ScalarField& phi, VectorField& w) {
    ScalarField div(grid);
    divergence(grid, u, div);
    poisson->solve(div.v, phi.v, 0.0, 1.0);  // phi = (-DG)^{-1} div
    for (double& x : phi.v) x = -x;
    gradient(grid, phi, w);
    u.axpy(-1.0, w);
  }

  VectorField rhs(const VectorField& u, const VectorField& f, double alpha) {
    VectorField b(grid);
    for (int c = 0; c < 3; ++c)
      for (std::size_t m = 0; m < b.c[c].size(); ++m) b.c[c][m] = alpha * u.c[c][m] + f.c[c][m];
    zero_wall_faces(grid, b);
    return b;
  }

  StokesStats duct_step(VectorField& u, const VectorField& f, double dt) {
    const double alpha = fluid.rho / dt;
    const VectorField b = rhs(u, f, alpha);
    VectorField w1(grid), w2(grid);
    StokesStats st;
    // rhs of the Schur system: -D A^{-1} b
    ScalarField g(grid);
    apply_Ainv(b, w1, alpha);
    divergence(grid, w1, g);
    for (double& x : g.v) x = -x;
    const double gnorm = std::sqrt(dot(g.v, g.v));
    ScalarField r(grid), z(grid), d(grid), Sd(grid);
    remove_mean(p.v);
    apply_S(p, Sd, alpha, w1, w2);
    for (std::size_t m = 0; m < r.v.size(); ++m) r.v[m] = g.v[m] - Sd.v[m];
    double rnorm = std::sqrt(dot(r.v, r.v));
    const double ref = gnorm > 0.0 ? gnorm : 1.0;
    if (gnorm == 0.0 && rnorm == 0.0) {
      std::fill(p.v.begin(), p.v.end(), 0.0);
    } else {
      apply_M(r, z, alpha);
      d = z;
      double rz = dot(r.v, z.v);
      int it = 0;
      while (rnorm > opt.cg_rtol * ref) {
        if (it >= opt.cg_max_iterations)
          throw NumericalError("Stokes pressure PCG did not converge in " + std::to_string(it) +
                                   " iterations (relative residual " + std::to_string(rnorm / ref) + ")",
                               "raise stokes.cg_max_iterations or loosen stokes.cg_rtol");
        apply_S(d, Sd, alpha, w1, w2);
        const double a = rz / dot(d.v, Sd.v);
        for (std::size_t m = 0; m < r.v.size(); ++m) {
          p.v[m] += a * d.v[m];
          r.v[m] -= a * Sd.v[m];
        }
        rnorm = std::sqrt(dot(r.v, r.v));
        apply_M(r, z, alpha);
        const double rz_new = dot(r.v, z.v);
        const double beta = rz_new / rz;
        rz = rz_new;
        for (std::size_t m = 0; m < d.v.size(); ++m) d.v[m] = z.v[m] + beta * d.v[m];
        ++it;
      }
      st.iterations = it;
    }
    st.relative_residual = rnorm / ref;
    // velocity from the converged pressure, then the exact final projection
    gradient(grid, p, w1);
    for (int c = 0; c < 3; ++c)
      for (std::size_t m = 0; m < w1.c[c].size(); ++m) w1.c[c][m] = b.c[c][m] - w1.c[c][m];
    apply_Ainv(w1, u, alpha);
    ScalarField phi(grid);
    project(u, phi, w1);
    zero_wall_faces(grid, u);
    ScalarField div(grid);
    divergence(grid, u, div);
    st.max_divergence = div.max_abs();
    return st;
  }

  StokesStats duct_bare(VectorField& u, const VectorField& f, double dt) {
    const double alpha = fluid.rho / dt;
    VectorField b = rhs(u, f, alpha);
    VectorField w(grid);
    gradient(grid, p, w);
    b.axpy(-1.0, w);
    apply_Ainv(b, u, alpha);
    ScalarField phi(grid);
    project(u, phi, w);
    zero_wall_faces(grid, u);
    for (std::size_t m = 0; m < p.v.size(); ++m) p.v[m] += alpha * phi.v[m];
    StokesStats st;
    ScalarField div(grid);
    divergence(grid, u, div);
    st.max_divergence = div.max_abs();
    return st;
  }
};

StokesSolver::StokesSolver(const MacGrid& grid, const FluidParams& fluid, const StokesOptions& opt)
    : impl_(std::make_unique<Impl>(grid, fluid, opt)) {}
StokesSolver::~StokesSolver() = default;
StokesSolver::StokesSolver(StokesSolver&&) noexcept = default;
StokesSolver& StokesSolver::operator=(StokesSolver&&) noexcept = default;

namespace {
void check_dt(double dt) {
  if (!(dt > 0.0) || !std::isfinite(dt)) throw InputError("dt", std::to_string(dt), "a positive time step in s");
}
}  // namespace

StokesStats StokesSolver::step(VectorField& u, const VectorField& f, double dt) {
  check_dt(dt);
  return impl_->grid.kind() == ContainerKind::PeriodicBox ? impl_->box_step(u, f, dt) : impl_->duct_step(u, f, dt);
}

StokesStats StokesSolver::bare_fft_solve(VectorField& u, const VectorField& f, double dt) {
  check_dt(dt);
  return impl_->grid.kind() == ContainerKind::PeriodicBox ? impl_->box_step(u, f, dt) : impl_->duct_bare(u, f, dt);
}

const ScalarField& StokesSolver::pressure() const { return impl_->p; }
const MacGrid& StokesSolver::grid() const { return impl_->grid; }
const FluidParams& StokesSolver::fluid() const { return impl_->fluid; }

}  // namespace swim::full3d
