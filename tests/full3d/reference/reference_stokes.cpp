#include "tests/full3d/reference/reference_stokes.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "common/errors.hpp"
#include "full3d/operators.hpp"
#include "full3d/reference/duct_fft.hpp"
#include "tests/full3d/reference/direct_stokes.hpp"

namespace swim::full3d::reference {

namespace {

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

double norm2(const VectorField& v) {
  double s = 0.0;
  for (const auto& a : v.c) s += dot(a, a);
  return std::sqrt(s);
}

// E A E^T = alpha E E^T + mu E (-L) E^T, the multiplier block of the PCG preconditioner, with
// -L (the duct's wall rules) restricted to the support of E (the only entries it needs).
class LocalHelmholtz {
 public:
  LocalHelmholtz(const MacGrid& g, const VelocityConstraints& con) {
    using Triplet = Eigen::Triplet<double>;
    const auto& E = con.matrix();
    std::array<std::size_t, 4> offset{};
    for (int c = 0; c < 3; ++c) offset[c + 1] = offset[c] + g.size(c);
    const std::size_t total = offset[3];
    std::vector<char> in_support(total, 0);
    for (int r = 0; r < E.outerSize(); ++r)
      for (VelocityConstraints::Matrix::InnerIterator it(E, r); it; ++it) in_support[it.col()] = 1;
    std::vector<Triplet> lt;
    const double ih2 = 1.0 / (g.h() * g.h());
    for (int c = 0; c < 3; ++c) {
      const auto d = g.dims(c);
      for (int k = 0; k < d[2]; ++k)
        for (int j = 0; j < d[1]; ++j)
          for (int i = 0; i < d[0]; ++i) {
            const std::size_t gi = offset[c] + MacGrid::index(d, i, j, k);
            if (!in_support[gi]) continue;
            const int idx[3] = {i, j, k};
            double diag = 6.0;
            for (int dir = 0; dir < 3; ++dir)
              for (int s = -1; s <= 1; s += 2) {
                int nb[3] = {i, j, k};
                const int tt = idx[dir] + s;
                if (g.periodic(dir)) {
                  nb[dir] = (tt + d[dir]) % d[dir];
                } else if (tt < 0 || tt >= d[dir]) {
                  diag += 1.0;  // ghost value -u
                  continue;
                } else {
                  nb[dir] = tt;
                  if (g.on_wall(c, dir, tt)) continue;  // held at zero
                }
                const std::size_t gj = offset[c] + MacGrid::index(d, nb[0], nb[1], nb[2]);
                if (in_support[gj]) lt.emplace_back(gi, gj, -ih2);
              }
            lt.emplace_back(gi, gi, diag * ih2);
          }
    }
    VelocityConstraints::Matrix negL(static_cast<Eigen::Index>(total), static_cast<Eigen::Index>(total));
    negL.setFromTriplets(lt.begin(), lt.end());
    const VelocityConstraints::Matrix Et = E.transpose();
    EEt_ = E * Et;
    ELEt_ = E * (negL * Et);
  }
  void apply(const std::vector<double>& r, std::vector<double>& z, double alpha, double mu) const {
    const Eigen::Map<const Eigen::VectorXd> rv(r.data(), Eigen::Index(r.size()));
    z.resize(r.size());
    Eigen::Map<Eigen::VectorXd> zv(z.data(), Eigen::Index(z.size()));
    zv = mu * (ELEt_ * rv);
    if (alpha != 0.0) zv += alpha * (EEt_ * rv);
  }

 private:
  VelocityConstraints::Matrix EEt_, ELEt_;
};

void check_dt(double dt) {
  if (!(dt > 0.0) || !std::isfinite(dt)) throw InputError("dt", std::to_string(dt), "a positive time step in s");
}

}  // namespace

struct ReferenceStokes::Impl {
  MacGrid grid;
  FluidParams fluid;
  Options opt;
  ScalarField p;
  DuctFft fft;
  std::unique_ptr<VelocityConstraints> con;
  std::unique_ptr<LocalHelmholtz> local;
  std::vector<double> lam;
  std::unique_ptr<DirectStokes> direct;
  // SparseLu: the multiplier is recovered on demand from the last step's (b, u, p, alpha)
  bool lam_stale = false;
  VectorField last_b, last_u;
  double last_alpha = 0.0;
  // scratch
  VectorField wb, w1, w2, uc;
  ScalarField rp, zp, dp, sdp, div;
  std::vector<double> rl, zl, dl, sdl;

  Impl(const MacGrid& g, const FluidParams& f, const Options& o) : grid(g), fluid(f), opt(o), p(g), fft(g, o.fft) {
    if (!(f.rho > 0.0)) throw InputError("fluid.rho", std::to_string(f.rho), "a positive density in kg/m^3");
    if (!(f.mu > 0.0)) throw InputError("fluid.mu", std::to_string(f.mu), "a positive dynamic viscosity in Pa s");
    for (auto* v : {&wb, &w1, &w2, &uc}) *v = VectorField(g);
    for (auto* v : {&rp, &zp, &dp, &sdp, &div}) *v = ScalarField(g);
    if (o.cylinder.enabled) {
      con = std::make_unique<VelocityConstraints>(wall_constraints(g, o.cylinder.radius, o.wall));
      lam.assign(con->rows(), 0.0);
    }
    if (o.method == Method::SparseLu) {
      if (o.cylinder.enabled && o.wall.wall != CylinderWall::Staircase)
        throw InputError("reference::Options::wall", "not staircase",
                         "the sparse-LU reference supports the plain duct and the staircase cylinder only");
      direct = std::make_unique<DirectStokes>(g, f.mu, o.cylinder.enabled ? &o.cylinder : nullptr,
                                              std::max(1, o.threads), o.fft);
    } else if (con) {
      local = std::make_unique<LocalHelmholtz>(g, *con);
    }
  }

  void rhs_into(VectorField& b, const VectorField& u, const VectorField& f, double alpha) {
    for (int c = 0; c < 3; ++c)
      for (std::size_t m = 0; m < b.c[c].size(); ++m) b.c[c][m] = alpha * u.c[c][m] + f.c[c][m];
    zero_wall_faces(grid, b);
  }

  // Preconditioner: M^{-1} = blockdiag(mu I + alpha (-DG)^{-1}  [Cahouet-Chabard],  E A E^T).
  void apply_M(double alpha) {
    if (alpha > opt.cc_poisson_drop_ratio * fluid.mu * fft.lambda_min()) {
      fft.poisson(rp, zp);
      for (std::size_t m = 0; m < zp.v.size(); ++m) zp.v[m] = alpha * zp.v[m] + fluid.mu * rp.v[m];
    } else {  // quasi-steady: alpha (-DG)^{-1} is below the drop ratio times mu
      for (std::size_t m = 0; m < zp.v.size(); ++m) zp.v[m] = fluid.mu * rp.v[m];
    }
    remove_mean(zp.v);
    if (local) local->apply(rl, zl, alpha, fluid.mu);
  }
  // residual of the constraints on v: r = (G^T v, E v) = (-D v, E v)
  void constraint_residual(const VectorField& v, ScalarField& outp, std::vector<double>& outl) {
    divergence(grid, v, outp);
    for (double& x : outp.v) x = -x;
    if (con) con->gather(v, outl);
  }
  double scaled_norm() const {
    const double h = grid.h();
    return std::sqrt(h * h * dot(rp.v, rp.v) + (con ? dot(rl, rl) : 0.0));
  }

  // Solves A u + G p + E^T lam = b, D u = 0, E u = 0 (no E without the cylinder) by PCG on the
  // multipliers y = (p, lam): K^T A^{-1} K y = K^T A^{-1} b with K = [G, E^T]. The unprojected
  // velocity uc = A^{-1}(b - K y) is updated alongside: one K, one A^{-1} (three transform
  // pairs) and one K^T per iteration.
  StokesStats pcg_step(VectorField& u, const VectorField& f, double dt) {
    const double alpha = fluid.rho / dt;
    rhs_into(wb, u, f, alpha);
    StokesStats st;
    remove_mean(p.v);
    gradient(grid, p, w1);
    for (int c = 0; c < 3; ++c)
      for (std::size_t m = 0; m < w1.c[c].size(); ++m) w1.c[c][m] = wb.c[c][m] - w1.c[c][m];
    if (con) con->scatter_add(lam, -1.0, w1);
    fft.helmholtz(w1, uc, alpha, fluid.mu);
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
          throw NumericalError("reference Stokes PCG did not converge in " + std::to_string(it) +
                                   " iterations (relative residual " + std::to_string(rnorm / ref) + ")",
                               "raise reference::Options::cg_max_iterations or loosen cg_rtol");
        gradient(grid, dp, w1);
        if (con) con->scatter_add(dl, 1.0, w1);
        fft.helmholtz(w1, w2, alpha, fluid.mu);
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
    fft.project(u);
    divergence(grid, u, div);
    st.max_divergence = div.max_abs();
    if (con) {
      con->gather(u, rl);
      for (double x : rl) st.max_constraint = std::max(st.max_constraint, std::abs(x));
    }
    return st;
  }

  // Per-mode sparse LU: no iteration, E u = 0 exactly (masked faces eliminated).
  StokesStats lu_step(VectorField& u, const VectorField& f, double dt) {
    const double alpha = fluid.rho / dt;
    rhs_into(wb, u, f, alpha);
    direct->solve(wb, u, p, alpha);
    StokesStats st;
    if (direct->last_solve_factorized()) st.factorization_seconds = direct->last_factorization_seconds();
    zero_wall_faces(grid, u);
    divergence(grid, u, div);
    st.max_divergence = div.max_abs();
    if (con) {
      last_b = wb;
      last_u = u;
      last_alpha = alpha;
      lam_stale = true;
    }
    return st;
  }
};

ReferenceStokes::ReferenceStokes(const MacGrid& g, const FluidParams& fluid, const Options& opt)
    : impl_(std::make_unique<Impl>(g, fluid, opt)) {}
ReferenceStokes::~ReferenceStokes() = default;
ReferenceStokes::ReferenceStokes(ReferenceStokes&&) noexcept = default;
ReferenceStokes& ReferenceStokes::operator=(ReferenceStokes&&) noexcept = default;

StokesStats ReferenceStokes::step(VectorField& u, const VectorField& f, double dt) {
  check_dt(dt);
  return impl_->direct ? impl_->lu_step(u, f, dt) : impl_->pcg_step(u, f, dt);
}
const ScalarField& ReferenceStokes::pressure() const { return impl_->p; }
void ReferenceStokes::set_pressure(const ScalarField& p) {
  if (p.v.size() != impl_->grid.cells())
    throw InputError("pressure", std::to_string(p.v.size()) + " values",
                     "one value per cell (" + std::to_string(impl_->grid.cells()) + ")");
  impl_->p = p;
  impl_->lam_stale = false;
}
const VelocityConstraints* ReferenceStokes::constraints() const { return impl_->con.get(); }
const std::vector<double>& ReferenceStokes::multiplier() const {
  Impl& m = *impl_;
  if (m.lam_stale) {
    recover_multiplier(*m.con, m.last_b, m.last_u, m.p, m.last_alpha, m.fluid.mu, m.lam);
    m.lam_stale = false;
  }
  return m.lam;
}
std::size_t ReferenceStokes::factor_bytes() const { return impl_->direct ? impl_->direct->factor_bytes() : 0; }
bool ReferenceStokes::has_pressure(int j, int k) const {
  return impl_->direct ? impl_->direct->has_pressure(j, k) : true;
}

}  // namespace swim::full3d::reference
