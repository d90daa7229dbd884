#include "validation/calibration.hpp"

#include <gsl/gsl_fit.h>

#include <algorithm>
#include <cmath>

#include "common/errors.hpp"
#include "full3d/membrane.hpp"

namespace swim::validation {

namespace {
// d^2/ds^2 of E(X + sV) + P sum A_i r_i(X + sV) for the unit mode V_i ~ cos(n phi_i) e_r,i,
// by central differences of the exact gradient: V . (g(X + sV) - g(X - sV)) / (2 s).
double ovalisation_stiffness(const full3d::CylinderMesh& mesh, const full3d::MembraneParams& p, double pressure,
                             const Eigen::Matrix3Xd& X, int n) {
  const Eigen::Matrix3Xd er = full3d::radial_directions(mesh, X);
  Eigen::Matrix3Xd V(3, X.cols());
  for (Eigen::Index i = 0; i < X.cols(); ++i) {
    const double phi = std::atan2(er(2, i), er(1, i));
    V.col(i) = std::cos(n * phi) * er.col(i);
  }
  V /= V.norm();
  auto grad = [&](const Eigen::Matrix3Xd& Y) {
    Eigen::Matrix3Xd g = -full3d::elastic_forces(mesh, Y, p);
    const Eigen::Matrix3Xd e = full3d::radial_directions(mesh, Y);
    for (Eigen::Index i = 0; i < Y.cols(); ++i) g.col(i) += pressure * mesh.node_area[i] * e.col(i);
    return g;
  };
  const double s = 1e-4 * mesh.rest_length.minCoeff();
  return V.cwiseProduct(grad(X + s * V) - grad(X - s * V)).sum() / (2.0 * s);
}
}  // namespace

std::vector<double> default_loads(const full3d::Params3d& p) {
  const double q_static = p.c1_estimate() * (p.R0 - p.protocol.R_f);
  std::vector<double> out;
  for (double f : {0.02, 0.05, 0.1, 0.2, 0.35, 0.5, 0.75, 1.0, 1.5}) out.push_back(f * q_static);
  return out;
}

StaticCalibration calibrate_static(const full3d::Params3d& p, const std::vector<double>& pressures) {
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
    const full3d::PressureResponse r = full3d::relax_under_pressure(mesh, p.membrane, pr);
    LoadPoint lp;
    lp.pressure_Pa = pr;
    lp.displacement_m = p.R0 - r.mid_radius;
    lp.secant_C1_Pa_per_m = r.c1;
    lp.iterations = r.iterations;
    lp.ovalisation_stiffness_n2_N_per_m = ovalisation_stiffness(mesh, p.membrane, pr, r.X, 2);
    lp.ovalisation_stiffness_n3_N_per_m = ovalisation_stiffness(mesh, p.membrane, pr, r.X, 3);
    c.loads.push_back(lp);
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
  if (n < 2)
    throw NumericalError("only " + std::to_string(n) + " of " + std::to_string(c.loads.size()) +
                             " calibration loads are linear and stable to ring buckling; no C1 fit",
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

scene::json to_json(const StaticCalibration& c, const full3d::Params3d& p, const scene::json& resolved) {
  scene::json pts = scene::json::array();
  for (const auto& lp : c.loads)
    pts.push_back({{"pressure_Pa", lp.pressure_Pa},
                   {"displacement_m", lp.displacement_m},
                   {"secant_C1_Pa_per_m", lp.secant_C1_Pa_per_m},
                   {"in_linear_range", lp.in_linear_range},
                   {"ovalisation_stiffness_n2_N_per_m", lp.ovalisation_stiffness_n2_N_per_m},
                   {"ovalisation_stiffness_n3_N_per_m", lp.ovalisation_stiffness_n3_N_per_m},
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
