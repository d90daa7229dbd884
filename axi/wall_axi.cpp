#include "axi/wall_axi.hpp"

#include <Eigen/Sparse>
#include <Eigen/SparseLU>
#include <cmath>
#include <string>
#include <vector>

#include "common/errors.hpp"

namespace swim::axi {

namespace {
constexpr double kSqrt3 = 1.7320508075688772935;
}

double stretching_density(double ks, double ls, double lt, double* dW_dls, double* dW_dlt) {
  const double c = ks / kSqrt3;
  const double q = std::sqrt(0.25 * lt * lt + 0.75 * ls * ls);
  const double a = lt - 1.0, b = q - 1.0;
  if (dW_dls) *dW_dls = 3.0 * c * b * ls / q;
  if (dW_dlt) *dW_dlt = c * (2.0 * a + b * lt / q);
  return c * (a * a + 2.0 * b * b);
}

AxiWall::AxiWall(const AxiWallParams& p) : p_(p) {
  const auto bad = [](double v) { return !std::isfinite(v); };
  if (bad(p.R0) || !(p.R0 > 0)) throw InputError("swimmer.radius", std::to_string(p.R0), "must be > 0");
  if (bad(p.L) || !(p.L > 0)) throw InputError("swimmer.length", std::to_string(p.L), "must be > 0");
  if (p.nodes < 3) throw InputError("axi.spacing_factor", std::to_string(p.nodes), "the wall needs at least 3 nodes");
  if (bad(p.ks) || !(p.ks > 0)) throw InputError("wall.spring_constant", std::to_string(p.ks), "must be > 0");
  if (bad(p.D) || !(p.D >= 0)) throw InputError("full3d.membrane.bending_rigidity", std::to_string(p.D), "must be >= 0");
  n_ = p.nodes;
  h_ = p.L / (n_ - 1);
  X0_ = Eigen::Matrix3Xd::Zero(3, n_);
  A_.resize(n_);
  for (int k = 0; k < n_; ++k) {
    X0_(0, k) = k * h_;
    X0_(1, k) = p.R0;
    A_[k] = 2.0 * M_PI * p.R0 * h_ * (k == 0 || k == n_ - 1 ? 0.5 : 1.0);
  }
}

std::array<double, 2> AxiWall::energies(const Eigen::Matrix3Xd& X) const {
  std::array<double, 2> e{};
  evaluate(X, nullptr, &e);
  return e;
}

Eigen::Matrix3Xd AxiWall::forces(const Eigen::Matrix3Xd& X, std::array<double, 2>* energy) const {
  Eigen::Matrix3Xd F = Eigen::Matrix3Xd::Zero(3, n_);
  std::array<double, 2> e{};
  evaluate(X, &F, &e);
  if (energy) *energy = e;
  return F;
}

double AxiWall::uniform_energy(double R) const {
  return 2.0 * M_PI * p_.R0 * p_.L * stretching_density(p_.ks, 1.0, R / p_.R0);
}

double AxiWall::evaluate(const Eigen::Matrix3Xd& X, Eigen::Matrix3Xd* F, std::array<double, 2>* energy) const {
  if (X.cols() != n_) throw InputError("wall", std::to_string(X.cols()), "positions must have one column per wall node");
  const double R0 = p_.R0, h = h_, a = 2.0 * M_PI * R0, D = p_.D, nu = kWallPoisson;
  const int ne = n_ - 1;
  // per segment: vector, length, hoop bending strain and its gradient
  std::vector<double> dx(ne), dr(ne), l2(ne), kt(ne), gkt(ne, 0.0);
  double Es = 0.0, Eb = 0.0;
  const double g1 = 0.5 - 0.5 / kSqrt3, g2 = 0.5 + 0.5 / kSqrt3;
  const bool grad = F != nullptr;
  // gradient accumulated as dE/dX (F = -G at the end)
  auto add = [&](int k, double gx, double gr) {
    (*F)(0, k) -= gx;
    (*F)(1, k) -= gr;
  };
  for (int e = 0; e < ne; ++e) {
    dx[e] = X(0, e + 1) - X(0, e);
    dr[e] = X(1, e + 1) - X(1, e);
    l2[e] = dx[e] * dx[e] + dr[e] * dr[e];
    const double l = std::sqrt(l2[e]);
    const double ls = l / h;
    double Wls[2], Wlt[2];
    const double lt1 = (X(1, e) + g1 * dr[e]) / R0, lt2 = (X(1, e) + g2 * dr[e]) / R0;
    Es += 0.5 * a * h * (stretching_density(p_.ks, ls, lt1, &Wls[0], &Wlt[0]) +
                         stretching_density(p_.ks, ls, lt2, &Wls[1], &Wlt[1]));
    kt[e] = (dx[e] / l - 1.0) / R0;
    if (grad) {
      const double dEdls = 0.5 * a * h * (Wls[0] + Wls[1]);
      const double sx = dEdls * dx[e] / (l * h), sr = dEdls * dr[e] / (l * h);
      const double c1 = 0.5 * a * h * Wlt[0] / R0, c2 = 0.5 * a * h * Wlt[1] / R0;
      add(e + 1, sx, sr + c1 * g1 + c2 * g2);
      add(e, -sx, -sr + c1 * (1.0 - g1) + c2 * (1.0 - g2));
    }
  }
  if (D > 0.0) {
    const double cb = 0.5 * a * D;
    for (int e = 0; e < ne; ++e) {
      Eb += cb * h * kt[e] * kt[e];
      gkt[e] += cb * 2.0 * h * kt[e];
    }
    for (int k = 1; k + 1 < n_; ++k) {
      const double w = n_ == 3 ? 2.0 * h : (k == 1 || k == n_ - 2) ? 1.5 * h : h;
      const int ea = k - 1, eb = k;
      const double cross = dx[ea] * dr[eb] - dr[ea] * dx[eb], dot = dx[ea] * dx[eb] + dr[ea] * dr[eb];
      const double th = std::atan2(cross, dot);
      const double ks = th / h, kbar = 0.5 * (kt[ea] + kt[eb]);
      Eb += cb * w * (ks * ks + 2.0 * nu * ks * kbar);
      if (grad) {
        const double dks = cb * w * (2.0 * ks + 2.0 * nu * kbar);
        const double dkbar = cb * w * 2.0 * nu * ks;
        gkt[ea] += 0.5 * dkbar;
        gkt[eb] += 0.5 * dkbar;
        // d theta / d(segment a) = (a_r, -a_x)/|a|^2, d theta / d(segment b) = (-b_r, b_x)/|b|^2
        const double s = dks / h;
        const double ax = s * dr[ea] / l2[ea], ar = -s * dx[ea] / l2[ea];
        const double bx = -s * dr[eb] / l2[eb], br = s * dx[eb] / l2[eb];
        add(k, ax, ar);
        add(k - 1, -ax, -ar);
        add(k + 1, bx, br);
        add(k, -bx, -br);
      }
    }
    if (grad)
      for (int e = 0; e < ne; ++e) {
        const double l3 = l2[e] * std::sqrt(l2[e]);
        const double gx = gkt[e] * dr[e] * dr[e] / (l3 * R0), gr = -gkt[e] * dx[e] * dr[e] / (l3 * R0);
        add(e + 1, gx, gr);
        add(e, -gx, -gr);
      }
  }
  if (energy) *energy = {Es, Eb};
  return Es + Eb;
}

AxiPressureResponse relax_under_pressure(const AxiWall& wall, double P, double tol_force, int max_iterations) {
  if (!std::isfinite(P) || P == 0.0) throw InputError("pressure", std::to_string(P), "must be finite and non-zero");
  if (max_iterations < 1) throw InputError("max_iterations", std::to_string(max_iterations), "must be >= 1");
  const int n = wall.nodes();
  const Eigen::VectorXd& A = wall.node_area();
  if (!(tol_force > 0)) tol_force = 1e-9 * std::abs(P) * A.maxCoeff();
  // unknowns: x_1..x_{n-1} (index k-1), r_0..r_{n-1} (index n-1+k)
  const int m = 2 * n - 1;
  auto residual = [&](const Eigen::Matrix3Xd& X) {
    const Eigen::Matrix3Xd F = wall.forces(X);
    Eigen::VectorXd g(m);
    for (int k = 1; k < n; ++k) g[k - 1] = -F(0, k);
    for (int k = 0; k < n; ++k) g[n - 1 + k] = -F(1, k) + P * A[k];
    return g;
  };
  auto apply = [&](Eigen::Matrix3Xd& X, const Eigen::VectorXd& d, double s) {
    for (int k = 1; k < n; ++k) X(0, k) += s * d[k - 1];
    for (int k = 0; k < n; ++k) X(1, k) += s * d[n - 1 + k];
  };
  AxiPressureResponse res;
  res.X = wall.reference();
  Eigen::VectorXd g = residual(res.X);
  const double eps = 1e-7 * wall.params().R0;
  for (int it = 0;; ++it) {
    res.max_residual_force = g.cwiseAbs().maxCoeff();
    res.iterations = it;
    if (res.max_residual_force < tol_force) break;
    if (it >= max_iterations)
      throw NumericalError("the static wall did not reach equilibrium under " + std::to_string(P) + " Pa in " +
                               std::to_string(max_iterations) + " Newton steps",
                           "lower the load");
    // banded Jacobian by central differences, 5 colours per coordinate (a node couples to
    // at most 2 neighbours each side)
    std::vector<Eigen::Triplet<double>> trip;
    for (int comp = 0; comp < 2; ++comp)
      for (int colour = 0; colour < 5; ++colour) {
        Eigen::Matrix3Xd Xp = res.X, Xm = res.X;
        for (int k = colour; k < n; k += 5) {
          if (comp == 0 && k == 0) continue;
          Xp(comp, k) += eps;
          Xm(comp, k) -= eps;
        }
        const Eigen::VectorXd d = (residual(Xp) - residual(Xm)) / (2.0 * eps);
        for (int k = colour; k < n; k += 5) {
          if (comp == 0 && k == 0) continue;
          const int col = comp == 0 ? k - 1 : n - 1 + k;
          for (int j = std::max(0, k - 2); j <= std::min(n - 1, k + 2); ++j) {
            if (j >= 1 && d[j - 1] != 0.0) trip.emplace_back(j - 1, col, d[j - 1]);
            if (d[n - 1 + j] != 0.0) trip.emplace_back(n - 1 + j, col, d[n - 1 + j]);
          }
        }
      }
    Eigen::SparseMatrix<double> J(m, m);
    J.setFromTriplets(trip.begin(), trip.end());
    Eigen::SparseLU<Eigen::SparseMatrix<double>> lu;
    lu.compute(J);
    if (lu.info() != Eigen::Success) throw NumericalError("singular Jacobian of the static wall", "lower the load");
    const Eigen::VectorXd d = lu.solve(-g);
    double s = 1.0;
    const double norm0 = g.norm();
    for (int back = 0;; ++back) {
      Eigen::Matrix3Xd Xt = res.X;
      apply(Xt, d, s);
      const Eigen::VectorXd gt = residual(Xt);
      if ((gt.allFinite() && gt.norm() < norm0) || back >= 20) {
        res.X = Xt;
        g = gt;
        break;
      }
      s *= 0.5;
    }
  }
  res.mid_radius = n % 2 ? res.X(1, n / 2) : 0.5 * (res.X(1, n / 2 - 1) + res.X(1, n / 2));
  res.c1 = P / (wall.params().R0 - res.mid_radius);
  return res;
}

}  // namespace swim::axi
