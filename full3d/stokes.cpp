#include "full3d/stokes.hpp"

#include <cmath>
#include <algorithm>
#include <complex>
#include <limits>
#include <numbers>
#include <string>
#include <thread>
#include <vector>

#include "common/errors.hpp"
#include "full3d/capacitance_stokes.hpp"
#include "full3d/direct_stokes.hpp"
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
  double lambda_min = 0.0;  // smallest nonzero eigenvalue of -DG, 1/m^2
  // Cylinder (fictitious domain): constraint rows and multiplier (warm-started)
  std::unique_ptr<VelocityConstraints> con;
  std::vector<double> lam;
  // Direct per-mode solver; the multiplier is recovered lazily from (b, u, p, alpha) of the last step
  std::unique_ptr<DirectStokes> direct;
  // Exact capacitance (Woodbury) solver of the plain duct
  std::unique_ptr<CapacitanceStokes> capacitance;
  bool lam_stale = false;
  VectorField last_b, last_u;
  double last_alpha = 0.0;
  // scratch
  VectorField wb, w1, w2, uc;
  ScalarField rp, zp, dp, sdp, div, phi;
  std::vector<double> rl, zl, dl, sdl;

  Impl(const MacGrid& g, const FluidParams& f, const StokesOptions& o) : grid(g), fluid(f), opt(o), p(g) {
    if (!(f.rho > 0.0)) throw InputError("fluid.rho", std::to_string(f.rho), "a positive density in kg/m^3");
    if (!(f.mu > 0.0)) throw InputError("fluid.mu", std::to_string(f.mu), "a positive dynamic viscosity in Pa s");
    const int nx = g.nx(), ny = g.ny(), nz = g.nz();
    if (g.kind() == ContainerKind::PeriodicBox && o.cylinder.enabled)
      throw InputError("container", to_string(g.kind()), "the circular cylinder needs a square_duct grid");
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
      const double c4 = 4.0 / (h * h);
      lambda_min = std::min(c4 * std::pow(std::sin(kPi / (2.0 * ny)), 2), c4 * std::pow(std::sin(kPi / (2.0 * nz)), 2));
      if (nx > 1) lambda_min = std::min(lambda_min, c4 * std::pow(std::sin(kPi / nx), 2));
      for (auto* v : {&wb, &w1, &w2, &uc}) *v = VectorField(g);
      for (auto* v : {&rp, &zp, &dp, &sdp, &div, &phi}) *v = ScalarField(g);
      if (o.cylinder.enabled) {
        con = std::make_unique<VelocityConstraints>(g, o.cylinder);
        lam.assign(con->rows(), 0.0);
      }
      const bool direct_applies = !o.cylinder.enabled || o.cylinder.wall == CylinderWall::Staircase;
      if (o.method == StokesMethod::Direct && !direct_applies)
        throw InputError("full3d.cylinder_wall", "not staircase",
                         "the direct solver (StokesOptions::method = Direct) supports the plain duct and the "
                         "staircase cylinder wall only: use full3d.cylinder_wall = \"staircase\", or the Auto or "
                         "Iterative method");
      // the capacitance solver: plain duct, or the staircase cylinder at least half a cell
      // inside the duct walls (CapacitanceStokes::supports_cylinder)
      const bool capacitance_applies =
          !o.cylinder.enabled ||
          (o.cylinder.wall == CylinderWall::Staircase && CapacitanceStokes::supports_cylinder(g, o.cylinder));
      if (o.method == StokesMethod::Capacitance && !capacitance_applies)
        throw InputError("full3d.cylinder_wall", "not staircase",
                         "the capacitance solver (StokesOptions::method = Capacitance) supports the plain duct "
                         "and the staircase cylinder (radius <= duct half-width - h/2) only: use "
                         "full3d.cylinder_wall = \"staircase\", or the Auto, Direct or Iterative method");
      const CylinderOptions* cyl = o.cylinder.enabled ? &o.cylinder : nullptr;
      const double limit = o.direct_memory_limit_gib * 1024.0 * 1024.0 * 1024.0;
      const bool use_capacitance =
          o.method == StokesMethod::Capacitance ||
          (o.method == StokesMethod::Auto && capacitance_applies &&
           6.0 * double(CapacitanceStokes::estimate_bytes(g, cyl)) <= limit);
      const bool use_direct =
          o.method == StokesMethod::Direct ||
          (o.method == StokesMethod::Auto && !use_capacitance && o.cylinder.enabled && direct_applies &&
           2.0 * double(DirectStokes::estimate_bytes(g)) <= limit);
      if (use_capacitance) {
        const int thr = o.direct_threads > 0 ? o.direct_threads : std::max(1, o.fft.threads);
        capacitance = std::make_unique<CapacitanceStokes>(g, f.mu, cyl, thr, o.fft);
      }
      if (use_direct) {
        int thr = o.direct_threads;
        if (thr <= 0) thr = std::max(1, int(std::thread::hardware_concurrency()));
        direct = std::make_unique<DirectStokes>(g, f.mu, o.cylinder.enabled ? &o.cylinder : nullptr, thr, o.fft);
      }
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
    ScalarField dv(grid);
    divergence(grid, u, dv);
    st.max_divergence = dv.max_abs();
    return st;
  }

  // ---- square duct (and cylinder) ---------------------------------------------
  void apply_Ainv(const VectorField& r, VectorField& x, double alpha) {
    for (int c = 0; c < 3; ++c) helmholtz[c].solve(r.c[c], x.c[c], alpha, fluid.mu);
  }
  // Preconditioner: M^{-1} = blockdiag(mu I + alpha (-DG)^{-1}  [Cahouet-Chabard],  E A E^T).
  void apply_M(double alpha) {
    if (alpha > opt.cc_poisson_drop_ratio * fluid.mu * lambda_min) {
      poisson->solve(rp.v, zp.v, 0.0, 1.0);
      for (std::size_t m = 0; m < zp.v.size(); ++m) zp.v[m] = alpha * zp.v[m] + fluid.mu * rp.v[m];
    } else {  // quasi-steady: alpha (-DG)^{-1} is below the drop ratio times mu
      for (std::size_t m = 0; m < zp.v.size(); ++m) zp.v[m] = fluid.mu * rp.v[m];
    }
    remove_mean(zp.v);
    if (con) con->apply_local_helmholtz(rl, zl, alpha, fluid.mu);
  }
  // Makes u exactly discrete-divergence-free: u -= G phi with D G phi = D u.
  void project(VectorField& u) {
    divergence(grid, u, div);
    poisson->solve(div.v, phi.v, 0.0, 1.0);  // phi = (-DG)^{-1} div
    for (double& x : phi.v) x = -x;
    gradient(grid, phi, w1);
    u.axpy(-1.0, w1);
  }

  void rhs_into(VectorField& b, const VectorField& u, const VectorField& f, double alpha) {
    for (int c = 0; c < 3; ++c)
      for (std::size_t m = 0; m < b.c[c].size(); ++m) b.c[c][m] = alpha * u.c[c][m] + f.c[c][m];
    zero_wall_faces(grid, b);
  }
  static double norm2(const VectorField& v) {
    double s = 0.0;
    for (const auto& a : v.c) s += dot(a, a);
    return std::sqrt(s);
  }
  // residual of the constraints on uc: r = (G^T uc, E uc) = (-D uc, E uc)
  void constraint_residual(const VectorField& v, ScalarField& outp, std::vector<double>& outl) {
    divergence(grid, v, outp);
    for (double& x : outp.v) x = -x;
    if (con) con->gather(v, outl);
  }
  double scaled_norm() const {
    const double h = grid.h();
    return std::sqrt(h * h * dot(rp.v, rp.v) + (con ? dot(rl, rl) : 0.0));
  }

  // Solves A u + G p + E^T lam = b, D u = 0, E u = 0 (no E without the cylinder) by PCG
  // on the multipliers y = (p, lam): K^T A^{-1} K y = K^T A^{-1} b with K = [G, E^T].
  // The unprojected velocity uc = A^{-1}(b - K y) is updated alongside, so each
  // iteration costs one K, one A^{-1} (three transforms pairs) and one K^T.
  StokesStats duct_step(VectorField& u, const VectorField& f, double dt) {
    const double alpha = fluid.rho / dt;
    rhs_into(wb, u, f, alpha);
    StokesStats st;
    remove_mean(p.v);
    gradient(grid, p, w1);
    for (int c = 0; c < 3; ++c)
      for (std::size_t m = 0; m < w1.c[c].size(); ++m) w1.c[c][m] = wb.c[c][m] - w1.c[c][m];
    if (con) con->scatter_add(lam, -1.0, w1);
    apply_Ainv(w1, uc, alpha);
    constraint_residual(uc, rp, rl);
    const double ref0 = norm2(uc);
    double rnorm = scaled_norm();
    double ref = std::max(ref0, std::numeric_limits<double>::min());
    int it = 0;
    if (rnorm > opt.cg_rtol * ref) {
      apply_M(alpha);
      dp = zp;
      dl = zl;
      double rz = dot(rp.v, zp.v) + (con ? dot(rl, zl) : 0.0);
      while (true) {
        if (it >= opt.cg_max_iterations)
          throw NumericalError("Stokes multiplier PCG did not converge in " + std::to_string(it) +
                                   " iterations (relative residual " + std::to_string(rnorm / ref) + ")",
                               "raise StokesOptions::cg_max_iterations or loosen StokesOptions::cg_rtol (API), or use full3d.cylinder_wall = \"staircase\" (direct solvers)");
        gradient(grid, dp, w1);
        if (con) con->scatter_add(dl, 1.0, w1);
        apply_Ainv(w1, w2, alpha);
        constraint_residual(w2, sdp, sdl);
        const double dSd = dot(dp.v, sdp.v) + (con ? dot(dl, sdl) : 0.0);
        if (!(dSd > 0.0)) break;  // exact solution reached (or breakdown at round-off)
        const double a = rz / dSd;
        for (std::size_t m = 0; m < p.v.size(); ++m) {
          p.v[m] += a * dp.v[m];
          rp.v[m] -= a * sdp.v[m];
        }
        if (con)
          for (std::size_t m = 0; m < lam.size(); ++m) {
            lam[m] += a * dl[m];
            rl[m] -= a * sdl[m];
          }
        uc.axpy(-a, w2);
        ++it;
        rnorm = scaled_norm();
        ref = std::max(ref0, norm2(uc));
        if (rnorm <= opt.cg_rtol * ref) break;
        apply_M(alpha);
        const double rz_new = dot(rp.v, zp.v) + (con ? dot(rl, zl) : 0.0);
        const double beta = rz_new / rz;
        rz = rz_new;
        for (std::size_t m = 0; m < dp.v.size(); ++m) dp.v[m] = zp.v[m] + beta * dp.v[m];
        if (con)
          for (std::size_t m = 0; m < dl.size(); ++m) dl[m] = zl[m] + beta * dl[m];
      }
    }
    st.iterations = it;
    st.relative_residual = rnorm / ref;
    // velocity of the converged multipliers, then the exact final projection
    for (int c = 0; c < 3; ++c) u.c[c] = uc.c[c];
    project(u);
    zero_wall_faces(grid, u);
    divergence(grid, u, div);
    st.max_divergence = div.max_abs();
    if (con) {
      con->gather(u, rl);
      for (double x : rl) st.max_constraint = std::max(st.max_constraint, std::abs(x));
    }
    return st;
  }

  // Direct per-mode solve (direct_stokes.hpp): no iteration, E u = 0 exactly.
  StokesStats direct_step(VectorField& u, const VectorField& f, double dt) {
    const double alpha = fluid.rho / dt;
    rhs_into(wb, u, f, alpha);
    direct->solve(wb, u, p, alpha);
    StokesStats st;
    st.direct = true;
    if (direct->last_solve_factorized()) st.factorization_seconds = direct->last_factorization_seconds();
    zero_wall_faces(grid, u);
    if (con) {
      last_b = wb;
      last_alpha = alpha;
    }
    finish_exact_step(u, st);
    return st;
  }

  // Shared tail of the exact paths (Direct, Capacitance): the optional final projection, the
  // divergence statistic and, for the cylinder, the state of the lazily recovered multiplier.
  // Masked faces are eliminated unknowns, exactly zero unless the projection moved them.
  void finish_exact_step(VectorField& u, StokesStats& st) {
    if (opt.direct_final_projection) {
      project(u);
      zero_wall_faces(grid, u);
    }
    divergence(grid, u, div);
    st.max_divergence = div.max_abs();
    if (con) {
      if (opt.direct_final_projection) {
        con->gather(u, rl);
        for (double x : rl) st.max_constraint = std::max(st.max_constraint, std::abs(x));
      }
      last_u = u;
      lam_stale = true;
    }
  }

  // Capacitance (Woodbury) solve of the plain duct (capacitance_stokes.hpp): exact, no iteration.
  StokesStats capacitance_step(VectorField& u, const VectorField& f, double dt) {
    const double alpha = fluid.rho / dt;
    lam_stale = false;
    if (con) {
      // cylinder: keep b for the lazily recovered multiplier, as the Direct path does
      rhs_into(wb, u, f, alpha);
      capacitance->solve(wb, u, p, alpha);  // wall and masked faces come out exactly 0
      last_b = wb;
      last_alpha = alpha;
    } else {
      capacitance->step(u, f, p, alpha);  // b = alpha u^n + f formed inside; wall faces come out exactly 0
    }
    StokesStats st;
    st.direct = true;
    if (capacitance->last_solve_factorized()) st.factorization_seconds = capacitance->last_factorization_seconds();
    finish_exact_step(u, st);
    return st;
  }

  // lambda = E (b - A u - G p), A = alpha - mu L: the force the masked rows need.
  void refresh_multiplier() {
    if (!lam_stale) return;
    laplacian(grid, last_u, w1);
    gradient(grid, p, w2);
    for (int c = 0; c < 3; ++c)
      for (std::size_t m = 0; m < w1.c[c].size(); ++m)
        w1.c[c][m] = last_b.c[c][m] - last_alpha * last_u.c[c][m] + fluid.mu * w1.c[c][m] - w2.c[c][m];
    con->gather(w1, lam);
    lam_stale = false;
  }

  StokesStats duct_bare(VectorField& u, const VectorField& f, double dt) {
    const double alpha = fluid.rho / dt;
    lam_stale = false;
    rhs_into(wb, u, f, alpha);
    gradient(grid, p, w1);
    wb.axpy(-1.0, w1);
    apply_Ainv(wb, u, alpha);
    project(u);
    zero_wall_faces(grid, u);
    for (std::size_t m = 0; m < p.v.size(); ++m) p.v[m] += alpha * phi.v[m];
    StokesStats st;
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
  double cfl = 0.0;
  if (impl_->opt.advection.enabled) cfl = advect(impl_->grid, u, dt, impl_->opt.advection);  // module (28)
  StokesStats st = impl_->grid.kind() == ContainerKind::PeriodicBox ? impl_->box_step(u, f, dt)
                    : impl_->capacitance                             ? impl_->capacitance_step(u, f, dt)
                    : impl_->direct                                  ? impl_->direct_step(u, f, dt)
                                                                     : impl_->duct_step(u, f, dt);
  st.advection_cfl = cfl;
  return st;
}

StokesStats StokesSolver::bare_fft_solve(VectorField& u, const VectorField& f, double dt) {
  check_dt(dt);
  return impl_->grid.kind() == ContainerKind::PeriodicBox ? impl_->box_step(u, f, dt) : impl_->duct_bare(u, f, dt);
}

const ScalarField& StokesSolver::pressure() const { return impl_->p; }
void StokesSolver::set_pressure(const ScalarField& p) {
  if (p.v.size() != impl_->grid.cells())
    throw InputError("pressure", std::to_string(p.v.size()) + " values",
                     "one value per cell (" + std::to_string(impl_->grid.cells()) + ")");
  impl_->p = p;
  impl_->lam_stale = false;  // the lazily recovered multiplier would mix old and new states
}
bool StokesSolver::uses_direct() const { return impl_->direct != nullptr || impl_->capacitance != nullptr; }
StokesMethod StokesSolver::active_method() const {
  if (impl_->grid.kind() == ContainerKind::PeriodicBox) return StokesMethod::Auto;
  if (impl_->capacitance) return StokesMethod::Capacitance;
  return impl_->direct ? StokesMethod::Direct : StokesMethod::Iterative;
}
std::size_t StokesSolver::direct_factor_bytes() const {
  if (impl_->capacitance) return impl_->capacitance->factor_bytes();
  return impl_->direct ? impl_->direct->factor_bytes() : 0;
}
const VelocityConstraints* StokesSolver::constraints() const { return impl_->con.get(); }
const std::vector<double>& StokesSolver::multiplier() const {
  if ((impl_->direct || impl_->capacitance) && impl_->con) impl_->refresh_multiplier();
  return impl_->lam;
}
const MacGrid& StokesSolver::grid() const { return impl_->grid; }
const FluidParams& StokesSolver::fluid() const { return impl_->fluid; }

}  // namespace swim::full3d
