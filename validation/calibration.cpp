#include "validation/calibration.hpp"

#include <gsl/gsl_fit.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cmath>

#include "common/errors.hpp"
#include "full3d/grid.hpp"
#include "full3d/ib_solver.hpp"
#include "full3d/membrane.hpp"
#include "full3d/run3d.hpp"

namespace swim::validation {

namespace {
// Gradient of the loaded energy E(Y) + P sum A_i r_i(Y): -F_el + P A_i e_r,i.
Eigen::Matrix3Xd loaded_gradient(const full3d::CylinderMesh& mesh, const full3d::MembraneParams& p, double pressure,
                                 const Eigen::Matrix3Xd& Y) {
  Eigen::Matrix3Xd g = -full3d::elastic_forces(mesh, Y, p);
  const Eigen::Matrix3Xd e = full3d::radial_directions(mesh, Y);
  for (Eigen::Index i = 0; i < Y.cols(); ++i) g.col(i) += pressure * mesh.node_area[i] * e.col(i);
  return g;
}

// d^2/ds^2 of E(X + sV) + P sum A_i r_i(X + sV) for the unit ring modes V_i ~ cos(n phi_i) e_r,i,
// n = 2 .. n_theta/2 (see the scan below), by central differences of the exact gradient: V . (g(X + sV) - g(X - sV)) / (2 s).
// (Modes with an axial variation cos(k pi x / L) are stiffer than k = 0 on the paper's tube.)
std::vector<double> ring_mode_stiffness(const full3d::CylinderMesh& mesh, const full3d::MembraneParams& p,
                                        double pressure, const Eigen::Matrix3Xd& X) {
  const Eigen::Matrix3Xd er = full3d::radial_directions(mesh, X);
  auto grad = [&](const Eigen::Matrix3Xd& Y) { return loaded_gradient(mesh, p, pressure, Y); };
  const double s = 1e-4 * mesh.rest_length.minCoeff();
  // the stiffness grows as n^4 past its minimum: scan n = 2..32, and further only while the
  // softest mode is the last one scanned
  std::vector<double> k;
  for (int n = 2; n <= mesh.n_theta / 2; ++n) {
    if (n > 32 && std::min_element(k.begin(), k.end()) != k.end() - 1) break;
    Eigen::Matrix3Xd V(3, X.cols());
    for (Eigen::Index i = 0; i < X.cols(); ++i) V.col(i) = std::cos(n * std::atan2(er(2, i), er(1, i))) * er.col(i);
    V /= V.norm();
    k.push_back(V.cwiseProduct(grad(X + s * V) - grad(X - s * V)).sum() / (2.0 * s));
  }
  return k;
}
// Smallest eigenvalue of the Hessian of the loaded energy at X, without the two free rigid
// motions (axial translation, rotation about the axis): Lanczos with full reorthogonalisation
// on Hessian-vector products (central differences of the exact gradient), from a fixed
// pseudo-random start. Ritz values bound the spectrum from inside, so a negative result proves
// the equilibrium unstable; a positive one is the best estimate after `iterations` products.
double lowest_hessian_eigenvalue(const full3d::CylinderMesh& mesh, const full3d::MembraneParams& p, double pressure,
                                 const Eigen::Matrix3Xd& X, int iterations) {
  const Eigen::Index n = X.size();
  auto grad = [&](const Eigen::Matrix3Xd& Y) { return loaded_gradient(mesh, p, pressure, Y); };
  const double s = 1e-4 * mesh.rest_length.minCoeff();
  auto hess = [&](const Eigen::VectorXd& v) {
    const Eigen::Map<const Eigen::Matrix3Xd> V(v.data(), 3, X.cols());
    const Eigen::Matrix3Xd d = (grad(X + s * V) - grad(X - s * V)) / (2.0 * s);
    return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(d.data(), n));
  };
  // rigid modes: translation along x, rotation about the axis
  Eigen::MatrixXd rigid = Eigen::MatrixXd::Zero(n, 2);
  for (Eigen::Index i = 0; i < X.cols(); ++i) {
    rigid(3 * i, 0) = 1.0;
    rigid(3 * i + 1, 1) = -(X(2, i) - mesh.axis_start.z());
    rigid(3 * i + 2, 1) = X(1, i) - mesh.axis_start.y();
  }
  rigid.col(0).normalize();
  rigid.col(1) -= rigid.col(0).dot(rigid.col(1)) * rigid.col(0);
  rigid.col(1).normalize();
  const int m = std::min<int>(iterations, int(n) - 2);
  Eigen::MatrixXd Q(n, m + 1);
  Eigen::VectorXd alpha(m), beta(m);
  Eigen::VectorXd q(n);
  std::uint64_t r = 0x2545F4914F6CDD1Dull;
  for (Eigen::Index i = 0; i < n; ++i) {
    r = r * 6364136223846793005ull + 1442695040888963407ull;
    q[i] = double(r >> 11) / 9007199254740992.0 - 0.5;
  }
  q -= rigid * (rigid.transpose() * q);
  q.normalize();
  Q.col(0) = q;
  int k = 0;
  for (; k < m; ++k) {
    Eigen::VectorXd w = hess(Q.col(k));
    alpha[k] = Q.col(k).dot(w);
    // full reorthogonalisation (twice) against the basis and the rigid modes
    for (int pass = 0; pass < 2; ++pass) {
      w -= Q.leftCols(k + 1) * (Q.leftCols(k + 1).transpose() * w);
      w -= rigid * (rigid.transpose() * w);
    }
    beta[k] = w.norm();
    if (beta[k] <= 1e-14 * std::abs(alpha[k])) {
      ++k;
      break;
    }
    Q.col(k + 1) = w / beta[k];
  }
  Eigen::MatrixXd T = Eigen::MatrixXd::Zero(k, k);
  for (int i = 0; i < k; ++i) {
    T(i, i) = alpha[i];
    if (i + 1 < k) T(i, i + 1) = T(i + 1, i) = beta[i];
  }
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(T, Eigen::EigenvaluesOnly).eigenvalues()[0];
}

}  // namespace

std::vector<double> default_loads(const full3d::Params3d& p) {
  const double q_static = p.c1_estimate() * (p.R0 - p.protocol.R_f);
  std::vector<double> out;
  for (double f : {0.01, 0.02, 0.03, 0.05, 0.075, 0.1, 0.15, 0.2, 0.35, 0.5, 0.75, 1.0, 1.5}) out.push_back(f * q_static);
  return out;
}

StaticCalibration calibrate_static(const full3d::Params3d& p, const std::vector<double>& pressures,
                                   const std::function<void(std::size_t)>& on_load) {
  StaticCalibration c;
  const full3d::CylinderMesh mesh = full3d::make_mesh(p);
  c.n_theta = mesh.n_theta;
  c.n_rings = mesh.n_rings;
  c.nodes = int(mesh.X0.cols());
  c.spring_network_c1 = p.c1_estimate();
  std::vector<double> P = pressures;
  std::sort(P.begin(), P.end());
  for (double pr : P) {
    if (!(pr > 0) || !std::isfinite(pr))
      throw InputError("calibration load", std::to_string(pr), "every load must be a positive pressure");
    full3d::PressureResponse r;
    try {
      r = full3d::relax_under_pressure(mesh, p.membrane, pr);
    } catch (const NumericalError& e) {
      // loads are tried in increasing order: the first one without a static state ends the
      // series (the larger ones would not reach one either); three points still fit C1
      if (c.loads.size() < 3) throw;
      c.no_static_state_from_Pa = pr;
      c.no_static_state_reason = e.what();
      break;
    }
    LoadPoint lp;
    lp.pressure_Pa = pr;
    lp.displacement_m = p.R0 - r.mid_radius;
    lp.secant_C1_Pa_per_m = r.c1;
    lp.iterations = r.iterations;
    lp.ring_mode_stiffness_N_per_m = ring_mode_stiffness(mesh, p.membrane, pr, r.X);
    const auto& k = lp.ring_mode_stiffness_N_per_m;
    const auto soft = std::min_element(k.begin(), k.end());
    lp.softest_ring_mode = int(soft - k.begin()) + 2;
    lp.softest_ring_mode_stiffness_N_per_m = *soft;
    lp.lowest_eigenvalue_N_per_m = lowest_hessian_eigenvalue(mesh, p.membrane, pr, r.X, 150);
    c.loads.push_back(lp);
    if (on_load) on_load(c.loads.size());
  }
  // linear range: secant within 1 % of the smallest load's
  const double c_small = c.loads.front().secant_C1_Pa_per_m;
  std::vector<double> x, y;
  c.fit.linear_over_all_loads = true;
  for (auto& lp : c.loads) {
    lp.in_linear_range = std::abs(lp.secant_C1_Pa_per_m / c_small - 1.0) <= 0.01;
    if (!lp.in_linear_range) c.fit.linear_over_all_loads = false;
    if (!lp.in_linear_range || !lp.stable()) continue;
    x.push_back(lp.displacement_m);
    y.push_back(lp.pressure_Pa);
    c.fit.linear_up_to_Pa = lp.pressure_Pa;
  }
  const int n = int(x.size());
  c.fit.points = n;
  if (n < 1)
    throw NumericalError("none of " + std::to_string(c.loads.size()) +
                             " calibration loads is linear and stable to ring buckling; no C1 fit",
                         "lower protocol.pressure or raise full3d.membrane.bending_constant");
  double ymean = 0;
  for (double v : y) ymean += v / n;
  double sstot = 0;
  for (double v : y) sstot += (v - ymean) * (v - ymean);
  {
    double c1, cov, sumsq;
    gsl_fit_mul(x.data(), 1, y.data(), 1, std::size_t(n), &c1, &cov, &sumsq);
    c.fit.c1 = c1;
    c.fit.c1_stderr = std::sqrt(cov);
    c.fit.r2 = sstot > 0 ? 1.0 - sumsq / sstot : 1.0;
  }
  if (n >= 3) {
    double c0, c1, cov00, cov01, cov11, sumsq;
    gsl_fit_linear(x.data(), 1, y.data(), 1, std::size_t(n), &c0, &c1, &cov00, &cov01, &cov11, &sumsq);
    c.fit.intercept = c0;
    c.fit.slope = c1;
    c.fit.intercept_stderr = std::sqrt(cov00);
    c.fit.slope_stderr = std::sqrt(cov11);
    c.fit.r2_linear = sstot > 0 ? 1.0 - sumsq / sstot : 1.0;
  }
  return c;
}

WetConfirmation confirm_wet(const full3d::Params3d& p, double pressure, double static_displacement_m,
                            bool axisymmetric_wall) {
  const auto t0 = std::chrono::steady_clock::now();
  const full3d::MacGrid grid(p.nx, p.ny, p.nz, p.h, p.container_kind());
  const full3d::CylinderMesh mesh = full3d::make_mesh(p);
  full3d::IbOptions opt = full3d::ib_options(p);
  opt.dt_key = "full3d.dt";
  opt.axisymmetric_wall = axisymmetric_wall;
  full3d::IbSolver ib(grid, p.fluid, mesh, p.membrane, Eigen::VectorXd::Zero(mesh.nodes()), opt);
  const Eigen::VectorXd area = mesh.node_area;
  ib.set_external_force([&](double, const Eigen::Matrix3Xd& X) {
    Eigen::Matrix3Xd F = full3d::radial_directions(mesh, X);
    for (Eigen::Index i = 0; i < X.cols(); ++i) F.col(i) *= -pressure * area[i];
    return F;
  });
  full3d::IbState s = ib.initial_state();
  // half the explicit stability limit dt lambda_max < 2, from the undeformed and from a
  // contracted state (the rate grows as the tube contracts)
  double dt = std::min(p.dt, 1.0 / ib.explicit_rate(s, p.dt));
  const int r0 = (mesh.n_rings - 1) / 2, r1 = mesh.n_rings / 2;
  auto delta = [&](const full3d::IbState& st) {
    const Eigen::VectorXd rr = full3d::ring_radii(mesh, st.X);
    return mesh.radius - 0.5 * (rr[r0] + rr[r1]);
  };
  WetConfirmation w;
  w.axisymmetric_wall = axisymmetric_wall;
  w.pressure_Pa = pressure;
  w.static_displacement_m = static_displacement_m;
  std::vector<double> t_hist, d_hist;
  int steps = 0;
  for (; steps < 4000; ++steps) {
    if (steps == 50) dt = std::min(dt, 1.0 / ib.explicit_rate(s, dt));
    ib.step(s, dt);
    t_hist.push_back(s.t);
    d_hist.push_back(delta(s));
    if (steps >= 100) {
      // the displacement a tenth of the elapsed time ago
      const auto it = std::upper_bound(t_hist.begin(), t_hist.end(), 0.9 * s.t);
      const std::size_t k = std::size_t(std::max<std::ptrdiff_t>(0, (it - t_hist.begin()) - 1));
      if (std::abs(d_hist.back() - d_hist[k]) < 1e-3 * std::abs(d_hist.back())) {
        w.steady = true;
        ++steps;
        break;
      }
    }
  }
  w.steps = steps;
  w.dt_s = dt;
  w.simulated_time_s = s.t;
  w.displacement_m = d_hist.back();
  w.relative_difference = w.displacement_m / static_displacement_m - 1.0;
  w.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return w;
}

scene::json to_json(const StaticCalibration& c, const full3d::Params3d& p, const scene::json& resolved) {
  scene::json pts = scene::json::array();
  for (const auto& lp : c.loads)
    pts.push_back({{"pressure_Pa", lp.pressure_Pa},
                   {"displacement_m", lp.displacement_m},
                   {"secant_C1_Pa_per_m", lp.secant_C1_Pa_per_m},
                   {"in_linear_range", lp.in_linear_range},
                   {"ring_mode_stiffness_N_per_m", lp.ring_mode_stiffness_N_per_m},
                   {"softest_ring_mode", lp.softest_ring_mode},
                   {"softest_ring_mode_stiffness_N_per_m", lp.softest_ring_mode_stiffness_N_per_m},
                   {"lowest_hessian_eigenvalue_N_per_m", lp.lowest_eigenvalue_N_per_m},
                   {"stable_to_ring_buckling", lp.stable()},
                   {"iterations", lp.iterations}});
  scene::json j = scene::json::object();
  j["C1_Pa_per_m"] = c.fit.c1;
  j["C1_stderr_Pa_per_m"] = c.fit.c1_stderr;
  j["C1_r2"] = c.fit.r2;
  j["C1_with_intercept"] = {{"slope_Pa_per_m", c.fit.slope},
                            {"slope_stderr_Pa_per_m", c.fit.slope_stderr},
                            {"intercept_Pa", c.fit.intercept},
                            {"intercept_stderr_Pa", c.fit.intercept_stderr},
                            {"r2", c.fit.r2_linear}};
  j["linear_within_1_percent_up_to_Pa"] = c.fit.linear_up_to_Pa;
  j["linear_over_all_loads"] = c.fit.linear_over_all_loads;
  j["fit_points"] = c.fit.points;
  j["load_points"] = pts;
  if (c.no_static_state_from_Pa > 0)
    j["loads_without_static_state"] = {{"from_Pa", c.no_static_state_from_Pa}, {"reason", c.no_static_state_reason}};
  j["C1_spring_network_Pa_per_m"] = c.spring_network_c1;
  j["method"] = "static: uniform inward pressure on the 3D spring-network membrane, relaxed to equilibrium";
  j["mass_per_area_kg_per_m2"] = p.mass_per_area;
  j["grid"] = {{"cell_size_m", p.h},
               {"cells", {p.nx, p.ny, p.nz}},
               {"container", p.container},
               {"membrane_nodes", c.nodes},
               {"nodes_per_ring", c.n_theta},
               {"rings", c.n_rings}};
  j["scene"] = resolved;
  return j;
}

}  // namespace swim::validation
