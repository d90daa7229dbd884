#include "validation/calibration.hpp"

#include <gsl/gsl_fit.h>
#include <gsl/gsl_multifit.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <cstdlib>
#include <cmath>

#include "common/errors.hpp"
#include "common/si_format.hpp"
#include "full3d/grid.hpp"
#include "full3d/ib_solver.hpp"
#include "full3d/membrane.hpp"
#include "full3d/world3d.hpp"
#include "reduced1d/tube_law.hpp"

#include <array>
#include <cstdio>

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

/// A uniform load's static state on the round branch, with the stiffness of its ring modes.
struct RoundState {
  double pressure_Pa = 0;
  full3d::PressureResponse response;
  std::vector<double> ring_mode_stiffness;  ///< N/m, of cos(n phi) for n = 2, 3, ...
  int softest_mode = 0;                     ///< the n of the smallest
  double softest_stiffness = 0;             ///< N/m
};

/// The uniform-load loop of the static calibration and of the tube law: the loads in the order
/// given (increasing), each relaxed to its static state on the round branch (from the previous
/// load's state with warm_start, else from the reference mesh) and its ring modes' stiffness
/// measured, then handed to `take`, which returns false to end the loop. A load without a
/// static state ends the loop: `no_state(P, error)` is called and the error rethrown when it
/// returns true.
void round_branch(const full3d::CylinderMesh& mesh, const full3d::MembraneParams& membrane,
                  const std::vector<double>& loads, bool warm_start, const std::function<bool(const RoundState&)>& take,
                  const std::function<bool(double, const NumericalError&)>& no_state) {
  Eigen::Matrix3Xd prev;
  for (double P : loads) {
    RoundState st;
    st.pressure_Pa = P;
    try {
      st.response = full3d::relax_under_pressure(mesh, membrane, P, 0.0, 50,
                                                 warm_start && prev.size() ? &prev : nullptr);
    } catch (const NumericalError& e) {
      if (no_state(P, e)) throw;
      return;
    }
    if (warm_start) prev = st.response.X;
    st.ring_mode_stiffness = ring_mode_stiffness(mesh, membrane, P, st.response.X);
    const auto soft = std::min_element(st.ring_mode_stiffness.begin(), st.ring_mode_stiffness.end());
    st.softest_mode = int(soft - st.ring_mode_stiffness.begin()) + 2;
    st.softest_stiffness = *soft;
    if (!take(st)) return;
  }
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
  const full3d::CylinderMesh mesh = full3d::make_round_mesh(p);  // the round tube, without the seed
  c.n_theta = mesh.n_theta;
  c.n_rings = mesh.n_rings;
  c.nodes = int(mesh.X0.cols());
  c.spring_network_c1 = p.c1_estimate();
  std::vector<double> P = pressures;
  std::sort(P.begin(), P.end());
  for (double pr : P)
    if (!(pr > 0) || !std::isfinite(pr))
      throw InputError("calibration load", std::to_string(pr), "every load must be a positive pressure");
  // each load from the reference mesh
  round_branch(
      mesh, p.membrane, P, false,
      [&](const RoundState& st) {
        LoadPoint lp;
        lp.pressure_Pa = st.pressure_Pa;
        lp.displacement_m = p.R0 - st.response.mid_radius;
        lp.secant_C1_Pa_per_m = st.response.c1;
        lp.iterations = st.response.iterations;
        lp.ring_mode_stiffness_N_per_m = st.ring_mode_stiffness;
        lp.softest_ring_mode = st.softest_mode;
        lp.softest_ring_mode_stiffness_N_per_m = st.softest_stiffness;
        lp.lowest_eigenvalue_N_per_m = lowest_hessian_eigenvalue(mesh, p.membrane, st.pressure_Pa, st.response.X, 150);
        c.loads.push_back(lp);
        if (on_load) on_load(c.loads.size());
        return true;
      },
      [&](double pr, const NumericalError& e) {
        // loads are tried in increasing order: the first one without a static state ends the
        // series (the larger ones would not reach one either); three points still fit C1
        if (c.loads.size() < 3) return true;
        c.no_static_state_from_Pa = pr;
        c.no_static_state_reason = e.what();
        return false;
      });
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

AxialStiffness measure_axial_stiffness(const full3d::Params3d& p) {
  const auto t0 = std::chrono::steady_clock::now();
  AxialStiffness a;
  a.d_wall = p.bending_rigidity;
  // the scene's node spacing: the round calibration mesh's ring count and equilateral spacing
  const full3d::CylinderMesh scene_mesh = full3d::make_round_mesh(p);
  const double dx = scene_mesh.ring_spacing;
  const double c1_net = p.c1_estimate();
  const double lb = a.d_wall > 0 ? std::pow(a.d_wall / c1_net, 0.25) : 0.0;
  const double lambda0 = std::max(1.5 * lb, 8.0 * dx);
  const int n_waves = 4;
  for (int j = 0; j < n_waves; ++j) {
    a.wavelengths_m.push_back(lambda0 * double(1 << j));
    a.wavenumbers_per_m.push_back(2.0 * M_PI / a.wavelengths_m.back());
  }
  a.window_m = 2.0 * a.wavelengths_m.back();
  a.end_margin_m = std::max(10.0 * lb, 2.0 * lambda0);
  const full3d::CylinderMesh mesh = full3d::make_cylinder(p.R0, a.window_m + 2.0 * a.end_margin_m,
                                                          scene_mesh.n_theta, Eigen::Vector3d::Zero());
  a.tube_length_m = mesh.length;
  a.ring_spacing_m = mesh.ring_spacing;
  a.n_theta = mesh.n_theta;
  a.n_rings = mesh.n_rings;
  a.nodes = mesh.nodes();
  // the scene's D on the long tube (with either bending model: the long tube's edges differ
  // from the scene mesh's by its axial stretch, about 1 %, and D / k_b with them)
  full3d::MembraneParams mp = p.membrane;
  if (a.d_wall > 0) mp.kb = a.d_wall / full3d::bending_rigidity_per_kb(mesh, mp.bending);
  a.bending_constant_N = mp.kb;

  // rings' reference axial positions about the middle, and the window's rings
  const double x_mid = 0.5 * mesh.length;
  Eigen::VectorXd xi(mesh.n_rings);
  std::vector<int> window;
  for (int k = 0; k < mesh.n_rings; ++k) {
    xi[k] = k * mesh.ring_spacing - x_mid;
    if (std::abs(xi[k]) <= 0.5 * a.window_m * (1.0 + 1e-12)) window.push_back(k);
  }
  // inward displacement of each ring under the ring pressures P(xi)
  auto relax = [&](const std::function<double(double)>& shape, double p0, int* iterations) {
    Eigen::VectorXd P(mesh.n_rings);
    for (int k = 0; k < mesh.n_rings; ++k) P[k] = p0 * shape(xi[k]);
    const full3d::PressureResponse r = full3d::relax_under_ring_pressures(mesh, mp, P);
    *iterations = r.iterations;
    return Eigen::VectorXd(p.R0 - r.ring_radius.array());
  };
  const double target = 1e-3 * p.R0;  // response amplitude: linear range
  {
    int it = 0;
    a.c1_load_Pa = c1_net * target;
    const Eigen::VectorXd d = relax([](double) { return 1.0; }, a.c1_load_Pa, &it);
    double mean = 0;
    for (int k : window) mean += d[k] / double(window.size());
    a.c1_displacement_m = mean;
    a.c1 = a.c1_load_Pa / mean;
  }
  for (int j = 0; j < n_waves; ++j) {
    const double k = a.wavenumbers_per_m[std::size_t(j)];
    const double p0 = (c1_net + a.d_wall * std::pow(k, 4)) * target;
    int it = 0;
    const Eigen::VectorXd d = relax([k](double x) { return std::cos(k * x); }, p0, &it);
    // least squares d = A cos + B sin + c over the window
    Eigen::MatrixXd M(window.size(), 3);
    Eigen::VectorXd y(window.size());
    for (std::size_t i = 0; i < window.size(); ++i) {
      const double x = xi[window[i]];
      M(Eigen::Index(i), 0) = std::cos(k * x);
      M(Eigen::Index(i), 1) = std::sin(k * x);
      M(Eigen::Index(i), 2) = 1.0;
      y[Eigen::Index(i)] = d[window[i]];
    }
    const Eigen::Vector3d c = (M.transpose() * M).ldlt().solve(M.transpose() * y);
    const double amp = c[0];
    a.load_amplitudes_Pa.push_back(p0);
    a.response_amplitudes_m.push_back(amp);
    a.C_Pa_per_m.push_back(p0 / amp);
    a.quadrature_ratio.push_back(std::abs(c[1]) / amp);
    a.profile_residual_ratio.push_back((y - M * c).norm() / std::sqrt(double(window.size())) / amp);
    a.iterations.push_back(it);
  }
  a.bending_length_m = a.d_wall > 0 ? std::pow(a.d_wall / a.c1, 0.25) : 0.0;

  // Fits of C - C1 (GSL), each point weighted by 1 / C^2: every C is measured to the same
  // relative precision, so the shortest wavelength (C ~ 300 C1) does not outweigh the rest.
  // The ring lattice's fourth difference: a load cos(k x) on rings dx apart meets the bending
  // stiffness D K^4 with K = (2 / dx) sin(k dx / 2), below D k^4 by 6-9 % at 8-10 dx per
  // wavelength (docs/validation.md, "Axial stiffness"); D is fitted on K^4, and on k^4 for
  // comparison.
  const std::size_t n = std::size_t(n_waves);
  for (int j = 0; j < n_waves; ++j) {
    const double k = a.wavenumbers_per_m[std::size_t(j)];
    a.lattice_wavenumbers_per_m.push_back(2.0 / a.ring_spacing_m * std::sin(0.5 * k * a.ring_spacing_m));
  }
  std::vector<double> y(n), w(n), xk4(n), xK4(n);
  for (std::size_t j = 0; j < n; ++j) {
    y[j] = a.C_Pa_per_m[j] - a.c1;
    w[j] = 1.0 / (a.C_Pa_per_m[j] * a.C_Pa_per_m[j]);
    xk4[j] = std::pow(a.wavenumbers_per_m[j], 4);
    xK4[j] = std::pow(a.lattice_wavenumbers_per_m[j], 4);
  }
  // through the origin; the standard error from the weighted residual (the weights are relative)
  auto mul = [&](const std::vector<double>& x, double& d, double& se, double* r2) {
    double cov, chisq;
    gsl_fit_wmul(x.data(), 1, w.data(), 1, y.data(), 1, n, &d, &cov, &chisq);
    se = std::sqrt(cov * chisq / double(n - 1));
    if (r2) {
      double ss = 0;  // R^2 about zero (a fit through the origin), weighted
      for (std::size_t j = 0; j < n; ++j) ss += w[j] * y[j] * y[j];
      *r2 = ss > 0 ? 1.0 - chisq / ss : 1.0;
    }
  };
  mul(xK4, a.d_fit, a.d_fit_stderr, &a.d_fit_r2);
  mul(xk4, a.d_fit_continuum_k, a.d_fit_continuum_k_stderr, nullptr);
  // C - C1 = A k^2 + D K^4, columns scaled by the shortest wavelength's k for conditioning
  {
    const double ks = a.wavenumbers_per_m.front();
    std::unique_ptr<gsl_matrix, decltype(&gsl_matrix_free)> X(gsl_matrix_alloc(n, 2), gsl_matrix_free);
    std::unique_ptr<gsl_vector, decltype(&gsl_vector_free)> yy(gsl_vector_alloc(n), gsl_vector_free),
        ww(gsl_vector_alloc(n), gsl_vector_free), cc(gsl_vector_alloc(2), gsl_vector_free);
    std::unique_ptr<gsl_matrix, decltype(&gsl_matrix_free)> cov(gsl_matrix_alloc(2, 2), gsl_matrix_free);
    std::unique_ptr<gsl_multifit_linear_workspace, decltype(&gsl_multifit_linear_free)> ws(
        gsl_multifit_linear_alloc(n, 2), gsl_multifit_linear_free);
    for (std::size_t j = 0; j < n; ++j) {
      const double q = a.wavenumbers_per_m[j] / ks, Q = a.lattice_wavenumbers_per_m[j] / ks;
      gsl_matrix_set(X.get(), j, 0, q * q);
      gsl_matrix_set(X.get(), j, 1, Q * Q * Q * Q);
      gsl_vector_set(yy.get(), j, y[j]);
      gsl_vector_set(ww.get(), j, w[j]);
    }
    double chisq;
    gsl_multifit_wlinear(X.get(), ww.get(), yy.get(), cc.get(), cov.get(), &chisq, ws.get());
    const double s2 = chisq / double(n - 2);
    a.k2_coefficient = gsl_vector_get(cc.get(), 0) / (ks * ks);
    a.k2_coefficient_stderr = std::sqrt(gsl_matrix_get(cov.get(), 0, 0) * s2) / (ks * ks);
    a.d_fit_k2 = gsl_vector_get(cc.get(), 1) / std::pow(ks, 4);
    a.d_fit_k2_stderr = std::sqrt(gsl_matrix_get(cov.get(), 1, 1) * s2) / std::pow(ks, 4);
  }
  a.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return a;
}

scene::json to_json(const AxialStiffness& a) {
  std::vector<double> ratio, shell;
  for (std::size_t j = 0; j < a.C_Pa_per_m.size(); ++j) {
    ratio.push_back(a.C_Pa_per_m[j] / a.c1);
    shell.push_back(a.c1 + a.d_wall * std::pow(a.lattice_wavenumbers_per_m[j], 4));
  }
  scene::json j = scene::json::object();
  j["wavelengths_m"] = a.wavelengths_m;
  j["wavenumbers_per_m"] = a.wavenumbers_per_m;
  j["lattice_wavenumbers_per_m"] = a.lattice_wavenumbers_per_m;
  j["C_Pa_per_m"] = a.C_Pa_per_m;
  j["C_over_C1"] = ratio;
  j["shell_law_C_Pa_per_m"] = shell;
  j["load_amplitudes_Pa"] = a.load_amplitudes_Pa;
  j["response_amplitudes_m"] = a.response_amplitudes_m;
  j["quadrature_ratio"] = a.quadrature_ratio;
  j["profile_residual_ratio"] = a.profile_residual_ratio;
  j["newton_iterations"] = a.iterations;
  j["C1_Pa_per_m"] = a.c1;
  j["C1_load_Pa"] = a.c1_load_Pa;
  j["C1_displacement_m"] = a.c1_displacement_m;
  j["bending_rigidity_fit_J"] = a.d_fit;
  j["bending_rigidity_fit_stderr_J"] = a.d_fit_stderr;
  j["bending_rigidity_fit_r2"] = a.d_fit_r2;
  j["bending_rigidity_wall_J"] = a.d_wall;
  j["fit_on_k4"] = {{"bending_rigidity_J", a.d_fit_continuum_k},
                    {"bending_rigidity_stderr_J", a.d_fit_continuum_k_stderr},
                    {"model", "C - C1 = D k^4 (the continuum wavenumber; the lattice's fourth difference left in)"}};
  j["bending_length_m"] = a.bending_length_m;
  j["fit_with_k2"] = {{"k2_coefficient_N_per_m", a.k2_coefficient},
                      {"k2_coefficient_stderr_N_per_m", a.k2_coefficient_stderr},
                      {"bending_rigidity_J", a.d_fit_k2},
                      {"bending_rigidity_stderr_J", a.d_fit_k2_stderr},
                      {"model", "C - C1 = A k^2 + D K^4"}};
  j["tube_length_m"] = a.tube_length_m;
  j["measurement_window_m"] = a.window_m;
  j["end_margin_m"] = a.end_margin_m;
  j["ring_spacing_m"] = a.ring_spacing_m;
  j["nodes_per_ring"] = a.n_theta;
  j["rings"] = a.n_rings;
  j["membrane_nodes"] = a.nodes;
  j["bending_constant_N"] = a.bending_constant_N;
  j["wall_time_s"] = a.wall_time_s;
  j["method"] =
      "static: inward ring pressures p0 cos(k (x - x_mid)) on a long round tube of the scene's wall and node spacing, "
      "relaxed to equilibrium on the 3D membrane; amplitude a of the inward ring displacement by least squares over "
      "the middle window (an integer number of wavelengths), C(k) = p0 / a; C1 from a uniform load on the same tube; "
      "fit C - C1 = D K^4 with weights 1 / C^2, K = (2 / dx) sin(k dx / 2) the ring lattice's wavenumber "
      "(thin-shell law D w'''' + C1 w = p, free axial ends)";
  return j;
}

void add_axial_stiffness(scene::json& j, const AxialStiffness& a) {
  j["axial_stiffness"] = to_json(a);
  j["axial_bending_rigidity_J"] = a.d_fit;
}

AxialStiffnessOutcome try_measure_axial_stiffness(const full3d::Params3d& p) {
  AxialStiffnessOutcome o;
  try {
    o.measured = measure_axial_stiffness(p);
  } catch (const NumericalError& e) {
    o.failure = e.what();
  }
  return o;
}

scene::json AxialStiffnessOutcome::entries() const {
  scene::json j = scene::json::object();
  if (measured)
    add_axial_stiffness(j, *measured);
  else
    j["axial_stiffness"] = {{"status", "failed: " + failure}};
  return j;
}

WetConfirmation confirm_wet(const full3d::Params3d& p, double pressure, double static_displacement_m,
                            bool axisymmetric_wall) {
  const auto t0 = std::chrono::steady_clock::now();
  const full3d::World3d world(p);
  const full3d::CylinderMesh& mesh = world.mesh;
  full3d::IbOptions opt = world.options;
  opt.axisymmetric_wall = axisymmetric_wall;
  const std::unique_ptr<full3d::IbSolver> solver = world.solver(opt);  // a massless wall
  full3d::IbSolver& ib = *solver;
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

// ---- The whole static tube law ---------------------------------------------------------------

namespace swim::validation {

namespace {

struct MidMeasures {
  double mean = 0, area = 0, spread = 0, min_node = 0;
};
// Middle ring(s): mean node radius, area-equivalent radius (shoelace in the cross-section
// plane, nodes in their ring order), spread of the node radii; smallest node radius overall.
MidMeasures mid_measures(const full3d::CylinderMesh& mesh, const Eigen::Matrix3Xd& X) {
  MidMeasures m;
  const Eigen::VectorXd r = full3d::node_radii(mesh, X);
  m.min_node = r.minCoeff();
  const int r0 = (mesh.n_rings - 1) / 2, r1 = mesh.n_rings / 2;
  double lo = 1e300, hi = -1e300;
  for (int ring : {r0, r1}) {
    double mean = 0, area = 0;
    for (int i = 0; i < mesh.n_theta; ++i) {
      const int a = mesh.node(ring, i), b = mesh.node(ring, (i + 1) % mesh.n_theta);
      mean += r[a] / mesh.n_theta;
      const double ya = X(1, a) - mesh.axis_start.y(), za = X(2, a) - mesh.axis_start.z();
      const double yb = X(1, b) - mesh.axis_start.y(), zb = X(2, b) - mesh.axis_start.z();
      area += 0.5 * (ya * zb - yb * za);
      lo = std::min(lo, r[a]);
      hi = std::max(hi, r[a]);
    }
    m.mean += 0.5 * mean;
    m.area += 0.5 * std::sqrt(std::max(area, 0.0) / M_PI);
  }
  m.spread = hi - lo;
  return m;
}

// Minimise E(X) + P sum A_i r_i over every node position by L-BFGS (memory 20), in scaled
// variables x = X / R0, energy / (k_s R0^2). The loaded energy is a sum of many small terms and
// its changes near the minimum fall below its round-off, so the line search works on the
// directional derivative phi'(alpha) = g(x + alpha d) . d (secant steps until
// |phi'(alpha)| <= 0.9 |phi'(0)|, the strong Wolfe curvature condition), with the energy
// required not to rise beyond its round-off.
}  // namespace

Minimised minimise_loaded_energy(const full3d::CylinderMesh& mesh, const full3d::MembraneParams& mp, double P,
                                 const Eigen::Matrix3Xd& start, double tol_force, int max_iterations, double eps) {
  const double R0 = mesh.radius, fs = mp.ks * R0 * R0, gs = mp.ks * R0;
  const Eigen::Index n = start.size();
  long calls = 0;
  auto evaluate = [&](const Eigen::VectorXd& x, Eigen::VectorXd& g, double& maxf) {
    const Eigen::Map<const Eigen::Matrix3Xd> Xs(x.data(), 3, start.cols());
    const Eigen::Matrix3Xd X = Xs * R0;
    std::array<double, 2> e{};
    Eigen::Matrix3Xd G = -full3d::elastic_forces(mesh, X, mp, 1, &e);
    const Eigen::VectorXd r = full3d::node_radii(mesh, X);
    double load = 0;
    for (Eigen::Index i = 0; i < X.cols(); ++i) {
      // sqrt(r^2 + eps^2) - eps: the load fades within eps of the axis (the walls' contact there)
      const double re = std::sqrt(r[i] * r[i] + eps * eps);
      load += mesh.node_area[i] * (re - eps);
      if (re > 0) {
        const double y = X(1, i) - mesh.axis_start.y(), z = X(2, i) - mesh.axis_start.z();
        G(1, i) += P * mesh.node_area[i] * y / re;
        G(2, i) += P * mesh.node_area[i] * z / re;
      }
    }
    Eigen::Index imax = 0;
    maxf = G.colwise().norm().maxCoeff(&imax);
    if (std::getenv("SWIM_LBFGS_TRACE") && ++calls % 5000 == 0)
      std::fprintf(stderr, "    max-force node %ld: r/R0 %.4g, |F|/(P A) %.3g; min r/R0 %.4g\n", long(imax), r[imax] / R0,
                   maxf / (P * mesh.node_area[imax]), r.minCoeff() / R0);
    g = Eigen::Map<const Eigen::VectorXd>(G.data(), n) / gs;
    return (e[0] + e[1] + P * load) / fs;
  };
  Eigen::VectorXd x = Eigen::Map<const Eigen::VectorXd>(start.data(), n) / R0, g(n), gn(n);
  double maxf = 0;
  double f = evaluate(x, g, maxf);
  constexpr int m = 20;
  std::vector<Eigen::VectorXd> S, Y;
  std::vector<double> rho;
  Minimised out;
  int it = 0;
  // SWIM_LBFGS_TRACE set: progress on stderr every 500 iterations (and the node of the largest
  // force every 5 000 evaluations), a diagnostic of slow relaxations
  const bool trace = std::getenv("SWIM_LBFGS_TRACE") != nullptr;
  for (; it < max_iterations && maxf > tol_force; ++it) {
    if (trace && it % 500 == 0)
      std::fprintf(stderr, "    L-BFGS %6d: max force / tolerance %.3g, energy %.15g\n", it, maxf / tol_force, f);
    // two-loop recursion
    Eigen::VectorXd d = -g;
    std::vector<double> a(S.size());
    for (int k = int(S.size()) - 1; k >= 0; --k) {
      a[k] = rho[k] * S[k].dot(d);
      d -= a[k] * Y[k];
    }
    const double gamma = S.empty() ? 1e-3 / std::max(g.lpNorm<Eigen::Infinity>(), 1e-300)
                                   : S.back().dot(Y.back()) / Y.back().squaredNorm();
    d *= gamma;
    for (std::size_t k = 0; k < S.size(); ++k) d += S[k] * (a[k] - rho[k] * Y[k].dot(d));
    double d0 = g.dot(d);
    if (!(d0 < 0)) {  // not a descent direction: restart from steepest descent
      S.clear(), Y.clear(), rho.clear();
      d = -g * 1e-3 / std::max(g.lpNorm<Eigen::Infinity>(), 1e-300);
      d0 = g.dot(d);
    }
    double alpha = 1.0, fn = 0, maxfn = 0;
    bool ok = false;
    double lo = 0, dlo = d0;  // bracket [lo, alpha] on phi'
    for (int ls = 0; ls < 30; ++ls) {
      fn = evaluate(x + alpha * d, gn, maxfn);
      const double da = gn.dot(d);
      const bool energy_ok = std::isfinite(fn) && fn <= f + 1e-4 * alpha * d0 + 1e-12 * std::abs(f);
      if (energy_ok && std::abs(da) <= 0.9 * std::abs(d0)) {
        ok = true;
        break;
      }
      if (energy_ok && da < 0) {  // still descending: extrapolate (secant, at most 4x)
        const double next = alpha - da * (alpha - lo) / (da - dlo);
        lo = alpha, dlo = da;
        alpha = std::isfinite(next) ? std::min(std::max(next, 1.1 * alpha), 4.0 * alpha) : 2.0 * alpha;
        continue;
      }
      // overshot (phi' > 0 or the energy rose): secant inside [lo, alpha]
      double next = (std::isfinite(fn) && da > 0) ? lo - dlo * (alpha - lo) / (da - dlo) : 0.5 * (lo + alpha);
      next = std::min(std::max(next, lo + 0.1 * (alpha - lo)), lo + 0.9 * (alpha - lo));
      alpha = next;
    }
    if (!ok) {
      if (!S.empty()) {  // lose the memory once, then give up
        S.clear(), Y.clear(), rho.clear();
        continue;
      }
      break;
    }
    const Eigen::VectorXd s = alpha * d, y = gn - g;
    const double sy = s.dot(y);
    if (sy > 1e-300) {
      if (int(S.size()) == m) S.erase(S.begin()), Y.erase(Y.begin()), rho.erase(rho.begin());
      S.push_back(s), Y.push_back(y), rho.push_back(1.0 / sy);
    }
    x += s;
    g = gn;
    f = fn;
    maxf = maxfn;
  }
  out.X = Eigen::Map<const Eigen::Matrix3Xd>(x.data(), 3, start.cols()) * R0;
  out.iterations = it;
  out.residual = maxf;
  out.converged = maxf <= tol_force;
  return out;
}

namespace {

LawPoint make_point(const full3d::CylinderMesh& mesh, double P, const Eigen::Matrix3Xd& X, double residual,
                    int iterations) {
  LawPoint lp;
  lp.pressure_Pa = P;
  const MidMeasures m = mid_measures(mesh, X);
  lp.mid_radius_m = m.mean;
  lp.area_radius_m = m.area;
  lp.radius_spread_m = m.spread;
  lp.min_node_radius_m = m.min_node;
  lp.residual_force_N = residual;
  lp.iterations = iterations;
  return lp;
}

}  // namespace

double round_closed_form_c1(const full3d::CylinderMesh& mesh, double ks) {
  return 2.0 * ks * std::sin(M_PI / mesh.n_theta) / (mesh.radius * mesh.ring_spacing);
}

void fit_branch(LawBranch& b, double R0) {
  std::vector<LawPoint> pts = b.points;
  std::sort(pts.begin(), pts.end(), [](const LawPoint& a, const LawPoint& c) { return a.pressure_Pa > c.pressure_Pa; });
  b.knots_R.clear();
  b.knots_w.clear();
  b.dropped_non_monotone = 0;
  for (const auto& lp : pts) {  // deepest first: R ascending, w = -P ascending
    const double R = lp.mid_radius_m, w = -lp.pressure_Pa;
    if (!b.knots_R.empty() && !(R > b.knots_R.back() && w > b.knots_w.back())) {
      ++b.dropped_non_monotone;
      continue;
    }
    if (!(R < R0)) {
      ++b.dropped_non_monotone;
      continue;
    }
    b.knots_R.push_back(R);
    b.knots_w.push_back(w);
  }
  b.knots_R.push_back(R0);
  b.knots_w.push_back(0.0);
  const std::size_t K = b.knots_R.size();
  if (K < 3) throw NumericalError("the tube law has fewer than three monotone knots", "add loads");
  b.slope_at_R0 = reduced1d::TubeLaw(R0, b.knots_R, b.knots_w).slope_at_R0();
  double sum2 = 0;
  int cnt = 0;
  b.loo_max_abs_Pa = b.loo_max_rel = 0;
  for (std::size_t k = 1; k + 1 < K; ++k) {
    std::vector<double> R = b.knots_R, w = b.knots_w;
    R.erase(R.begin() + std::ptrdiff_t(k));
    w.erase(w.begin() + std::ptrdiff_t(k));
    if (R.size() < 3) continue;
    const reduced1d::TubeLaw law(R0, R, w);
    const double res = law(b.knots_R[k]) - b.knots_w[k];
    b.loo_max_abs_Pa = std::max(b.loo_max_abs_Pa, std::abs(res));
    b.loo_max_rel = std::max(b.loo_max_rel, std::abs(res / b.knots_w[k]));
    sum2 += res * res;
    ++cnt;
    if (k == K - 2) b.slope_at_R0_loo = law.slope_at_R0();
  }
  b.loo_rms_Pa = cnt ? std::sqrt(sum2 / cnt) : 0.0;
}

TubeLawCalibration calibrate_tube_law(const full3d::Params3d& p, double c1, double c1_stderr,
                                      const TubeLawOptions& o) {
  TubeLawCalibration t;
  t.c1_fit = c1;
  t.c1_fit_stderr = c1_stderr;
  const full3d::CylinderMesh mesh = full3d::make_round_mesh(p);  // the round tube, without the seed
  const double R0 = mesh.radius;
  t.closed_form_c1 = round_closed_form_c1(mesh, p.membrane.ks);
  const double Pscale = p.c1_estimate() * R0;
  const double deepest = o.deepest_ratio * R0;
  const std::vector<double> load_fractions = {0.01, 0.02, 0.03, 0.04, 0.05, 0.06, 0.075, 0.1, 0.125, 0.15, 0.2,
                                              0.3,  0.4,  0.5,  0.6,  0.7,  0.75, 0.8, 0.85,  0.9};
  // ---- round branch
  auto t0 = std::chrono::steady_clock::now();
  std::vector<Eigen::Matrix3Xd> round_X;
  {
    std::vector<double> loads;
    for (double f : load_fractions) loads.push_back(f * Pscale);
    // each load from the previous equilibrium
    round_branch(
        mesh, p.membrane, loads, true,
        [&](const RoundState& st) {
          const full3d::PressureResponse& r = st.response;
          LawPoint lp = make_point(mesh, st.pressure_Pa, r.X, r.max_residual_force, r.iterations);
          lp.softest_ring_mode = st.softest_mode;
          lp.softest_ring_mode_stiffness_N_per_m = st.softest_stiffness;
          t.round.points.push_back(lp);
          round_X.push_back(r.X);
          if (lp.mid_radius_m <= deepest) {
            t.round.stopped_because = "reached R_mid <= deepest_ratio R0";
            return false;
          }
          return true;
        },
        [&](double P, const NumericalError& e) {
          t.round.stopped_because = "no static state at " + significant(P, 4) + " Pa: " + e.what();
          return false;
        });
    if (t.round.stopped_because.empty()) t.round.stopped_because = "end of the load list";
  }
  for (const auto& lp : t.round.points) {
    const double dev = std::abs(lp.pressure_Pa / (t.closed_form_c1 * (R0 - lp.mid_radius_m)) - 1.0);
    t.round_max_rel_dev_closed_form = std::max(t.round_max_rel_dev_closed_form, dev);
  }
  fit_branch(t.round, R0);
  t.round.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // ---- buckling load: the softest ring-mode stiffness crosses zero
  int first_unstable = -1;
  for (std::size_t i = 0; i < t.round.points.size(); ++i)
    if (t.round.points[i].softest_ring_mode_stiffness_N_per_m < 0) {
      first_unstable = int(i);
      break;
    }
  if (first_unstable < 0) {
    t.buckled_absent_because = "no ring mode turns unstable on the round branch over the loads";
    return t;
  }
  {
    const LawPoint& b = t.round.points[first_unstable];
    t.buckling_mode = b.softest_ring_mode;
    if (first_unstable == 0) {
      t.buckling_load_Pa = b.pressure_Pa;  // at or below the smallest load
    } else {
      const LawPoint& a = t.round.points[first_unstable - 1];
      const double ka = a.softest_ring_mode_stiffness_N_per_m, kb = b.softest_ring_mode_stiffness_N_per_m;
      t.buckling_load_Pa = a.pressure_Pa + (b.pressure_Pa - a.pressure_Pa) * ka / (ka - kb);
    }
  }
  if (!o.buckled) {
    t.buckled_absent_because = "not computed (TubeLawOptions::buckled = false)";
    return t;
  }
  // ---- buckled branch: every node free, the same loads in increasing order, each from the
  // previous equilibrium plus a small seeded ring mode of the buckling n (uniform along the
  // tube), until R_mid <= deepest_ratio R0
  t0 = std::chrono::steady_clock::now();
  t.buckled_computed = true;
  {
    const double tol = o.lbfgs_tolerance * mesh.node_area.maxCoeff();
    // one load from `from`: seeded, minimised; false (and the reason) when L-BFGS fails
    auto relax = [&](double P, const Eigen::Matrix3Xd& from, Eigen::Matrix3Xd& X, LawPoint& lp) {
      Eigen::Matrix3Xd start = from;
      const Eigen::Matrix3Xd er = full3d::radial_directions(mesh, start);
      for (Eigen::Index i = 0; i < start.cols(); ++i)
        start.col(i) +=
            o.seed_amplitude_ratio * R0 * std::cos(t.buckling_mode * std::atan2(er(2, i), er(1, i))) * er.col(i);
      const Minimised mz =
          minimise_loaded_energy(mesh, p.membrane, P, start, tol * P, o.lbfgs_max_iterations, o.axis_contact_ratio * R0);
      if (!mz.converged) {
        char b[200];
        std::snprintf(b, sizeof b, "L-BFGS did not reach the force tolerance %.3g N at %.4g Pa (residual %.3g N after %d "
                      "iterations)", tol * P, P, mz.residual, mz.iterations);
        t.buckled.stopped_because = b;
        return false;
      }
      X = mz.X;
      lp = make_point(mesh, P, X, mz.residual, mz.iterations);
      std::fprintf(stderr, "  buckled branch: P = %.4g Pa  R_mid/R0 = %.4f  spread/R0 = %.3g  %d iterations\n", P,
                   lp.mid_radius_m / R0, lp.radius_spread_m / R0, mz.iterations);
      return true;
    };
    auto collapsed = [&](const LawPoint& lp) { return lp.radius_spread_m > 0.01 * R0; };
    Eigen::Matrix3Xd X = mesh.X0, Xround;
    double prev_P = 0;
    int after = 0;  // loads after the collapse
    bool ok = true;
    for (double f : load_fractions) {
      const double P = f * Pscale;
      LawPoint lp;
      Eigen::Matrix3Xd Xn;
      if (!(ok = relax(P, X, Xn, lp))) break;
      if (t.collapse_load_Pa == 0 && collapsed(lp)) {
        // bracket the collapse: bisect between the last round load and this one, each try
        // from the last round state
        double lo = prev_P, hi = P;
        for (int k = 0; k < o.collapse_bisections && lo > 0; ++k) {
          const double mid = 0.5 * (lo + hi);
          LawPoint lm;
          Eigen::Matrix3Xd Xm;
          if (!(ok = relax(mid, Xround, Xm, lm))) break;
          t.buckled.points.push_back(lm);
          if (collapsed(lm)) hi = mid;
          else lo = mid, Xround = Xm;
        }
        if (!ok) break;
        t.collapse_load_Pa = hi;
        t.round_up_to_Pa = lo;
      }
      X = Xn;
      if (!collapsed(lp)) Xround = Xn;
      t.buckled.points.push_back(lp);
      prev_P = P;
      if (t.collapse_load_Pa > 0) ++after;
      if (lp.mid_radius_m <= deepest && after >= o.loads_after_collapse) {
        t.buckled.stopped_because = "reached R_mid <= deepest_ratio R0 with loads_after_collapse loads beyond the collapse";
        break;
      }
    }
    if (ok && t.buckled.stopped_because.empty()) t.buckled.stopped_because = "end of the load list";
  }
  fit_branch(t.buckled, R0);
  t.buckled.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return t;
}

scene::json to_json(const TubeLawCalibration& t, double R0) {
  auto branch = [&](const LawBranch& b) {
    scene::json pts = scene::json::array();
    for (const auto& lp : b.points)
      pts.push_back({{"pressure_Pa", lp.pressure_Pa},
                     {"mid_radius_m", lp.mid_radius_m},
                     {"area_radius_m", lp.area_radius_m},
                     {"radius_spread_m", lp.radius_spread_m},
                     {"min_node_radius_m", lp.min_node_radius_m},
                     {"softest_ring_mode", lp.softest_ring_mode},
                     {"softest_ring_mode_stiffness_N_per_m", lp.softest_ring_mode_stiffness_N_per_m},
                     {"residual_force_N", lp.residual_force_N},
                     {"iterations", lp.iterations}});
    return scene::json{{"load_points", pts},
                       {"knots_radius_m", b.knots_R},
                       {"knots_wall_pressure_Pa", b.knots_w},
                       {"slope_at_R0_Pa_per_m", b.slope_at_R0},
                       {"slope_at_R0_without_smallest_load_Pa_per_m", b.slope_at_R0_loo},
                       {"leave_one_out_max_abs_Pa", b.loo_max_abs_Pa},
                       {"leave_one_out_rms_Pa", b.loo_rms_Pa},
                       {"leave_one_out_max_relative", b.loo_max_rel},
                       {"dropped_non_monotone_points", b.dropped_non_monotone},
                       {"deepest_radius_m", b.knots_R.front()},
                       {"deepest_radius_over_R0", b.knots_R.front() / R0},
                       {"stopped_because", b.stopped_because},
                       {"wall_time_s", b.wall_time_s}};
  };
  scene::json j = {
      {"method",
       "uniform inward loads on the 3D membrane, relaxed in increasing order from the previous equilibrium; law "
       "w(R) = -P(R) through the knots (mean node radius of the middle ring(s), load), monotone Steffen "
       "interpolation (GSL gsl_interp_steffen), linear beyond the knots with the end slopes"},
      {"radius_measure", "mean node radius of the middle ring(s)"},
      {"C1_small_load_fit_Pa_per_m", t.c1_fit},
      {"C1_small_load_fit_stderr_Pa_per_m", t.c1_fit_stderr},
      {"C1_round_closed_form_Pa_per_m", t.closed_form_c1},
      {"round_max_relative_deviation_from_closed_form", t.round_max_rel_dev_closed_form},
      {"round", branch(t.round)}};
  j["buckling_load_Pa"] = t.buckling_load_Pa > 0 ? scene::json(t.buckling_load_Pa) : scene::json(nullptr);
  j["buckling_ring_mode"] = t.buckling_mode;
  j["buckling_load_method"] = "round branch: the softest ring mode cos(n phi) (uniform along the tube) reaches zero "
                              "stiffness, interpolated between the loads";
  if (t.buckled_computed) {
    j["buckled"] = branch(t.buckled);
    j["buckled"]["seed"] = "every load from the previous equilibrium plus the ring mode cos(n phi) e_r of the round "
                           "branch's buckling n, amplitude 1e-3 R0, uniform along the tube; every node free (L-BFGS on "
                           "the loaded energy, force tolerance 1e-3 of the largest nodal load)";
    j["buckled"]["axis_contact"] = "the load P A_i e_r fades as r / sqrt(r^2 + eps^2) within eps = 0.01 R0 of the axis, "
                                   "where the collapsing wall meets itself (the membrane has no self-contact)";
    j["collapse_load_Pa"] = t.collapse_load_Pa > 0 ? scene::json(t.collapse_load_Pa) : scene::json(nullptr);
    j["round_up_to_Pa"] = t.round_up_to_Pa;
  } else {
    j["buckled_absent_because"] = t.buckled_absent_because;
  }
  return j;
}

}  // namespace swim::validation
