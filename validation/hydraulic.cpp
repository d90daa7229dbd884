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
#include "full3d/run3d.hpp"
#include "full3d/stokes.hpp"
#include "validation/richardson.hpp"

namespace swim::validation {

namespace {

using full3d::MacGrid;
using full3d::VectorField;

double dot(const Eigen::Matrix3Xd& a, const Eigen::Matrix3Xd& b) { return a.cwiseProduct(b).sum(); }

struct Sample {
  double r, u;
};

struct RootFit {
  double root = 0, stderr_root = 0;
};

// u = c0 + s r^2 on the lumen samples; the zero a = sqrt(-c0 / s) and its standard error.
RootFit lumen_fit(const std::vector<Sample>& pts, double* c1_out) {
  std::vector<double> x, y;
  for (const auto& s : pts) {
    x.push_back(s.r * s.r);
    y.push_back(s.u);
  }
  std::vector<double> radii = x;
  std::sort(radii.begin(), radii.end());
  const auto distinct = std::unique(radii.begin(), radii.end(), [](double a, double b) { return std::abs(a - b) <= 1e-9 * b; }) - radii.begin();
  if (distinct < 3)
    throw NumericalError("too few distinct radii (" + std::to_string(distinct) + ") among the lumen velocity samples for the Poiseuille fit",
                         "refine full3d.grid.cells_across (the lumen needs r < R0 - 2h)");
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

double mean(const std::vector<double>& v) { return gsl_stats_mean(v.data(), 1, v.size()); }
double sample_std(const std::vector<double>& v) { return v.size() < 2 ? 0.0 : gsl_stats_sd(v.data(), 1, v.size()); }

}  // namespace

HydraulicRadii measure_hydraulic_radii(const full3d::Params3d& scene) {
  const auto t0 = std::chrono::steady_clock::now();
  full3d::Params3d p = scene;
  if (p.container != "cylinder") {  // the inscribed cylinder of the duct (or box)
    p.container = "cylinder";
    p.ny += 2;
    p.nz += 2;
  }
  const MacGrid grid(p.nx, p.ny, p.nz, p.h, p.container_kind());
  const full3d::CylinderMesh mesh = full3d::make_mesh(p);
  const full3d::IbOptions opt = full3d::ib_options(p);
  full3d::StokesSolver stokes(grid, p.fluid, opt.stokes);
  const double dt = 1e3;  // steady Stokes: rho h^2 / (mu dt) ~ 1e-13
  const double Rc = p.container_radius, R0 = p.R0, h = p.h, mu = p.fluid.mu;
  const Eigen::Matrix3Xd& X = mesh.X0;
  const int threads = p.threads;

  HydraulicRadii out;
  out.body_force_N_per_m3 = 4.0 * mu * 1e-6 / (Rc * Rc);  // centreline speed ~ 1 um/s
  VectorField fb(grid);
  std::fill(fb.c[0].begin(), fb.c[0].end(), out.body_force_N_per_m3);

  auto solve = [&](const VectorField& f) {
    VectorField u(grid);
    stokes.step(u, f, dt);
    return u;
  };
  auto mobility = [&](const Eigen::Matrix3Xd& F) {  // J S^-1 spread(F)
    VectorField f(grid);
    full3d::spread(grid, X, F, f, threads);
    const VectorField u = solve(f);
    Eigen::Matrix3Xd U;
    full3d::interpolate(grid, u, X, U, threads);
    return U;
  };
  // held tube: J S^-1 (fb + spread F) = 0, by conjugate gradients on F
  Eigen::Matrix3Xd Ub;
  full3d::interpolate(grid, solve(fb), X, Ub, threads);
  const Eigen::Matrix3Xd b = -Ub;
  Eigen::Matrix3Xd F = Eigen::Matrix3Xd::Zero(3, X.cols()), r = b, d = b;
  double rr = dot(r, r);
  // The mobility has a near null space (node forces below the grid's resolution), so CG
  // stalls near a relative residual of 1e-3: stop there and keep the best iterate. A wall
  // slip of 1e-3 of the flow moves the fitted radii by far less than their uncertainty.
  const double tol = 1e-3 * std::sqrt(dot(b, b));
  Eigen::Matrix3Xd F_best = F;
  double rr_best = rr;
  int it = 0;
  for (; it < 400 && std::sqrt(rr) > tol; ++it) {
    const Eigen::Matrix3Xd Ad = mobility(d);
    const double dAd = dot(d, Ad);
    if (!(dAd > 0)) break;
    const double alpha = rr / dAd;
    F += alpha * d;
    r -= alpha * Ad;
    const double rr_new = dot(r, r);
    d = r + (rr_new / rr) * d;
    rr = rr_new;
    if (rr < rr_best) {
      rr_best = rr;
      F_best = F;
    }
  }
  F = F_best;
  out.cg_iterations = it;
  VectorField f = fb;
  full3d::spread_add(grid, X, F, f, threads);
  const VectorField u = solve(f);
  Eigen::Matrix3Xd Un;
  full3d::interpolate(grid, u, X, Un, threads);
  out.max_node_speed_m_per_s = Un.colwise().norm().maxCoeff();
  out.max_fluid_speed_m_per_s = u.max_abs();
  if (!(out.max_node_speed_m_per_s <= 1e-2 * out.max_fluid_speed_m_per_s))
    throw NumericalError("the held-tube solve left the wall moving at " + si(out.max_node_speed_m_per_s, "m/s") +
                             " against a flow of " + si(out.max_fluid_speed_m_per_s, "m/s") + " after " +
                             std::to_string(it) + " conjugate-gradient iterations",
                         "coarsen full3d.grid.cells_across");

  // profiles on the axial-velocity planes near the tube's middle
  const Eigen::Vector3d a0 = p.axis_start();
  const double xc = a0.x() + 0.5 * p.L;
  const int ic = int(std::lround(xc / h));
  const int half = std::max(0, std::min(2, int((0.5 * p.L) / h) - 4));
  const auto d0 = grid.dims(0);
  std::vector<double> a_in, a_out, rc_eff, se_in, se_out;
  double flux_mid = 0, q_pois = 0;
  for (int i = ic - half; i <= ic + half; ++i) {
    std::vector<Sample> lumen, annulus;
    double flux = 0;
    for (int k = 0; k < d0[2]; ++k)
      for (int j = 0; j < d0[1]; ++j) {
        const auto pos = grid.position(0, i, j, k);
        const double rad = std::hypot(pos[1] - a0.y(), pos[2] - a0.z());
        const double ux = u.c[0][MacGrid::index(d0, i, j, k)];
        if (rad < R0) flux += ux * h * h;
        if (rad < R0 - 2.0 * h) lumen.push_back({rad, ux});
        if (rad > R0 + 2.0 * h && rad < Rc - h) annulus.push_back({rad, ux});
      }
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
