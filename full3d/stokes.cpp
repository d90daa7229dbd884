#include "full3d/stokes.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <string>

#include "common/errors.hpp"
#include "full3d/capacitance_stokes.hpp"
#include "full3d/operators.hpp"

namespace swim::full3d {

namespace {

constexpr double kPi = std::numbers::pi;

std::string gib(double bytes) { return std::to_string(bytes / (1024.0 * 1024.0 * 1024.0)) + " GiB"; }

}  // namespace

int factor_slots(const MacGrid& g, const StokesOptions& o) {
  if (g.boundary() == GridBoundary::PeriodicBox) return CapacitanceStokes::kCachedAlphas;
  // The factors of as many dt values as fit the memory limit (up to kCachedAlphas); at least
  // two, the midpoint scheme's dt/2 and dt.
  const CylinderOptions* cyl = o.cylinder.enabled ? &o.cylinder : nullptr;
  const double per_alpha = double(CapacitanceStokes::estimate_bytes(g, cyl));
  const double limit = o.memory_limit_gib * 1024.0 * 1024.0 * 1024.0;
  const int slots = int(std::min<double>(CapacitanceStokes::kCachedAlphas, std::floor(limit / per_alpha)));
  if (slots < 2)
    throw InputError("full3d.grid.cells_across",
                     std::to_string(g.nx()) + " x " + std::to_string(g.ny()) + " x " + std::to_string(g.nz()) + " cells",
                     "a grid whose Stokes factors for two time steps fit the memory limit (" + gib(2 * per_alpha) +
                         " needed, " + gib(limit) +
                         " allowed by full3d.memory_limit_gib): fewer cells across, a shorter swimmer, or a larger "
                         "full3d.memory_limit_gib on a machine that has the memory");
  return slots;
}

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

  // Square duct and cylinder: the capacitance solver
  std::unique_ptr<CapacitanceStokes> capacitance;
  // Cylinder: the constraint rows
  std::unique_ptr<VelocityConstraints> con;

  Impl(const MacGrid& g, const FluidParams& f, const StokesOptions& o) : grid(g), fluid(f), opt(o), p(g) {
    if (!(f.rho > 0.0)) throw InputError("fluid.rho", std::to_string(f.rho), "a positive density in kg/m^3");
    if (!(f.mu > 0.0)) throw InputError("fluid.mu", std::to_string(f.mu), "a positive dynamic viscosity in Pa s");
    const int nx = g.nx(), ny = g.ny(), nz = g.nz();
    if (g.boundary() == GridBoundary::PeriodicBox) {
      if (o.cylinder.enabled)
        throw InputError("container", to_string(g.boundary()), "the circular cylinder needs a square_duct grid");
      const std::size_t nc = std::size_t(nz) * ny * (nx / 2 + 1);
      for (int c = 0; c < 3; ++c) {
        real[c] = FftwBuffer(g.cells());
        spec[c] = FftwBuffer(2 * nc);
      }
      pspec = FftwBuffer(2 * nc);
      r2c = plan_r2c_3d({nz, ny, nx}, real[0].data(), spec[0].complex(), o.fft);
      c2r = plan_c2r_3d({nz, ny, nx}, spec[0].complex(), real[0].data(), o.fft);
      return;
    }
    const CylinderOptions* cyl = o.cylinder.enabled ? &o.cylinder : nullptr;
    if (cyl) {
      con = std::make_unique<VelocityConstraints>(g, o.cylinder);  // validates the radius
      if (!CapacitanceStokes::supports_cylinder(g, o.cylinder))
        throw InputError("container.radius", std::to_string(o.cylinder.radius) + " m",
                         "a cylinder at least half a cell inside the duct walls (the scenes build the duct one "
                         "cell wider than the cylinder on each side)");
    }
    const int slots = factor_slots(g, o);
    const int thr = o.threads > 0 ? o.threads : std::max(1, o.fft.threads);
    capacitance = std::make_unique<CapacitanceStokes>(g, f.mu, cyl, thr, o.fft);
    capacitance->limit_cache(slots);
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
    st.max_divergence = max_abs_divergence(grid, u, threads());
    return st;
  }

  int threads() const { return opt.threads > 0 ? opt.threads : std::max(1, opt.fft.threads); }

  // ---- square duct and cylinder: the capacitance solver, exact, no iteration ----------
  /// un: u^n (may be u itself), nullptr for a fluid at rest.
  StokesStats capacitance_step(const VectorField* un, VectorField& u, const VectorField& f, double dt) {
    // b = alpha u^n + f formed inside; wall and masked faces come out exactly 0
    if (un)
      capacitance->step(*un, f, u, p, fluid.rho / dt);
    else
      capacitance->solve(f, u, p, fluid.rho / dt);
    StokesStats st;
    if (capacitance->last_solve_factorized()) st.factorization_seconds = capacitance->last_factorization_seconds();
    st.max_divergence = max_abs_divergence(grid, u, threads());
    return st;
  }

  StokesStats step(const VectorField* un, VectorField& u, const VectorField& f, double dt) {
    if (!(dt > 0.0) || !std::isfinite(dt)) throw InputError("dt", std::to_string(dt), "a positive time step in s");
    double cfl = 0.0;
    if (opt.advection.enabled || !capacitance) {  // in place: u^n first into u
      if (!un) {
        u = VectorField(grid);
      } else if (un != &u) {
        u = *un;
      }
      un = &u;
      if (opt.advection.enabled) cfl = advect(grid, u, dt, opt.advection);  // module (28)
    }
    StokesStats st = capacitance ? capacitance_step(un, u, f, dt) : box_step(u, f, dt);
    st.advection_cfl = cfl;
    return st;
  }
};

StokesSolver::StokesSolver(const MacGrid& grid, const FluidParams& fluid, const StokesOptions& opt)
    : impl_(std::make_unique<Impl>(grid, fluid, opt)) {}
StokesSolver::~StokesSolver() = default;
StokesSolver::StokesSolver(StokesSolver&&) noexcept = default;
StokesSolver& StokesSolver::operator=(StokesSolver&&) noexcept = default;

StokesStats StokesSolver::step(VectorField& u, const VectorField& f, double dt) { return impl_->step(&u, u, f, dt); }
StokesStats StokesSolver::step(const VectorField& un, VectorField& u, const VectorField& f, double dt) {
  return impl_->step(&un, u, f, dt);
}
StokesStats StokesSolver::step_from_rest(VectorField& u, const VectorField& f, double dt) {
  return impl_->step(nullptr, u, f, dt);
}

const ScalarField& StokesSolver::pressure() const { return impl_->p; }
void StokesSolver::compute_pressure(bool on) {
  if (impl_->capacitance) impl_->capacitance->compute_pressure(on);
}
bool StokesSolver::computes_pressure() const {
  return impl_->capacitance ? impl_->capacitance->computes_pressure() : true;
}
void StokesSolver::set_pressure(const ScalarField& p) {
  if (p.v.size() != impl_->grid.cells())
    throw InputError("pressure", std::to_string(p.v.size()) + " values",
                     "one value per cell (" + std::to_string(impl_->grid.cells()) + ")");
  impl_->p = p;
}
long StokesSolver::factorizations() const { return impl_->capacitance ? impl_->capacitance->factorizations() : 0; }
double StokesSolver::factorization_seconds() const {
  return impl_->capacitance ? impl_->capacitance->factorization_seconds_total() : 0.0;
}
int StokesSolver::cached_time_steps() const { return impl_->capacitance ? impl_->capacitance->cache_slots() : 0; }
std::size_t StokesSolver::factor_bytes() const {
  return impl_->capacitance ? impl_->capacitance->factor_bytes() : 0;
}
const VelocityConstraints* StokesSolver::constraints() const { return impl_->con.get(); }
const MacGrid& StokesSolver::grid() const { return impl_->grid; }
const FluidParams& StokesSolver::fluid() const { return impl_->fluid; }

}  // namespace swim::full3d
