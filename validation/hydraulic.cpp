#include "validation/hydraulic.hpp"

#include <gsl/gsl_fit.h>
#include <gsl/gsl_multifit.h>
#include <gsl/gsl_statistics_double.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <memory>
#include <vector>

#include "common/errors.hpp"
#include "common/si_format.hpp"
#include "full3d/grid.hpp"
#include "full3d/ib.hpp"
#include "full3d/membrane.hpp"
#include "full3d/stokes.hpp"
#include "full3d/world3d.hpp"
#include "reduced1d/outer_flow.hpp"
#include "validation/richardson.hpp"

namespace swim::validation {

namespace {

using full3d::MacGrid;
using full3d::VectorField;

struct Sample {
  double r, u;
};

struct RootFit {
  double root = 0, stderr_root = 0;
};

// The lumen's Poiseuille fit needs three distinct radii among its samples (r < R0 - 2h): a
// property of the grid alone, so it is checked on the samples' positions before any solve.
void require_lumen_radii(const std::vector<Sample>& lumen) {
  std::vector<double> radii;
  for (const auto& s : lumen) radii.push_back(s.r * s.r);
  std::sort(radii.begin(), radii.end());
  const auto distinct = std::unique(radii.begin(), radii.end(), [](double a, double b) { return std::abs(a - b) <= 1e-9 * b; }) - radii.begin();
  if (distinct < 3)
    throw NumericalError("too few distinct radii (" + std::to_string(distinct) + ") among the lumen velocity samples for the Poiseuille fit",
                         "refine full3d.grid.cells_across (the lumen needs r < R0 - 2h)");
}

// u = c0 + s r^2 on the lumen samples; the zero a = sqrt(-c0 / s) and its standard error.
RootFit lumen_fit(const std::vector<Sample>& pts, double* c1_out) {
  std::vector<double> x, y;
  for (const auto& s : pts) {
    x.push_back(s.r * s.r);
    y.push_back(s.u);
  }
  require_lumen_radii(pts);
  double c0, s, c00, c01, c11, ss;
  gsl_fit_linear(x.data(), 1, y.data(), 1, x.size(), &c0, &s, &c00, &c01, &c11, &ss);
  if (!(s < 0 && c0 > 0))
    throw NumericalError("the lumen velocity profile is not a Poiseuille parabola (fit u = " + std::to_string(c0) +
                             " + " + std::to_string(s) + " r^2)",
                         "refine full3d.grid.cells_across");
  RootFit f;
  f.root = std::sqrt(-c0 / s);
  const double da_dc0 = 1.0 / (2.0 * f.root * -s), da_ds = c0 / (2.0 * f.root * s * s);
  f.stderr_root = std::sqrt(std::max(0.0, da_dc0 * da_dc0 * c00 + 2 * da_dc0 * da_ds * c01 + da_ds * da_ds * c11));
  *c1_out = -s;
  return f;
}

// u = A + B r^2 + C ln r on the annulus samples; its zeros near R0 and near Rc.
std::pair<RootFit, RootFit> annulus_fit(const std::vector<Sample>& pts, double R0, double Rc, double h) {
  const std::size_t n = pts.size();
  if (n < 6)
    throw NumericalError("too few annulus velocity samples (" + std::to_string(n) + ") for the annular Poiseuille fit",
                         "refine full3d.grid.cells_across or widen container.radius");
  std::unique_ptr<gsl_matrix, decltype(&gsl_matrix_free)> X(gsl_matrix_alloc(n, 3), gsl_matrix_free);
  std::unique_ptr<gsl_vector, decltype(&gsl_vector_free)> y(gsl_vector_alloc(n), gsl_vector_free), c(gsl_vector_alloc(3), gsl_vector_free);
  std::unique_ptr<gsl_matrix, decltype(&gsl_matrix_free)> cov(gsl_matrix_alloc(3, 3), gsl_matrix_free);
  std::unique_ptr<gsl_multifit_linear_workspace, decltype(&gsl_multifit_linear_free)> w(gsl_multifit_linear_alloc(n, 3),
                                                                                      gsl_multifit_linear_free);
  for (std::size_t i = 0; i < n; ++i) {
    const double r = pts[i].r / R0;  // scaled for conditioning
    gsl_matrix_set(X.get(), i, 0, 1.0);
    gsl_matrix_set(X.get(), i, 1, r * r);
    gsl_matrix_set(X.get(), i, 2, std::log(r));
    gsl_vector_set(y.get(), i, pts[i].u);
  }
  double chisq;
  gsl_multifit_linear(X.get(), y.get(), c.get(), cov.get(), &chisq, w.get());
  const double A = gsl_vector_get(c.get(), 0), B = gsl_vector_get(c.get(), 1), C = gsl_vector_get(c.get(), 2);
  auto u = [&](double r) { return A + B * (r / R0) * (r / R0) + C * std::log(r / R0); };
  auto du = [&](double r) { return 2.0 * B * r / (R0 * R0) + C / r; };
  auto root_in = [&](double lo, double hi, const char* what) {
    if (!(u(lo) * u(hi) < 0))
      throw NumericalError(std::string("the annulus velocity fit has no zero near the ") + what,
                           "refine full3d.grid.cells_across or widen container.radius");
    RootFit f;
    f.root = bracketed_root(u, lo, hi);
    const double rr = f.root / R0;
    const double phi[3] = {1.0, rr * rr, std::log(rr)};
    double var = 0;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) var += phi[a] * phi[b] * gsl_matrix_get(cov.get(), std::size_t(a), std::size_t(b));
    f.stderr_root = std::sqrt(std::max(0.0, var)) / std::abs(du(f.root));
    return f;
  };
  return {root_in(R0 - 3.0 * h, R0 + 2.0 * h, "tube wall"), root_in(Rc - 3.0 * h, Rc + 2.0 * h, "container wall")};
}

// The axial velocity on the x-faces of plane i, sampled for the profile fits: the lumen
// (r < R0 - 2h), the annulus (R0 + 2h < r < Rc - h), and the flux through r < R0.
struct PlaneSamples {
  std::vector<Sample> lumen, annulus;
  double flux = 0;
};
PlaneSamples plane_samples(const MacGrid& grid, const VectorField& u, int i, const Eigen::Vector3d& a0, double R0,
                           double Rc) {
  const double h = grid.h();
  const auto d0 = grid.dims(0);
  PlaneSamples out;
  for (int k = 0; k < d0[2]; ++k)
    for (int j = 0; j < d0[1]; ++j) {
      const auto pos = grid.position(0, i, j, k);
      const double rad = std::hypot(pos[1] - a0.y(), pos[2] - a0.z());
      const double ux = u.c[0][MacGrid::index(d0, i, j, k)];
      if (rad < R0) out.flux += ux * h * h;
      if (rad < R0 - 2.0 * h) out.lumen.push_back({rad, ux});
      if (rad > R0 + 2.0 * h && rad < Rc - h) out.annulus.push_back({rad, ux});
    }
  return out;
}

double mean(const std::vector<double>& v) { return gsl_stats_mean(v.data(), 1, v.size()); }
double sample_std(const std::vector<double>& v) { return v.size() < 2 ? 0.0 : gsl_stats_sd(v.data(), 1, v.size()); }


// The scene for the rigid-tube measurements: a duct (or box) replaced by its inscribed cylinder,
// and the round tube (a seed imperfection is the dynamics' start of buckling, not part of the
// round tube the 1D tier's offsets describe).
full3d::Params3d in_cylinder(const full3d::Params3d& scene) {
  full3d::Params3d p = scene;
  p.seed_mode = 0;
  p.seed_amplitude = 0.0;
  p.secondary_seed_mode = 0;
  p.secondary_seed_amplitude = 0.0;
  if (p.container != "cylinder") {
    p.container = "cylinder";
    p.ny += 2;
    p.nz += 2;
  }
  return p;
}

// The undeformed tube, rigid, in steady Stokes flow through the periodic container: node
// forces F (on the fluid) such that the flow driven by a body force fb plus spread(F) moves
// every node at its prescribed velocity V. Shared by the held tube (V = 0, fb = the driving
// force) and the towed tube (V = U e_x, fb = 0).
class RigidTubeFlow {
 public:
  explicit RigidTubeFlow(const full3d::Params3d& p)
      : p_(p), world_(p_), grid_(world_.grid()), mesh_(world_.mesh), stokes_(grid_, p_.fluid, world_.options.stokes) {}
  RigidTubeFlow(const RigidTubeFlow&) = delete;  // world_ refers to p_
  RigidTubeFlow& operator=(const RigidTubeFlow&) = delete;

  const MacGrid& grid() const { return grid_; }
  const Eigen::Matrix3Xd& nodes() const { return mesh_.X0; }

  struct Result {
    Eigen::Matrix3Xd F;             ///< node forces on the fluid, N
    VectorField u;                  ///< the flow, m/s
    int iterations = 0;
    double relative_residual = 0;   ///< of the kept iterate, in the space CG works in
    double max_slip_m_per_s = 0;    ///< max over the nodes of |u(X_i) - V_i|
    double max_fluid_speed_m_per_s = 0;
    /// b . x_k of the CG iterates up to the kept one: with x_0 = 0 it tends to b . A^-1 b (in
    /// exact arithmetic monotonically), and its last changes estimate the iterate's error.
    std::vector<double> work;
  };

  struct Cg {
    double rtol = 1e-3;
    int max_iterations = 400;
    /// Node forces restricted to the axisymmetric ones: on each ring an axial and a radial
    /// force density, F_i = (c_ax e_x + c_rad e_r,i) A_i, the constraint imposed on each ring's
    /// area-weighted mean axial and radial velocity. false: every node's force is free.
    bool axisymmetric = false;
  };

  // fb: nullptr for no body force. `what` names the solve in the error message.
  Result solve(const VectorField* fb, const Eigen::Matrix3Xd& V, const std::string& what, const Cg& cg) {
    const Eigen::Matrix3Xd& X = mesh_.X0;
    const Eigen::Index n3 = X.size();
    const int threads = p_.threads;
    const int nt = mesh_.n_theta, rings = mesh_.n_rings;
    // ring modes (B): the node forces e_i A_i / |A|_ring over one ring's nodes, e = e_x or e_r
    Eigen::Matrix3Xd er = Eigen::Matrix3Xd::Zero(3, X.cols());
    Eigen::VectorXd wnode = Eigen::VectorXd::Zero(X.cols());
    for (int g = 0; cg.axisymmetric && g < rings; ++g) {
      const double norm = mesh_.node_area.segment(g * nt, nt).norm();
      for (int i = g * nt; i < (g + 1) * nt; ++i) {
        const Eigen::Vector3d rel = X.col(i) - mesh_.axis_start;
        er.col(i) = Eigen::Vector3d(0.0, rel.y(), rel.z()).normalized();
        wnode[i] = mesh_.node_area[i] / norm;
      }
    }
    auto nodal = [&](const Eigen::VectorXd& x) -> Eigen::Matrix3Xd {
      if (!cg.axisymmetric) return Eigen::Map<const Eigen::Matrix3Xd>(x.data(), 3, X.cols());
      Eigen::Matrix3Xd F(3, X.cols());
      for (Eigen::Index i = 0; i < X.cols(); ++i) {
        const Eigen::Index g = i / nt;
        F.col(i) = wnode[i] * (x[2 * g] * Eigen::Vector3d::UnitX() + x[2 * g + 1] * er.col(i));
      }
      return F;
    };
    auto reduce = [&](const Eigen::Matrix3Xd& U) -> Eigen::VectorXd {
      if (!cg.axisymmetric) return Eigen::Map<const Eigen::VectorXd>(U.data(), n3);
      Eigen::VectorXd y = Eigen::VectorXd::Zero(2 * rings);
      for (Eigen::Index i = 0; i < X.cols(); ++i) {
        const Eigen::Index g = i / nt;
        y[2 * g] += wnode[i] * U(0, i);
        y[2 * g + 1] += wnode[i] * er.col(i).dot(U.col(i));
      }
      return y;
    };
    auto mobility = [&](const Eigen::VectorXd& x) {  // [B^T] J S^-1 spread([B] x)
      VectorField f(grid_);
      full3d::spread(grid_, X, nodal(x), f, threads);
      const VectorField u = stokes(f);
      Eigen::Matrix3Xd U;
      full3d::interpolate(grid_, u, X, U, threads);
      return reduce(U);
    };
    Eigen::Matrix3Xd bn = V;
    if (fb) {
      Eigen::Matrix3Xd Ub;
      full3d::interpolate(grid_, stokes(*fb), X, Ub, threads);
      bn -= Ub;
    }
    const Eigen::VectorXd b = reduce(bn);
    // CG on A x = b, A = [B^T] J S^-1 spread [B] (symmetric positive semi-definite: spreading
    // and interpolation are adjoint and S is symmetric).
    Eigen::VectorXd x = Eigen::VectorXd::Zero(b.size()), r = b, d = b;
    double rr = r.squaredNorm();
    const double bb = rr;
    // Node by node, the mobility has a near null space (node forces below the grid's
    // resolution), so CG stalls near a relative residual of 1e-3: stop at cg.rtol and keep
    // the best iterate.
    const double tol = cg.rtol * std::sqrt(bb);
    Eigen::VectorXd x_best = x;
    double rr_best = rr;
    Result out;
    std::vector<double> work = {0.0};
    std::size_t kept = 0;
    int it = 0;
    for (; it < cg.max_iterations && std::sqrt(rr) > tol; ++it) {
      const Eigen::VectorXd Ad = mobility(d);
      const double dAd = d.dot(Ad);
      if (!(dAd > 0)) break;
      const double alpha = rr / dAd;
      x += alpha * d;
      r -= alpha * Ad;
      const double rr_new = r.squaredNorm();
      d = r + (rr_new / rr) * d;
      rr = rr_new;
      work.push_back(b.dot(x));
      if (rr < rr_best) {
        rr_best = rr;
        x_best = x;
        kept = work.size() - 1;
      }
    }
    work.resize(kept + 1);
    out.work = std::move(work);
    out.F = nodal(x_best);
    out.iterations = it;
    out.relative_residual = bb > 0 ? std::sqrt(rr_best / bb) : 0.0;
    VectorField f = fb ? *fb : VectorField(grid_);
    full3d::spread_add(grid_, X, out.F, f, threads);
    out.u = stokes(f);
    Eigen::Matrix3Xd Un;
    full3d::interpolate(grid_, out.u, X, Un, threads);
    out.max_slip_m_per_s = (Un - V).colwise().norm().maxCoeff();
    out.max_fluid_speed_m_per_s = out.u.max_abs();
    // A solve that reached its tolerance and still leaves a node slipping: the slip is the
    // flow's part the forces cannot hold (on the ring forces, the non-axisymmetric part),
    // which grows as the grid coarsens. One that stopped short of it stalled.
    const bool converged = out.relative_residual <= cg.rtol;
    if (!(out.max_slip_m_per_s <= 1e-2 * out.max_fluid_speed_m_per_s))
      throw NumericalError("the " + what + " solve left the wall slipping at " + si(out.max_slip_m_per_s, "m/s") +
                               " against a flow of " + si(out.max_fluid_speed_m_per_s, "m/s") + " after " +
                               std::to_string(it) + " conjugate-gradient iterations" +
                               (converged ? " (converged: the grid does not resolve the wall)" : ""),
                           converged ? "refine full3d.grid.cells_across" : "coarsen full3d.grid.cells_across");
    return out;
  }

 private:
  VectorField stokes(const VectorField& f) {
    VectorField u(grid_);
    stokes_.step(u, f, kDt);
    return u;
  }
  static constexpr double kDt = 1e3;  // steady Stokes: rho h^2 / (mu dt) ~ 1e-13
  full3d::Params3d p_;
  full3d::World3d world_;  ///< the scene's mesh, grid and solver options
  MacGrid grid_;
  const full3d::CylinderMesh& mesh_;
  full3d::StokesSolver stokes_;
};

// The solve on the ring modes: it converges, so to a tight tolerance.
const RigidTubeFlow::Cg kRingCg{1e-6, 400, true};

}  // namespace

HydraulicRadii measure_hydraulic_radii(const full3d::Params3d& scene, bool axisymmetric_forces) {
  const auto t0 = std::chrono::steady_clock::now();
  const full3d::Params3d p = in_cylinder(scene);
  RigidTubeFlow flow(p);
  const MacGrid& grid = flow.grid();
  const double Rc = p.container_radius, R0 = p.R0, h = p.h, mu = p.fluid.mu;

  HydraulicRadii out;
  out.body_force_N_per_m3 = 4.0 * mu * 1e-6 / (Rc * Rc);  // centreline speed ~ 1 um/s
  VectorField fb(grid);
  std::fill(fb.c[0].begin(), fb.c[0].end(), out.body_force_N_per_m3);
  // the profiles, on the axial-velocity planes near the tube's middle: a grid on which the
  // lumen fit cannot be made is refused before the solve (on such a grid the held tube's
  // nodes also slip by more than the solve's check allows: the flow's non-axisymmetric part,
  // which the ring forces do not hold, grows as the lumen spans fewer cells)
  const Eigen::Vector3d a0 = p.axis_start();
  const double xc = a0.x() + 0.5 * p.L;
  const int ic = int(std::lround(xc / h));
  const int half = std::max(0, std::min(2, int((0.5 * p.L) / h) - 4));
  require_lumen_radii(plane_samples(grid, VectorField(grid), ic, a0, R0, Rc).lumen);
  // held tube: zero velocity at every node. A wall slip of 1e-3 of the flow (where CG stalls)
  // moves the fitted radii by far less than their uncertainty.
  const RigidTubeFlow::Result held = flow.solve(&fb, Eigen::Matrix3Xd::Zero(3, flow.nodes().cols()), "held-tube",
                 axisymmetric_forces ? kRingCg : RigidTubeFlow::Cg{});
  const VectorField& u = held.u;
  out.cg_iterations = held.iterations;
  out.holding_force_N = held.F.row(0).sum();
  out.max_node_speed_m_per_s = held.max_slip_m_per_s;
  out.max_fluid_speed_m_per_s = held.max_fluid_speed_m_per_s;

  std::vector<double> a_in, a_out, rc_eff, se_in, se_out;
  double flux_mid = 0, q_pois = 0;
  for (int i = ic - half; i <= ic + half; ++i) {
    const auto [lumen, annulus, flux] = plane_samples(grid, u, i, a0, R0, Rc);
    double c1 = 0;
    const RootFit fin = lumen_fit(lumen, &c1);
    const auto [fout, fwall] = annulus_fit(annulus, R0, Rc, h);
    a_in.push_back(R0 - fin.root);
    se_in.push_back(fin.stderr_root);
    a_out.push_back(fout.root - R0);
    se_out.push_back(fout.stderr_root);
    rc_eff.push_back(fwall.root);
    if (i == ic) {
      flux_mid = flux;
      const double G = 4.0 * mu * c1;
      q_pois = M_PI * std::pow(fin.root, 4) * G / (8.0 * mu);
    }
  }
  out.planes = int(a_in.size());
  out.a_in_m = mean(a_in);
  out.a_out_m = mean(a_out);
  out.a_in_uncertainty_m = std::hypot(sample_std(a_in), mean(se_in));
  out.a_out_uncertainty_m = std::hypot(sample_std(a_out), mean(se_out));
  out.container_radius_effective_m = mean(rc_eff);
  out.lumen_flux_m3_per_s = flux_mid;
  out.lumen_flux_poiseuille_m3_per_s = q_pois;
  out.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

scene::json to_json(const HydraulicRadii& h) {
  return {{"hydraulic_offset_inner_m", h.a_in_m},
          {"hydraulic_offset_inner_uncertainty_m", h.a_in_uncertainty_m},
          {"hydraulic_offset_outer_m", h.a_out_m},
          {"hydraulic_offset_outer_uncertainty_m", h.a_out_uncertainty_m},
          {"container_radius_effective_m", h.container_radius_effective_m},
          {"lumen_flux_m3_per_s", h.lumen_flux_m3_per_s},
          {"lumen_flux_poiseuille_fit_m3_per_s", h.lumen_flux_poiseuille_m3_per_s},
          {"body_force_N_per_m3", h.body_force_N_per_m3},
          {"held_tube_force_N", h.holding_force_N},
          {"held_wall_max_speed_m_per_s", h.max_node_speed_m_per_s},
          {"max_fluid_speed_m_per_s", h.max_fluid_speed_m_per_s},
          {"conjugate_gradient_iterations", h.cg_iterations},
          {"planes", h.planes},
          {"wall_time_s", h.wall_time_s},
          {"method",
           "undeformed tube held rigid (conjugate gradients on the node forces) in body-force-driven steady Stokes "
           "flow through the scene's container (a duct by its inscribed cylinder); Poiseuille fits of the lumen and "
           "annulus profiles on the planes near the tube's middle"}};
}

}  // namespace swim::validation

namespace swim::validation {

ConfinedTow confined_tow(const full3d::Params3d& scene) {
  const full3d::Params3d p = in_cylinder(scene);
  return {p.R0, p.L, p.container_radius, p.period, p.fluid.mu};
}

double confined_drag(const ConfinedTow& g, double a_in_m, double a_out_m) {
  return reduced1d::outer::confined_drag_coefficient(g.radius_m, g.length_m, a_in_m, a_out_m, g.container_radius_m,
                                                     g.period_m, g.viscosity_Pa_s);
}

double confined_tow_flux_per_speed(const ConfinedTow& g, double a_in_m, double a_out_m) {
  reduced1d::outer::ConfinedSystem sys(2, {g.length_m}, g.viscosity_Pa_s, a_in_m, a_out_m, g.container_radius_m,
                                       g.period_m, g.length_m);
  const double R[2] = {g.radius_m, g.radius_m};
  if (!sys.geometry(R)) return 0.0;
  const double Pi[2] = {0.0, 0.0};
  sys.transmural(Pi);
  return -sys.M[0][1] / sys.M[0][0];  // periodicity row at zero towing pressure: W = -M12 U / M11
}

TowedTube measure_towed_tube(const full3d::Params3d& scene, double speed) {
  if (!(speed != 0.0) || !std::isfinite(speed))
    throw InputError("towed-tube speed", std::to_string(speed), "a finite, nonzero speed in m/s");
  const auto t0 = std::chrono::steady_clock::now();
  const full3d::Params3d p = in_cylinder(scene);
  RigidTubeFlow flow(p);
  const MacGrid& grid = flow.grid();
  Eigen::Matrix3Xd V = Eigen::Matrix3Xd::Zero(3, flow.nodes().cols());
  V.row(0).setConstant(speed);
  // The axisymmetric node forces: node by node, the non-axisymmetric modes finer than the grid
  // form a near null space in which CG keeps adding forces (and dissipation) without
  // converging.
  const RigidTubeFlow::Result tow = flow.solve(nullptr, V, "towed-tube", kRingCg);

  TowedTube out;
  out.geometry = confined_tow(scene);
  out.speed_m_per_s = speed;
  out.force_N = tow.F.row(0).sum();
  out.drag_coefficient_N_s_per_m = out.force_N / speed;
  const std::size_t k = tow.work.size() - 1;  // the kept iterate
  const std::size_t back = std::max<std::size_t>(1, k / 10);
  out.drag_coefficient_uncertainty_N_s_per_m = k >= back ? std::abs(tow.work[k] - tow.work[k - back]) / (speed * speed) : 0.0;
  out.max_slip_m_per_s = tow.max_slip_m_per_s;
  out.max_fluid_speed_m_per_s = tow.max_fluid_speed_m_per_s;
  out.cg_relative_residual = tow.relative_residual;
  out.cg_iterations = tow.iterations;
  // net flux through the container's cross-section half a period from the tube's middle
  const int nx = grid.nx();
  const int ic = int(std::lround((p.axis_start().x() + 0.5 * p.L) / p.h));
  const int ifar = ((ic + nx / 2) % nx + nx) % nx;
  const auto d0 = grid.dims(0);
  double q = 0;
  for (int kk = 0; kk < d0[2]; ++kk)
    for (int j = 0; j < d0[1]; ++j) q += tow.u.c[0][MacGrid::index(d0, ifar, j, kk)];
  out.net_flux_m3_per_s = q * p.h * p.h;
  out.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

double outer_offset_from_drag(const ConfinedTow& g, double zeta, double a_in) {
  const double R0 = g.radius_m, Rc = g.container_radius_m;
  if (!(a_in >= 0 && a_in < R0))
    throw InputError("inner hydraulic offset", si(a_in, "m"), "0 <= a_in < the tube radius " + si(R0, "m"));
  if (!(zeta > 0) || !std::isfinite(zeta))
    throw NumericalError("the towed tube's drag coefficient " + std::to_string(zeta) + " N s/m is not positive",
                         "check the towed-tube solve");
  // the 1D tier's bounds: a_out >= 0 and R0 + a_out < 0.999 Rc (solver.cpp, ConfinedSystem::geometry)
  const double lo = 0.0, hi = (1.0 - 1e-9) * ((1.0 - 1e-3) * Rc - R0);
  if (!(hi > lo))
    throw InputError("container radius", si(Rc, "m"), "larger than the tube radius " + si(R0, "m"));
  auto f = [&](double a_out) { return confined_drag(g, a_in, a_out) - zeta; };
  const double f_lo = f(lo), f_hi = f(hi);
  if (f_lo > 0)
    throw NumericalError("the towed tube's drag coefficient " + si(zeta, "N s/m", 4) +
                             " is below the 1D confined drag of the tube without outer offset (" +
                             si(f_lo + zeta, "N s/m", 4) + " at a_in = " + si(a_in, "m") +
                             "): no a_out >= 0 reproduces it",
                         "the 3D flow's end effects or the container's effective radius exceed the offset; "
                         "refine full3d.grid.cells_across");
  if (f_hi < 0)
    throw NumericalError("the towed tube's drag coefficient " + si(zeta, "N s/m", 4) +
                             " exceeds the 1D confined drag of a tube touching the container (" +
                             si(f_hi + zeta, "N s/m", 4) + "): no a_out reproduces it",
                         "check the towed-tube solve");
  return bracketed_root(f, lo, hi);
}

OuterOffsetFromDrag outer_offset_from_drag(const ConfinedTow& g, double zeta, double zeta_unc, double a_in,
                                           double a_in_unc) {
  OuterOffsetFromDrag r;
  r.a_in_m = a_in;
  r.container_radius_m = g.container_radius_m;
  try {
    r.a_out_m = outer_offset_from_drag(g, zeta, a_in);
    // derivatives of the root by the implicit function theorem, with the partial derivatives
    // of the 1D drag by central differences (steps of 1e-4 R0: small against the
    // uncertainties, large against round-off)
    const double d = 1e-4 * g.radius_m, a_out = r.a_out_m;
    const double dz_dout = (confined_drag(g, a_in, a_out + d) - confined_drag(g, a_in, a_out - d)) / (2 * d);
    const double dz_din = (confined_drag(g, a_in + d, a_out) - confined_drag(g, a_in - d, a_out)) / (2 * d);
    const double dadz = 1.0 / dz_dout, dada = -dz_din / dz_dout;
    r.from_drag_m = std::abs(dadz) * zeta_unc;
    r.from_a_in_m = std::abs(dada) * a_in_unc;
    r.uncertainty_m = std::hypot(r.from_drag_m, r.from_a_in_m);
    r.found = true;
  } catch (const NumericalError& e) {
    r = OuterOffsetFromDrag{};
    r.a_in_m = a_in;
    r.container_radius_m = g.container_radius_m;
    r.note = e.what();
  }
  return r;
}

scene::json to_json(const TowedTube& t, const OuterOffsetFromDrag& a, const OuterOffsetFromDrag* at_effective_container) {
  scene::json j = scene::json::object();
  j["hydraulic_offset_outer_from_drag_m"] = a.found ? scene::json(a.a_out_m) : scene::json(nullptr);
  j["hydraulic_offset_outer_from_drag_uncertainty_m"] = a.found ? scene::json(a.uncertainty_m) : scene::json(nullptr);
  j["towed_drag_coefficient_N_s_per_m"] = t.drag_coefficient_N_s_per_m;
  scene::json d = {
      {"speed_m_per_s", t.speed_m_per_s},
      {"force_N", t.force_N},
      {"drag_coefficient_N_s_per_m", t.drag_coefficient_N_s_per_m},
      {"drag_coefficient_uncertainty_N_s_per_m", t.drag_coefficient_uncertainty_N_s_per_m},
      {"net_flux_m3_per_s", t.net_flux_m3_per_s},
      {"towed_wall_max_slip_m_per_s", t.max_slip_m_per_s},
      {"max_fluid_speed_m_per_s", t.max_fluid_speed_m_per_s},
      {"conjugate_gradient_iterations", t.cg_iterations},
      {"conjugate_gradient_relative_residual", t.cg_relative_residual},
      {"wall_time_s", t.wall_time_s},
      {"radius_m", t.geometry.radius_m},
      {"length_m", t.geometry.length_m},
      {"container_radius_m", t.geometry.container_radius_m},
      {"period_m", t.geometry.period_m},
      {"viscosity_Pa_s", t.geometry.viscosity_Pa_s},
      {"method",
       "undeformed tube towed rigidly along its axis through the scene's container (a duct by its inscribed "
       "cylinder) in steady Stokes flow, pressure periodic (zero mean pressure gradient, net flux free); "
       "axisymmetric node forces (axial and radial per ring) by conjugate gradients on the rings' mean velocities; "
       "a_out is the root of the 1D confined drag coefficient (reduced1d::outer::confined_drag_coefficient) at the "
       "profile-fitted a_in and the nominal container radius"}};
  d["hydraulic_offset_inner_used_m"] = a.a_in_m;
  if (a.found) {
    d["a_out_uncertainty_from_a_in_m"] = a.from_a_in_m;
    d["a_out_uncertainty_from_drag_m"] = a.from_drag_m;
    d["net_flux_1d_m3_per_s"] = confined_tow_flux_per_speed(t.geometry, a.a_in_m, a.a_out_m) * t.speed_m_per_s;
  } else {
    d["no_offset_reason"] = a.note;
  }
  if (at_effective_container) {
    const OuterOffsetFromDrag& e = *at_effective_container;
    scene::json s = {{"container_radius_m", e.container_radius_m}};
    s["hydraulic_offset_outer_from_drag_m"] = e.found ? scene::json(e.a_out_m) : scene::json(nullptr);
    s["hydraulic_offset_outer_from_drag_uncertainty_m"] = e.found ? scene::json(e.uncertainty_m) : scene::json(nullptr);
    if (!e.found) s["no_offset_reason"] = e.note;
    d["at_effective_container_radius"] = s;
  }
  j["towed_tube"] = d;
  return j;
}

TowedCalibration calibrate_towed(const full3d::Params3d& p, const HydraulicRadii& hr) {
  TowedCalibration c;
  try {
    c.tube = measure_towed_tube(p);
  } catch (const NumericalError& e) {
    c.error = e.what();
    c.json = {{"hydraulic_offset_outer_from_drag_m", nullptr},
              {"hydraulic_offset_outer_from_drag_uncertainty_m", nullptr},
              {"towed_drag_coefficient_N_s_per_m", nullptr},
              {"towed_tube", {{"status", "failed: " + c.error}}}};
    return c;
  }
  c.measured = true;
  const TowedTube& t = c.tube;
  c.nominal = outer_offset_from_drag(t.geometry, t.drag_coefficient_N_s_per_m, t.drag_coefficient_uncertainty_N_s_per_m,
                                     hr.a_in_m, hr.a_in_uncertainty_m);
  ConfinedTow eff = t.geometry;
  eff.container_radius_m = hr.container_radius_effective_m;
  c.effective = outer_offset_from_drag(eff, t.drag_coefficient_N_s_per_m, t.drag_coefficient_uncertainty_N_s_per_m,
                                       hr.a_in_m, hr.a_in_uncertainty_m);
  c.json = to_json(t, c.nominal, &c.effective);
  c.json["towed_tube"]["status"] = "ok";
  return c;
}

}  // namespace swim::validation
