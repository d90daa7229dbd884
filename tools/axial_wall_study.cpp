// swim_axial_wall_study: what the wall's axial freedom is worth to the force-driven protocol's
// timing, at a fixed flow model (docs/outer-flow-1d.md §6d, "The rings' axial freedom").
//
// A round tube of radius R0 and length L in the rigid container of radius Rc, driven by the
// protocol's segment loads (front segment first; each segment under the load P until its mean
// radius reaches R_f (1 + tol), then held there by a load of its own, the next one loaded).
// Flow: the 1D tier's plain confined lubrication on the rings' reference coordinate (lumen and
// annulus resistances in series, no net flux, the transmural pressure 0 beyond both open ends)
// with the short-wave traction 4 mu |k| on the wall's radial velocity, |k| continued beyond the
// ends by the mirror (the tier's default end condition, beta = 0) or by a wall at rest (beta = 1).
// The swimmer's own motion is left out (it is 10^-2 of the wall's velocities). Walls:
//   linear      the 1D tier's law: Pi = P - C1 w - D w'''' (w = R0 - r, free ends, C1 = Y/R0^2)
//   shell-fixed the axisymmetric tier's wall (axi/wall_axi.hpp), its rings held at their
//               reference z (the 1D tier's radial kinematics)
//   shell-free  the same wall, its rings free along the axis: each ring's axial force balance,
//               without (default) or with (--fluid-axial) the fluid's axial force on the wall
//               (the lumen's and the annulus's shear and the transmural pressure on the slope)
// Each ring carries its reference area A_k; its radial balance is F_r,k + (Pi_k - P_k) A_k = 0.
// Backward Euler in time, Newton with a dense finite-difference Jacobian: a study, not a
// solver (a few seconds to a minute per run).
//
// Then the recovery: every load released, until every ring's radius is within tol R0 of R0.
// Output: one line per segment: the time it took to reach R_f (1 + tol), the next segment's mean
// radius then, and the tube's length; then the recovery's time and the ring that came back last.
#include <Eigen/Dense>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "axi/wall_axi.hpp"
#include "reduced1d/outer_flow.hpp"

namespace {

constexpr double kPi = 3.14159265358979323846;

struct Options {
  std::string wall = "linear";
  bool fluid_axial = false;
  bool rest_ends = false;
  int rings = 101;
  double dt = 1e-4;            // s
  double length = 0.2e-6;      // m
  double first = 20e-9;        // m, the front segment
  int segments = 4;
  double pressure = 0.5;       // Pa
  double radius = 0.125e-6;    // m
  double container = 0.25e-6;  // m
  double ks = 5.5e-8;          // N/m
  double D = 2.1184615504e-24;  // J
  double mu = 1.2e-3;          // Pa s
  double ratio = 0.55, tol = 0.02;
  std::string record;  // radius.csv of the cycle (t_s, z_m at the ring's reference position, radius_m)
};

[[noreturn]] void usage(const char* msg) {
  std::fprintf(stderr,
               "swim_axial_wall_study: %s\n"
               "usage: swim_axial_wall_study [--wall linear|shell-fixed|shell-free] [--fluid-axial]\n"
               "  [--ends mirror|rest] [--rings N] [--dt-ms X] [--length-um X] [--first-nm X] [--segments N]\n"
               "  [--pressure-pa X] [--ratio X] [--record radius.csv]\n",
               msg);
  std::exit(2);
}

/// |k| along the tube's n equally spaced rings: the cosine transform (DCT-I) of the field
/// continued by its mirror image beyond both ends, or (rest) of the field on a tube `ext` times
/// as long with the rings in its middle and a wall at rest elsewhere.
Eigen::MatrixXd abs_k_operator(int n, double L, bool rest) {
  const int ext = rest ? 9 : 1;
  const int ne = (n - 1) * ext + 1;
  const double Le = L * ext;
  Eigen::MatrixXd forward(ne, ne), inverse(ne, ne);
  for (int m = 0; m < ne; ++m)
    for (int k = 0; k < ne; ++k) {
      const double c = std::cos(kPi * m * k / (ne - 1));
      forward(m, k) = 2.0 / (ne - 1) * c * ((k == 0 || k == ne - 1) ? 0.5 : 1.0);
      inverse(k, m) = c * ((m == 0 || m == ne - 1) ? 0.5 : 1.0);
    }
  Eigen::VectorXd wavenumber(ne);
  for (int m = 0; m < ne; ++m) wavenumber(m) = m * kPi / Le;
  const Eigen::MatrixXd H = inverse * wavenumber.asDiagonal() * forward;
  const int off = (ne - n) / 2;
  return H.block(off, off, n, n);
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> const char* {
      if (i + 1 >= argc) usage(("missing value after " + a).c_str());
      return argv[++i];
    };
    if (a == "--wall") o.wall = next();
    else if (a == "--fluid-axial") o.fluid_axial = true;
    else if (a == "--ends") {
      const std::string e = next();
      if (e != "mirror" && e != "rest") usage("--ends takes mirror or rest");
      o.rest_ends = e == "rest";
    } else if (a == "--rings") o.rings = std::atoi(next());
    else if (a == "--dt-ms") o.dt = std::atof(next()) * 1e-3;
    else if (a == "--length-um") o.length = std::atof(next()) * 1e-6;
    else if (a == "--first-nm") o.first = std::atof(next()) * 1e-9;
    else if (a == "--segments") o.segments = std::atoi(next());
    else if (a == "--pressure-pa") o.pressure = std::atof(next());
    else if (a == "--ratio") o.ratio = std::atof(next());
    else if (a == "--record") o.record = next();
    else usage(("unknown option " + a).c_str());
  }
  if (o.wall != "linear" && o.wall != "shell-fixed" && o.wall != "shell-free")
    usage("--wall takes linear, shell-fixed or shell-free");
  if (o.fluid_axial && o.wall != "shell-free") usage("--fluid-axial needs --wall shell-free");
  if (o.rings < 11 || !(o.dt > 0) || !(o.length > 0) || !(o.first > 0) || o.first >= o.length || o.segments < 2 ||
      !(o.pressure > 0) || !(o.ratio > 0 && o.ratio < 1))
    usage("an option is out of range (rings >= 11, dt, length, first segment in (0, length), segments >= 2, "
          "pressure > 0, ratio in (0, 1))");

  const int n = o.rings;
  const double R0 = o.radius, L = o.length, Rc = o.container, mu = o.mu, h = L / (n - 1);
  const double Y = swim::axi::young_modulus_2d(o.ks), C1 = Y / (R0 * R0);
  swim::axi::AxiWallParams wp;
  wp.R0 = R0;
  wp.L = L;
  wp.ks = o.ks;
  wp.D = o.D;
  wp.nodes = n;
  const swim::axi::AxiWall wall(wp);
  const Eigen::Matrix3Xd X0 = wall.reference();
  const Eigen::VectorXd& A = wall.node_area();
  std::vector<double> hb(n, h);
  hb[0] = hb[n - 1] = 0.5 * h;
  const Eigen::MatrixXd H = abs_k_operator(n, L, o.rest_ends);
  const bool free_rings = o.wall == "shell-free";
  const int m0 = free_rings ? 2 * n : n;  // unknowns r_k (and x_k), then the held segments' loads

  // segment of each ring: 0 the front segment [L - first, L], then equal ones towards the rear
  std::vector<int> seg(n);
  const double rest_len = (L - o.first) / (o.segments - 1);
  for (int k = 0; k < n; ++k) {
    const double z = X0(0, k);
    seg[k] = z >= L - o.first - 1e-15 ? 0 : std::min(o.segments - 1, 1 + int((L - o.first - z) / rest_len - 1e-12));
  }
  auto seg_mean = [&](const Eigen::VectorXd& y, int s) {
    double num = 0, den = 0;
    for (int k = 0; k < n; ++k)
      if (seg[k] == s) num += A(k) * y(k), den += A(k);
    return num / den / R0;
  };
  // lumen and annulus resistances per unit length (wall and container at rest; the annulus's
  // as the 1D tier's, reduced1d/outer_flow.hpp)
  auto r_in = [&](double r) { return 8 * mu / (kPi * r * r * r * r); };
  auto annulus = [&](double r) { return swim::reduced1d::outer::annulus_point(r, Rc, mu); };

  int active = 0;
  bool recovering = false;  // every load released
  std::vector<double> target;
  auto residual = [&](const Eigen::VectorXd& y, const Eigen::VectorXd& y_old) {
    const int m = int(y.size());
    std::vector<double> P(n);
    for (int k = 0; k < n; ++k)
      P[k] = recovering ? 0.0 : seg[k] == active ? o.pressure : (seg[k] < active ? y(m - active + seg[k]) : 0.0);
    Eigen::Matrix3Xd X = X0;
    for (int k = 0; k < n; ++k) {
      X(1, k) = y(k);
      if (free_rings) X(0, k) = y(n + k);
    }
    Eigen::VectorXd Pi(n);
    Eigen::Matrix3Xd F;
    if (o.wall == "linear") {
      std::vector<double> w(n + 4);
      for (int k = 0; k < n; ++k) w[k + 2] = R0 - y(k);
      w[1] = 2 * w[2] - w[3];  // free ends: w'' = w''' = 0
      w[0] = w[4] - 2 * w[3] + 2 * w[1];
      w[n + 2] = 2 * w[n + 1] - w[n];
      w[n + 3] = w[n - 1] - 2 * w[n] + 2 * w[n + 2];
      for (int k = 0; k < n; ++k)
        Pi(k) = P[k] - C1 * w[k + 2] - o.D * (w[k] - 4 * w[k + 1] + 6 * w[k + 2] - 4 * w[k + 3] + w[k + 4]) / (h * h * h * h);
    } else {
      F = wall.forces(X);
      for (int k = 0; k < n; ++k) Pi(k) = P[k] - F(1, k) / A(k);
    }
    Pi += 4 * mu * (H * ((y.head(n) - y_old.head(n)) / o.dt));
    std::vector<double> Q(n + 1), rr(n + 1);
    for (int j = 0; j <= n; ++j) rr[j] = j == 0 ? y(0) : (j == n ? y(n - 1) : 0.5 * (y(j - 1) + y(j)));
    auto cond = [&](double r) { return 1.0 / (r_in(r) + annulus(r).rho); };
    Q[0] = -cond(rr[0]) * Pi(0) / (0.5 * h);
    Q[n] = cond(rr[n]) * Pi(n - 1) / (0.5 * h);
    for (int j = 1; j < n; ++j) Q[j] = -cond(rr[j]) * (Pi(j) - Pi(j - 1)) / h;
    Eigen::VectorXd res(m);
    for (int k = 0; k < n; ++k)
      res(k) = (kPi * hb[k] * (y(k) * y(k) - y_old(k) * y_old(k)) - o.dt * (Q[k] - Q[k + 1])) / (kPi * R0 * h);
    if (free_rings) {
      // the fluid's axial force: the lumen's and the annulus's pressure gradients at each face
      // from its flux (Q = -p_in' / r_in = p_out' G_a), their mean over a ring's patch; per unit
      // length -pi R^2 p_in' from the lumen, (pi R^2 - S) p_out' from the annulus's shear
      std::vector<double> gin(n + 1, 0.0), gout(n + 1, 0.0);
      if (o.fluid_axial)
        for (int j = 0; j <= n; ++j) {
          gin[j] = -Q[j] * r_in(rr[j]);
          gout[j] = Q[j] * annulus(rr[j]).rho;
        }
      for (int k = 0; k < n; ++k) {
        double fx = 0;
        if (o.fluid_axial) {
          const double gi = 0.5 * (gin[k] + gin[k + 1]), go = 0.5 * (gout[k] + gout[k + 1]), rk = y(k);
          const int kl = k > 0 ? k - 1 : k, kr = k < n - 1 ? k + 1 : k;
          const double patch = 0.5 * (y(n + kr) - y(n + kl));
          fx = patch * (-kPi * rk * rk * gi + (kPi * rk * rk - annulus(rk).S) * go) -
               Pi(k) * kPi * (y(kr) * y(kr) - y(kl) * y(kl)) / 2;
        }
        res(n + k) = (F(0, k) + fx) / (Y * 2 * kPi * R0);
      }
      res(n) = (y(n) - X0(0, 0)) / R0;  // gauge: the rear rim's axial position
    }
    if (!recovering)
      for (int s = 0; s < active; ++s) res(m - active + s) = seg_mean(y, s) - target[s];
    return res;
  };

  Eigen::VectorXd y(m0);
  for (int k = 0; k < n; ++k) {
    y(k) = R0;
    if (free_rings) y(n + k) = X0(0, k);
  }
  std::printf("wall %s%s, ends %s, %d rings, dt %.3g ms, L %.0f nm, load %.3g Pa, R_f %.3g R0\n", o.wall.c_str(),
              o.fluid_axial ? " with the fluid's axial force" : "", o.rest_ends ? "rest" : "mirror", n, o.dt * 1e3,
              L * 1e9, o.pressure, o.ratio);
  double t = 0, t_event = 0;
  // the record every 0.5 ms: what `swim run` replays as wave.kind = "recorded" (its flow model on
  // this wall motion, the rings at their reference positions)
  FILE* rec = nullptr;
  if (!o.record.empty()) {
    rec = std::fopen(o.record.c_str(), "w");
    if (!rec) usage(("cannot write " + o.record).c_str());
    std::fprintf(rec, "t_s,z_m,radius_m\n");
  }
  double next_record = 0.0, last_written = -1.0;
  auto write_state = [&]() {
    for (int k = 0; k < n; ++k) std::fprintf(rec, "%.9g,%.9g,%.12g\n", t, X0(0, k), y(k));
    last_written = t;
  };
  auto record = [&]() {
    if (!rec || t < next_record - 1e-12) return;
    write_state();
    next_record += 5e-4;
  };
  record();
  const double reach = o.ratio * (1 + o.tol);
  int last_back = -1;
  while (true) {
    if (t - t_event > 0.5 && !recovering) {  // ten times the slowest segment of these tubes
      std::printf("segment %d stalls: %.4f R0 after %.0f ms (its static radius under the load lies above R_f)\n",
                  active, seg_mean(y, active), (t - t_event) * 1e3);
      return 3;
    }
    const Eigen::VectorXd y_old = y;
    const int m = int(y.size());
    for (int it = 0;; ++it) {
      const Eigen::VectorXd r = residual(y, y_old);
      if (it > 0 && r.cwiseAbs().maxCoeff() < 2e-11) break;
      Eigen::MatrixXd J(m, m);
      for (int c = 0; c < m; ++c) {
        Eigen::VectorXd yp = y;
        const double e = c < m0 ? 1e-7 * R0 : 1e-7;
        yp(c) += e;
        J.col(c) = (residual(yp, y_old) - r) / e;
      }
      const Eigen::VectorXd d = J.partialPivLu().solve(-r);
      y += d;
      double step = 0;
      for (int c = 0; c < m; ++c) step = std::max(step, std::abs(d(c)) / (c < m0 ? R0 : 1.0));
      if (step < 1e-9) break;
      // near the front rim the free rings' axial rows converge linearly (the fluid's axial force
      // is differentiated by finite differences): accept an update at 1e-6 R0 (0.1 pm) after 20
      // iterations
      if (it >= 20 && step < 1e-6) break;
      if (it == 100) {
        std::printf("Newton did not converge at t = %.2f ms (largest update %.3g)\n", t * 1e3, step);
        int worst = 0;
        for (int c = 0; c < m; ++c)
          if (std::abs(d(c)) / (c < m0 ? R0 : 1.0) > std::abs(d(worst)) / (worst < m0 ? R0 : 1.0)) worst = c;
        if (worst < m0) {
          const int k = worst % n;
          std::printf("  the largest update: the %s of the ring %.1f nm from the front end (r %.4f R0)\n",
                      worst < n ? "radius" : "axial position", (L - X0(0, k)) * 1e9, y(k) / R0);
        }
        return 3;
      }
    }
    t += o.dt;
    record();
    if (recovering) {
      int worst = 0;
      for (int k = 0; k < n; ++k)
        if (std::abs(y(k) - R0) > std::abs(y(worst) - R0)) worst = k;
      if (std::abs(y(worst) - R0) < o.tol * R0) {
        const double len = free_rings ? (y(2 * n - 1) - y(n)) * 1e9 : L * 1e9;
        std::printf("recovery: every ring within %.3g R0 of R0 after %.1f ms (cycle %.1f ms); the last to come back: the ring "
                    "%.1f nm from the front end; length %.1f nm\n",
                    o.tol, (t - t_event) * 1e3, t * 1e3, (L - X0(0, last_back)) * 1e9, len);
        if (rec) {
          if (t > last_written) write_state();  // the cycle's last state
          std::fclose(rec);
        }
        return 0;
      }
      last_back = worst;
      if (t - t_event > 1.0) {
        std::printf("recovery: not within %.3g R0 after 1 s (ring %.1f nm from the front end at %.4f R0)\n", o.tol,
                    (L - X0(0, worst)) * 1e9, y(worst) / R0);
        return 3;
      }
      continue;
    }
    if (seg_mean(y, active) <= reach) {
      const double len = free_rings ? (y(2 * n - 1) - y(n)) * 1e9 : L * 1e9;
      if (active + 1 < o.segments)
        std::printf("segment %d reaches %.3f R0 after %.1f ms (t = %.1f ms); segment %d at %.4f R0; length %.1f nm\n",
                    active, reach, (t - t_event) * 1e3, t * 1e3, active + 1, seg_mean(y, active + 1), len);
      else
        std::printf("segment %d reaches %.3f R0 after %.1f ms (t = %.1f ms); length %.1f nm\n", active, reach,
                    (t - t_event) * 1e3, t * 1e3, len);
      target.push_back(seg_mean(y, active));
      ++active;
      t_event = t;
      if (active == o.segments) {  // the recovery: every load released
        recovering = true;
        y.conservativeResize(m0);
        continue;
      }
      Eigen::VectorXd grown(m + 1);
      grown.head(m) = y;
      grown(m) = o.pressure;  // the held load starts at the load it had
      y = grown;
    }
  }
}
