#include "full3d/ib_solver.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include "common/errors.hpp"
#include "common/si_format.hpp"
#include "full3d/ib.hpp"

namespace swim::full3d {

ChebyshevStages chebyshev_stages(int s, double damping) {
  if (s < 1) throw InputError("Chebyshev stages", std::to_string(s), "at least 1");
  ChebyshevStages c;
  c.s = s;
  c.mu.assign(s + 1, 0.0);
  c.nu.assign(s + 1, 0.0);
  c.mut.assign(s + 1, 0.0);
  c.c.assign(s + 1, 0.0);
  if (s == 1) {  // forward Euler
    c.mut[1] = c.c[1] = 1.0;
    return c;
  }
  const double w0 = 1.0 + damping / double(s) / double(s);
  // T_j(w0) and T_j'(w0) by the three-term recurrence
  std::vector<double> T(s + 1), dT(s + 1);
  T[0] = 1.0, dT[0] = 0.0;
  T[1] = w0, dT[1] = 1.0;
  for (int j = 2; j <= s; ++j) {
    T[j] = 2.0 * w0 * T[j - 1] - T[j - 2];
    dT[j] = 2.0 * T[j - 1] + 2.0 * w0 * dT[j - 1] - dT[j - 2];
  }
  const double w1 = T[s] / dT[s];
  c.w0 = w0;
  c.w1 = w1;
  std::vector<double> b(s + 1);
  for (int j = 0; j <= s; ++j) b[j] = 1.0 / T[j];
  c.mut[1] = w1 * b[1];
  for (int j = 2; j <= s; ++j) {
    c.mu[j] = 2.0 * w0 * b[j] / b[j - 1];
    c.nu[j] = -b[j] / b[j - 2];
    c.mut[j] = 2.0 * w1 * b[j] / b[j - 1];
  }
  for (int j = 1; j <= s; ++j) c.c[j] = w1 * dT[j] / T[j];  // Y_j = y + c_j dt f + O(dt^2)
  return c;
}

int chebyshev_stages_for(double dt, double lambda, double fraction, int max_stages) {
  if (!(lambda > 0.0)) return 1;
  for (int s = 1; s < max_stages; ++s)
    if (fraction * chebyshev_stages(s).stability_interval() >= dt * lambda) return s;
  return max_stages;
}

IbSolver::IbSolver(const MacGrid& grid, const FluidParams& fluid, CylinderMesh mesh, MembraneParams membrane,
                   Eigen::VectorXd node_mass, IbOptions opt)
    : grid_(grid), mesh_(std::move(mesh)), membrane_(membrane), mass_(std::move(node_mass)), opt_(opt),
      stokes_(grid, fluid, opt.stokes) {
  if (mass_.size() != mesh_.nodes())
    throw InputError("IbSolver node_mass", std::to_string(mass_.size()) + " values",
                     "one mass per membrane node (" + std::to_string(mesh_.nodes()) + ")");
  if (!(opt_.max_cfl > 0.0)) throw InputError("full3d.max_cfl", significant(opt_.max_cfl, 4), "a positive number");
  if (opt_.wall_stabilization != WallStabilization::None) {
    if (opt_.scheme != IbScheme::ForwardEuler)
      throw InputError("full3d.wall_stabilization", to_string(opt_.wall_stabilization),
                       "only with full3d.scheme = forward_euler (or \"none\")");
    const double D = membrane_.kb * bending_rigidity_per_kb(mesh_, membrane_.bending);
    stab_ = std::make_unique<WallStabilizer>(mesh_, grid_.h(), fluid.mu, D, opt_.wall_stabilization,
                                             opt_.stabilization_factor, opt_.threads);
  }
}

IbState IbSolver::initial_state() const {
  IbState s;
  s.X = mesh_.X0;
  s.V = Eigen::Matrix3Xd::Zero(3, mesh_.nodes());
  s.V_prev = s.V;
  s.u = VectorField(grid_);
  return s;
}

const Eigen::Matrix3Xd& IbSolver::elastic(const Eigen::Matrix3Xd& X) const {
  ElasticPass& e = elastic_;
  const bool same = e.X.cols() == X.cols() && X.cols() > 0 &&
                    std::memcmp(e.X.data(), X.data(), sizeof(double) * std::size_t(X.size())) == 0;
  if (!same) {
    e.F = elastic_forces(mesh_, X, membrane_, opt_.threads, &e.energy);
    e.X = X;
  }
  return e.F;
}

std::array<double, 2> IbSolver::elastic_energy_parts(const Eigen::Matrix3Xd& X) const {
  elastic(X);
  return elastic_.energy;
}

Eigen::Matrix3Xd IbSolver::fluid_force(const Eigen::Matrix3Xd& X, double t, const Eigen::Matrix3Xd& accel) const {
  Eigen::Matrix3Xd F = elastic(X);
  if (external_) F += external_(t, X);
  if (mass_.size() > 0 && mass_.maxCoeff() > 0.0)
    for (Eigen::Index i = 0; i < F.cols(); ++i) F.col(i) -= mass_[i] * accel.col(i);
  return F;
}

std::string IbSolver::dt_remedy() const {
  std::string r = "reduce the time step " + opt_.dt_key;
  if (mass_.size() > 0 && mass_.maxCoeff() > 0.0)
    r += " -- but with the explicit node inertia -m a (lagged acceleration) a SMALLER step is less stable "
         "(stable only while m M / dt < 1/2, M the membrane mobility): raise the time step or turn the inertia "
         "term off (full3d.wall_inertia = false; docs/full3d.md)";
  return r;
}

void IbSolver::guard_finite(const Eigen::Matrix3Xd& A, const char* what, double t) const {
  if (!A.allFinite())
    throw NumericalError(std::string("non-finite ") + what + " (the explicit coupling became unstable)",
                         dt_remedy(), t);
}

void project_axisymmetric(const CylinderMesh& mesh, const Eigen::Matrix3Xd& X, Eigen::Matrix3Xd& U) {
  const Eigen::Matrix3Xd er = radial_directions(mesh, X);
  for (int r = 0; r < mesh.n_rings; ++r) {
    double ux = 0.0, ur = 0.0;
    for (int i = 0; i < mesh.n_theta; ++i) {
      const int k = mesh.node(r, i);
      ux += U(0, k);
      ur += U.col(k).dot(er.col(k));
    }
    ux /= mesh.n_theta;
    ur /= mesh.n_theta;
    for (int i = 0; i < mesh.n_theta; ++i) {
      const int k = mesh.node(r, i);
      U.col(k) = ur * er.col(k);
      U(0, k) = ux;
    }
  }
}

namespace {
// The step of the fluid's inertia term for a (half) step dt: IbOptions::inertia_step when set.
double inertia_step(const IbOptions& o, double dt) { return o.inertia_step > 0.0 ? o.inertia_step : dt; }
}  // namespace

IbStepStats IbSolver::step(IbState& s, double dt, int stages) {
  if (!(dt > 0.0) || !std::isfinite(dt)) throw InputError(opt_.dt_key, significant(dt, 4), "a positive time step in s");
  IbStepStats st;
  using clock = std::chrono::steady_clock;
  auto tic = clock::now();
  auto lap = [&](double& acc) {
    const auto now = clock::now();
    acc += std::chrono::duration<double>(now - tic).count();
    tic = now;
  };
  // Work fields kept between steps: fresh 3-field allocations of the grid size would be
  // returned to the OS and page-faulted in again every step (several ms on 128x32x32).
  // spread() overwrites f; the Stokes step writes u from s.u (no copy of u^n).
  VectorField& f = work_f_;
  VectorField& u = work_u_;
  const Eigen::Matrix3Xd accel = (s.V - s.V_prev) / dt;
  Eigen::Matrix3Xd U, Xnew;
  const double tau = inertia_step(opt_, dt), tau_half = inertia_step(opt_, 0.5 * dt);

  Eigen::Matrix3Xd F = fluid_force(s.X, s.t, accel);
  guard_finite(F, "membrane force", s.t);
  lap(st.time_forces);
  // one velocity evaluation: the force FY at the nodes Y spread, the Stokes step of tau from
  // the step's u^n into `into`, and the node velocities interpolated from it
  auto velocity = [&](const Eigen::Matrix3Xd& Y, const Eigen::Matrix3Xd& FY, VectorField& into, double tau_s) {
    spread(grid_, Y, FY, f, opt_.threads, &f_support_);
    lap(st.time_spread);
    const StokesStats ss = stokes_.step(s.u, into, f, tau_s);
    lap(st.time_fluid);
    st.stokes_iterations += ss.iterations;
    st.max_divergence = ss.max_divergence;
    ++st.fluid_solves;
    Eigen::Matrix3Xd UY;
    interpolate(grid_, into, Y, UY, opt_.threads);
    if (opt_.axisymmetric_wall) project_axisymmetric(mesh_, Y, UY);
    lap(st.time_interp);
    guard_finite(UY, "node velocity", s.t);
    return UY;
  };
  if (opt_.scheme == IbScheme::Chebyshev && stages > 1) {
    // Y_j = mu_j Y_{j-1} + nu_j Y_{j-2} + mut_j dt U(Y_{j-1}); every stage's fluid solve
    // starts from the step's u^n (the inertia term's old velocity)
    const ChebyshevStages c = chebyshev_stages(stages);
    Eigen::Matrix3Xd Y2 = s.X;
    Eigen::Matrix3Xd Y1 = s.X + (c.mut[1] * dt) * velocity(s.X, F, u, tau);
    for (int j = 2; j <= stages; ++j) {
      F = fluid_force(Y1, s.t + c.c[j - 1] * dt, accel);
      guard_finite(F, "membrane force", s.t);
      lap(st.time_forces);
      Eigen::Matrix3Xd Yj = c.mu[j] * Y1 + c.nu[j] * Y2 + (c.mut[j] * dt) * velocity(Y1, F, u, tau);
      guard_finite(Yj, "node position", s.t);
      Y2 = std::move(Y1);
      Y1 = std::move(Yj);
    }
    U = (Y1 - s.X) / dt;
    Xnew = std::move(Y1);
  } else if (opt_.scheme != IbScheme::Midpoint) {
    if (stab_) stab_->apply_root(dt, F);  // the mobility G M G: G on the forces spread...
    U = velocity(s.X, F, u, tau);
    if (stab_) {  // ...and on the velocities interpolated: the step's mean velocity
      stab_->apply_root(dt, U);
      guard_finite(U, "stabilised node velocity", s.t);
    }
    Xnew = s.X + dt * U;
  } else {
    const Eigen::Matrix3Xd U0 = velocity(s.X, F, work_uh_, tau_half);
    const Eigen::Matrix3Xd Xh = s.X + 0.5 * dt * U0;
    F = fluid_force(Xh, s.t + 0.5 * dt, accel);
    guard_finite(F, "membrane force", s.t);
    lap(st.time_forces);
    U = velocity(Xh, F, u, tau);
    Xnew = s.X + dt * U;
    st.max_velocity_change = (U - U0).colwise().norm().maxCoeff();
  }
  guard_finite(U, "node velocity", s.t);
  guard_finite(Xnew, "node position", s.t);
  st.max_node_speed = U.colwise().norm().maxCoeff();
  st.cfl = st.max_node_speed * dt / grid_.h();
  if (st.cfl > opt_.max_cfl && opt_.reject_on_cfl) {
    st.rejected = true;
    return st;
  }
  if (st.cfl > opt_.max_cfl)
    throw NumericalError("advective CFL number " + significant(st.cfl, 4) + " exceeds " + significant(opt_.max_cfl, 4) +
                             " (nodes move " + significant(st.cfl, 4) + " cells per step)",
                         dt_remedy(), s.t);
  st.max_edge = max_edge_length(mesh_, Xnew);
  if (opt_.check_no_leak && !(st.max_edge < 0.5 * grid_.h()))
    throw NumericalError("membrane edge of " + significant(st.max_edge, 4) + " m exceeds h/2 = " + significant(0.5 * grid_.h(), 4) +
                             " m after this step (was " + significant(max_edge_length(mesh_, s.X), 4) +
                             " m): the fluid would leak through the membrane",
                         "reduce the time step " + opt_.dt_key + " if the edge jumped in one step, otherwise refine the membrane",
                         s.t + dt);
  // the largest divergence is NaN when any fluid velocity is not finite (operators.hpp)
  if (!std::isfinite(st.max_divergence))
    throw NumericalError("non-finite fluid velocity (the explicit coupling became unstable)", dt_remedy(), s.t);
  s.X = std::move(Xnew);
  s.V_prev = std::move(s.V);
  s.V = std::move(U);
  std::swap(s.u, u);  // u (work_u_) keeps the old buffers for the next step
  s.t += dt;
  return st;
}

Eigen::Matrix3Xd IbSolver::rate_start(Eigen::Index n, const Eigen::Matrix3Xd* start) {
  if (start && start->cols() == n) return *start;
  // fixed pseudo-random start (a linear congruential sequence): reproducible on resume
  Eigen::Matrix3Xd v(3, n);
  std::uint64_t r = 0x9E3779B97F4A7C15ull;
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    r = r * 6364136223846793005ull + 1442695040888963407ull;
    v.data()[i] = double(r >> 11) * (1.0 / 9007199254740992.0) - 0.5;
  }
  return v;
}

template <class Body>
auto IbSolver::with_linearised_coupling(const IbState& s, double dt, Body&& body) {
  // membrane forces only: the actuation relays are saturating (their level moves by at most
  // one over a ramp of a fraction of delta), so their steep slope bounds an oscillation to the
  // ramp width instead of growing it
  const Eigen::Matrix3Xd F0 = elastic(s.X);
  const double eps = 1e-4 * grid_.h();  // finite-difference amplitude (max node displacement)
  // the pressure is the last step's result (fluid-field output): the estimate must not change it
  struct Restore {
    StokesSolver& s;
    bool was;
    std::optional<ScalarField> p;  // the box computes it anyway: kept and put back
    ~Restore() {
      s.compute_pressure(was);
      if (p) s.set_pressure(*p);
    }
  } restore{stokes_, stokes_.computes_pressure(), std::nullopt};
  stokes_.compute_pressure(false);
  if (stokes_.computes_pressure()) restore.p = stokes_.pressure();
  // A v: the decay rate the (stabilised) update gives the perturbation v, 1/s times v
  auto apply = [&](const Eigen::Matrix3Xd& v) {
    const double vmax = v.cwiseAbs().maxCoeff();
    Eigen::Matrix3Xd U;
    if (!(vmax > 0.0) || !std::isfinite(vmax)) return U;  // empty: no direction left
    const double scale = eps / vmax;
    Eigen::Matrix3Xd dF = (elastic_forces(mesh_, s.X + scale * v, membrane_, opt_.threads) - F0) / scale;
    if (stab_) stab_->apply_root(dt, dF);
    spread(grid_, s.X, dF, work_f_, opt_.threads, &f_support_);
    stokes_.step_from_rest(work_uh_, work_f_, inertia_step(opt_, dt));
    interpolate(grid_, work_uh_, s.X, U, opt_.threads);
    if (stab_) stab_->apply_root(dt, U);
    U = -U;
    return U;
  };
  return body(apply);
}

double IbSolver::explicit_rate(const IbState& s, double dt, int iterations, Eigen::Matrix3Xd* start) {
  Eigen::Matrix3Xd v = rate_start(s.X.cols(), start);
  const double lambda = with_linearised_coupling(s, dt, [&](auto&& apply) {
    double l = 0.0;
    for (int it = 0; it < iterations; ++it) {
      Eigen::Matrix3Xd Av = apply(v);
      if (Av.size() == 0) return l;
      l = Av.norm() / v.norm();  // |A v| / |v|
      const double amax = Av.cwiseAbs().maxCoeff();
      if (!(amax > 0.0) || !std::isfinite(amax)) return l;
      v = Av / amax;
    }
    return l;
  });
  if (start) *start = v;
  return lambda;
}

IbSolver::RateSpectrum IbSolver::explicit_spectrum(const IbState& s, double dt, int iterations,
                                                   const Eigen::Matrix3Xd* start) {
  const Eigen::Index n = s.X.cols(), len = 3 * n;
  const int k_max = std::max(1, iterations);
  Eigen::MatrixXd V(len, k_max + 1);  // orthonormal Krylov basis
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(k_max + 1, k_max);
  {
    const Eigen::Matrix3Xd v0 = rate_start(n, start);
    const double nv = v0.norm();
    if (!(nv > 0.0) || !std::isfinite(nv)) throw std::invalid_argument("explicit_spectrum: zero or non-finite start");
    V.col(0) = Eigen::Map<const Eigen::VectorXd>(v0.data(), len) / nv;
  }
  int k = 0;  // Arnoldi steps made
  with_linearised_coupling(s, dt, [&](auto&& apply) {
    while (k < k_max) {
      const Eigen::Matrix3Xd Av = apply(Eigen::Map<const Eigen::Matrix3Xd>(V.col(k).data(), 3, n));
      if (Av.size() == 0) return 0;
      Eigen::VectorXd w = Eigen::Map<const Eigen::VectorXd>(Av.data(), len);
      const double wnorm = w.norm();
      if (!std::isfinite(wnorm)) return 0;
      for (int pass = 0; pass < 2; ++pass)  // modified Gram-Schmidt, repeated once
        for (int i = 0; i <= k; ++i) {
          const double c = V.col(i).dot(w);
          H(i, k) += c;
          w -= c * V.col(i);
        }
      H(k + 1, k) = w.norm();
      ++k;
      if (!(H(k, k - 1) > 1e-12 * wnorm)) return 0;  // an invariant subspace: the Ritz values are exact
      V.col(k) = w / H(k, k - 1);
    }
    return 0;
  });
  RateSpectrum out;
  if (k == 0) return out;
  const Eigen::EigenSolver<Eigen::MatrixXd> es(H.topLeftCorner(k, k), true);
  for (int i = 0; i < k; ++i) {
    const std::complex<double> mu = es.eigenvalues()(i);
    const Eigen::VectorXcd y = es.eigenvectors().col(i);
    out.ritz.push_back(mu);
    out.residual.push_back(std::abs(mu) > 0.0 ? H(k, k - 1) * std::abs(y(k - 1)) / (y.norm() * std::abs(mu))
                                              : std::numeric_limits<double>::infinity());
  }
  return out;
}

}  // namespace swim::full3d
