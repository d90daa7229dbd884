// swim_fold_study: what holds the round wall's folded front rim, on which the hooked cases'
// recovery waits (docs/axi.md, "The triangles on the rims that hook"), and how that moves with
// the rings' spacing.
//
// Input: a run folder of the axisymmetric tier (its scene.resolved.json and checkpoint.bin: the
// wall as it was at the last checkpoint; run with axi.time_limit and axi.checkpoint_interval
// chosen so that a checkpoint falls at the time wanted). The wall is axi::AxiWall with the run's
// parameters. With --refine m each reference interval is cut into m (the shape carried over by a
// cubic spline in the reference position through the rings' x and r), so the same shape is
// resolved by m times the rings.
//
// Output: the fold's gap (the smallest distance from a ring to a wall segment at least four rings
// away along the wall: the folded rim's tip against the wall's outer layer), and for the shape as
// given and each refinement asked for:
//  - the unloaded wall's equilibrium Newton reaches from the shape (axi::relax_under_ring_
//    pressures under a load of 10^-12 Pa): how far from round, and the five smallest eigenvalues
//    of its stiffness (the energy's Hessian with x_0 held, N/m);
//  - with --horizon, the gradient flow of the wall alone under a local drag (ring force =
//    zeta A_k dX/dt, zeta = 1 Pa s/m, backward Euler with Newton on the stiffness): the time until
//    every ring is within 1 nm of R0. A wall that unfolds in microseconds under a drag of this
//    size holds no fold of its own: what holds it in the run is the fluid. A study, not a solver.
#include <Eigen/Dense>
#include <gsl/gsl_spline.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "axi/scene_axi.hpp"
#include "axi/wall_axi.hpp"
#include "common/errors.hpp"
#include "common/scene.hpp"
#include "full3d/checkpoint.hpp"
#include "full3d/run3d_checkpoint.hpp"

namespace {

struct Shape {
  double t = 0, R0 = 0, L = 0, ks = 0, D = 0;
  bool coupling = true;
  std::vector<double> s0, x, r;
};

Shape read_run(const std::string& dir) {
  const swim::scene::json resolved = swim::scene::load_file(dir + "/scene.resolved.json");
  swim::scene::json again;
  const swim::axi::ParamsAxi p = swim::axi::read_scene_axi(resolved, again);
  const swim::full3d::CheckpointReader rd(dir + "/checkpoint.bin", swim::full3d::RunCheckpoint::scene_hash(resolved));
  const swim::axi::AxiWall wall(
      swim::axi::AxiWallParams{p.base.R0, p.base.L, p.ks, p.D, p.wall_nodes, p.ring_s0, p.poisson_coupling});
  const std::vector<double> X = rd.get_vector("X");
  const int n = wall.nodes();
  if (X.size() != std::size_t(3 * n)) rd.damaged("its wall X has " + std::to_string(X.size()) + " values, not 3 x " + std::to_string(n));
  Shape s;
  s.t = rd.get_double("t"), s.R0 = p.base.R0, s.L = p.base.L, s.ks = p.ks, s.D = p.D, s.coupling = p.poisson_coupling;
  for (int k = 0; k < n; ++k) s.s0.push_back(wall.reference()(0, k)), s.x.push_back(X[3 * k]), s.r.push_back(X[3 * k + 1]);
  return s;
}

// the smallest distance from a ring to a wall segment at least four rings away along the wall
double fold_gap(const Shape& s, int* ring, int* segment) {
  const int n = int(s.s0.size());
  double best = 1e300;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j + 1 < n; ++j) {
      if (std::abs(j - k) < 4 && std::abs(j + 1 - k) < 4) continue;
      const double ax = s.x[j], ar = s.r[j], bx = s.x[j + 1] - ax, br = s.r[j + 1] - ar;
      const double u = std::clamp(((s.x[k] - ax) * bx + (s.r[k] - ar) * br) / (bx * bx + br * br), 0.0, 1.0);
      const double d = std::hypot(s.x[k] - ax - u * bx, s.r[k] - ar - u * br);
      if (d < best) best = d, *ring = k, *segment = j;
    }
  return best;
}

// natural cubic spline through (t_k, y_k) (GSL's cspline)
class Spline {
 public:
  Spline(const std::vector<double>& t, const std::vector<double>& y)
      : s_(gsl_spline_alloc(gsl_interp_cspline, t.size()), gsl_spline_free),
        acc_(gsl_interp_accel_alloc(), gsl_interp_accel_free) {
    gsl_spline_init(s_.get(), t.data(), y.data(), t.size());
  }
  double operator()(double u) const { return gsl_spline_eval(s_.get(), u, acc_.get()); }

 private:
  std::unique_ptr<gsl_spline, void (*)(gsl_spline*)> s_;
  std::unique_ptr<gsl_interp_accel, void (*)(gsl_interp_accel*)> acc_;
};

Shape refine(const Shape& s, int m) {
  if (m == 1) return s;
  Shape o = s;
  o.s0.clear(), o.x.clear(), o.r.clear();
  const Spline X(s.s0, s.x), R(s.s0, s.r);
  for (std::size_t k = 0; k + 1 < s.s0.size(); ++k)
    for (int j = 0; j < m; ++j) o.s0.push_back(s.s0[k] + (s.s0[k + 1] - s.s0[k]) * j / m);
  o.s0.push_back(s.s0.back());
  for (double u : o.s0) o.x.push_back(X(u)), o.r.push_back(R(u));
  return o;
}

Eigen::Matrix3Xd positions(const Shape& s) {
  Eigen::Matrix3Xd X = Eigen::Matrix3Xd::Zero(3, long(s.s0.size()));
  for (std::size_t k = 0; k < s.s0.size(); ++k) X(0, long(k)) = s.x[k] - s.x[0], X(1, long(k)) = s.r[k];
  return X;
}

double max_dev(const Eigen::Matrix3Xd& X, double R0) { return (X.row(1).array() - R0).abs().maxCoeff(); }

// the stiffness with x_0 held (row/column 0 of the [x_0, r_0, x_1, ...] ordering removed), dense
Eigen::MatrixXd held_stiffness(const swim::axi::AxiWall& w, const Eigen::Matrix3Xd& X) {
  const Eigen::MatrixXd K(w.stiffness(X, 1e-4 * w.min_ds0()));
  return K.bottomRightCorner(K.rows() - 1, K.cols() - 1);
}

void equilibrium(const swim::axi::AxiWall& w, const Eigen::Matrix3Xd& X, double R0) {
  const int n = w.nodes();
  const double fscale = w.params().ks * 2 * 3.14159265358979 * R0 * w.min_ds0() / R0;
  try {
    const auto res =
        swim::axi::relax_under_ring_pressures(w, std::vector<double>(n, 1e-12), X, 1e-6 * fscale, 200);
    const auto e = w.energies(res.X);
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(held_stiffness(w, res.X));
    std::printf("    equilibrium (Newton, %d iterations): largest |R - R0| %.3f nm, stretching %.3e J, bending %.3e J;"
                " smallest stiffness eigenvalues",
                res.iterations, 1e9 * max_dev(res.X, R0), e[0], e[1]);
    for (int i = 0; i < 5; ++i) std::printf(" %.3e", es.eigenvalues()(i));
    std::printf(" N/m\n");
  } catch (const std::exception& ex) {
    std::printf("    equilibrium: Newton from this shape did not converge (%s)\n", ex.what());
  }
}

// backward Euler of zeta A_k dX/dt = F(X), x_0 held; returns the time every ring comes within
// 1 nm of R0 (negative: not within the horizon)
double gradient_flow(const swim::axi::AxiWall& w, Eigen::Matrix3Xd X, double R0, double horizon, double* dev_mid) {
  const int n = w.nodes(), m = 2 * n - 1;
  const double zeta = 1.0;
  Eigen::VectorXd c(m);
  // ordering without x_0: [r_0, x_1, r_1, x_2, r_2, ...]: index of r_k = 2k, of x_k = 2k - 1
  for (int k = 0; k < n; ++k) {
    c(2 * k) = zeta * w.node_area()(k);
    if (k > 0) c(2 * k - 1) = zeta * w.node_area()(k);
  }
  auto pack = [&](const Eigen::Matrix3Xd& F) {
    Eigen::VectorXd v(m);
    for (int k = 0; k < n; ++k) {
      v(2 * k) = F(1, k);
      if (k > 0) v(2 * k - 1) = F(0, k);
    }
    return v;
  };
  double t = 0, dt = 1e-6;
  *dev_mid = -1;
  while (t < horizon) {
    if (max_dev(X, R0) < 1e-9) return t;
    Eigen::Matrix3Xd Y = X;
    bool ok = false;
    for (int it = 0; it < 20; ++it) {
      const Eigen::VectorXd F = pack(w.forces(Y));
      Eigen::VectorXd d(m);
      for (int k = 0; k < n; ++k) {
        d(2 * k) = Y(1, k) - X(1, k);
        if (k > 0) d(2 * k - 1) = Y(0, k) - X(0, k);
      }
      const Eigen::VectorXd G = c.cwiseProduct(d) / dt - F;
      const Eigen::MatrixXd J = Eigen::MatrixXd(c.asDiagonal()) / dt + held_stiffness(w, Y);
      const Eigen::VectorXd du = J.partialPivLu().solve(-G);
      for (int k = 0; k < n; ++k) {
        Y(1, k) += du(2 * k);
        if (k > 0) Y(0, k) += du(2 * k - 1);
      }
      if (du.cwiseAbs().maxCoeff() < 1e-7 * w.min_ds0()) {
        ok = true;
        break;
      }
    }
    if (!ok) {
      dt *= 0.5;
      continue;
    }
    const double change = (Y - X).cwiseAbs().maxCoeff();
    X = Y;
    t += dt;
    if (*dev_mid < 0 && t >= 0.5 * horizon) *dev_mid = max_dev(X, R0);
    dt *= std::clamp(0.02 * w.min_ds0() / std::max(change, 1e-30), 0.5, 1.5);
  }
  return -1;
}

}  // namespace

int main(int argc, char** argv) try {
  if (argc < 2) {
    std::fprintf(stderr, "usage: swim_fold_study RUN_DIR [--refine m1,m2,...] [--horizon s]\n");
    return 2;
  }
  const Shape s = read_run(argv[1]);
  std::vector<int> refinements{1};
  double horizon = 0;
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--refine" && i + 1 < argc) {
      refinements.clear();
      std::stringstream ss(argv[++i]);
      for (std::string v; std::getline(ss, v, ',');) refinements.push_back(std::stoi(v));
    } else if (a == "--horizon" && i + 1 < argc) {
      horizon = std::stod(argv[++i]);
    } else {
      std::fprintf(stderr, "swim_fold_study: unknown argument %s\n", a.c_str());
      return 2;
    }
  }
  int ring = 0, segment = 0;
  const double gap = fold_gap(s, &ring, &segment);
  std::printf("wall at t = %.4f s: %zu rings, R0 %.1f nm, L %.1f nm, ks %.3g N/m, D %.4g J, largest |R - R0| %.3f nm;"
              " the fold's gap %.2f nm (ring %d to the segment of rings %d-%d)\n",
              s.t, s.s0.size(), 1e9 * s.R0, 1e9 * s.L, s.ks, s.D, 1e9 * max_dev(positions(s), s.R0), 1e9 * gap, ring,
              segment, segment + 1);
  for (int m : refinements) {
    const Shape f = refine(s, m);
    swim::axi::AxiWall w(swim::axi::AxiWallParams{s.R0, s.L, s.ks, s.D, int(f.s0.size()), f.s0, s.coupling});
    const Eigen::Matrix3Xd X = positions(f);
    const auto e = w.energies(X);
    std::printf("  refinement %d: %d rings, smallest spacing %.2f nm; the shape's stretching %.3e J, bending %.3e J\n", m,
                w.nodes(), 1e9 * w.min_ds0(), e[0], e[1]);
    equilibrium(w, X, s.R0);
    if (horizon > 0) {
      double mid = 0;
      const double tr = gradient_flow(w, X, s.R0, horizon, &mid);
      if (tr >= 0)
        std::printf("    gradient flow (zeta = 1 Pa s/m): within 1 nm of round after %.4g s\n", tr);
      else
        std::printf("    gradient flow (zeta = 1 Pa s/m): not round within %.3g s (largest |R - R0| %.3f nm at half of it)\n",
                    horizon, 1e9 * mid);
    }
  }
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "swim_fold_study: %s\n", e.what());
  return 2;
}
