#include "axi/wall_axi.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "common/errors.hpp"
#include "common/si_format.hpp"

namespace swim::axi {

namespace {
constexpr double kPi = std::numbers::pi;
constexpr double kSqrt3 = 1.7320508075688772935;
// 2-point Gauss on [0, 1]
constexpr double kXi1 = 0.5 - 0.5 / kSqrt3, kXi2 = 0.5 + 0.5 / kSqrt3;

/// Band matrix (kl sub-, ku super-diagonals) with room for the fill of partial pivoting;
/// row i stores columns i - kl .. i + ku + kl.
class BandLU {
 public:
  BandLU(int n, int kl, int ku) : n_(n), kl_(kl), ku_(ku), w_(2 * kl + ku + 1), a_(size_t(n) * w_, 0.0) {}
  double& at(int i, int j) { return a_[size_t(i) * w_ + (j - i + kl_)]; }
  /// Solves A x = b in place (A is destroyed). False on a zero pivot.
  bool solve(Eigen::VectorXd& b) {
    const int up = ku_ + kl_;
    for (int k = 0; k < n_; ++k) {
      const int last = std::min(n_ - 1, k + kl_);
      int p = k;
      for (int i = k + 1; i <= last; ++i)
        if (std::abs(at(i, k)) > std::abs(at(p, k))) p = i;
      if (!(at(p, k) != 0.0) || !std::isfinite(at(p, k))) return false;
      const int jmax = std::min(n_ - 1, k + up);
      if (p != k) {
        for (int j = k; j <= jmax; ++j) std::swap(at(k, j), at(p, j));
        std::swap(b[k], b[p]);
      }
      const double piv = at(k, k);
      for (int i = k + 1; i <= last; ++i) {
        const double m = at(i, k) / piv;
        if (m == 0.0) continue;
        for (int j = k + 1; j <= jmax; ++j) at(i, j) -= m * at(k, j);
        b[i] -= m * b[k];
      }
    }
    for (int k = n_ - 1; k >= 0; --k) {
      double s = b[k];
      const int jmax = std::min(n_ - 1, k + up);
      for (int j = k + 1; j <= jmax; ++j) s -= at(k, j) * b[j];
      b[k] = s / at(k, k);
    }
    return b.allFinite();
  }

 private:
  int n_, kl_, ku_, w_;
  std::vector<double> a_;
};
/// Sum of squares, NaN-propagating (a plain loop: GCC 12 flags Eigen's AVX-512 reductions of
/// dynamic vectors as maybe-uninitialised).
double sum_sq(const Eigen::VectorXd& v) {
  double s = 0.0;
  for (Eigen::Index i = 0; i < v.size(); ++i) s += v[i] * v[i];
  return s;
}
}  // namespace

double stretching_density(double ks, double ls, double lt, double* dW_dls, double* dW_dlt, bool coupled) {
  const double c = ks / kSqrt3;
  if (!coupled) {  // Y / 2 = c
    const double et = lt - 1.0, es = ls - 1.0;
    if (dW_dls) *dW_dls = 2.0 * c * es;
    if (dW_dlt) *dW_dlt = 2.0 * c * et;
    return c * (et * et + es * es);
  }
  const double q = std::sqrt(0.25 * lt * lt + 0.75 * ls * ls);
  const double et = lt - 1.0, eq = q - 1.0;
  if (dW_dls || dW_dlt) {
    const double f = eq / q;  // d(q-1)^2/dq / (2 q)
    if (dW_dls) *dW_dls = 3.0 * c * f * ls;
    if (dW_dlt) *dW_dlt = c * (2.0 * et + f * lt);
  }
  return c * (et * et + 2.0 * eq * eq);
}

AxiWall::AxiWall(const AxiWallParams& p) : p_(p) {
  if (!(p.R0 > 0.0) || !std::isfinite(p.R0)) throw InputError("swimmer.R0", significant(p.R0), "a positive radius in m");
  if (!(p.L > 0.0) || !std::isfinite(p.L)) throw InputError("swimmer.L", significant(p.L), "a positive length in m");
  if (p.nodes < 3)
    throw InputError("axi wall nodes", std::to_string(p.nodes), "an integer >= 3 (meridian nodes of the wall)");
  if (!(p.ks > 0.0) || !std::isfinite(p.ks))
    throw InputError("axi wall spring constant ks", significant(p.ks), "a positive spring constant in N/m");
  if (!(p.D >= 0.0) || !std::isfinite(p.D))
    throw InputError("axi wall bending rigidity D", significant(p.D), "a non-negative bending rigidity in J");
  n_ = p.nodes;
  if (!p.s0.empty()) {
    bool ok = int(p.s0.size()) == n_ && p.s0.front() == 0.0 && p.s0.back() == p.L;
    for (int k = 1; ok && k < n_; ++k) ok = p.s0[k] > p.s0[k - 1];
    if (!ok)
      throw InputError("axi wall reference positions", std::to_string(p.s0.size()) + " values",
                       std::to_string(n_) + " strictly increasing positions from 0 to L (m)");
  }
  X0_.setZero(3, n_);
  for (int k = 0; k < n_; ++k) {
    X0_(0, k) = !p.s0.empty() ? p.s0[k] : k == n_ - 1 ? p.L : k * (p.L / (n_ - 1));
    X0_(1, k) = p.R0;
  }
  h0_.resize(n_ - 1);
  for (int e = 0; e + 1 < n_; ++e) h0_[e] = X0_(0, e + 1) - X0_(0, e);
  h_ = p.s0.empty() ? p.L / (n_ - 1) : h0_.maxCoeff();
  h_min_ = p.s0.empty() ? h_ : h0_.minCoeff();
  A_.resize(n_);
  w_.setZero(n_);
  for (int k = 0; k < n_; ++k) {
    const double left = k > 0 ? h0_[k - 1] : 0.0, right = k + 1 < n_ ? h0_[k] : 0.0;
    A_[k] = kPi * p.R0 * (left + right);
    if (k == 0 || k == n_ - 1) continue;
    w_[k] = 0.5 * (left + right);
    if (k == 1) w_[k] += 0.5 * h0_[0];            // the rear end's half-cell
    if (k == n_ - 2) w_[k] += 0.5 * h0_[n_ - 2];  // the front end's half-cell
  }
}

std::vector<double> graded_ring_positions(double L, double spacing, double end_ratio, double growth) {
  if (!(std::isfinite(end_ratio) && end_ratio > 0.0 && end_ratio <= 1.0))
    throw InputError("axi.rim_refinement", significant(end_ratio), "a ratio in (0, 1] (1: uniform ring spacing)");
  if (!(std::isfinite(growth) && growth > 1.0))
    throw InputError("axi.rim_refinement", "growth " + significant(growth), "a growth ratio > 1");
  if (!(std::isfinite(L) && L > 0.0 && std::isfinite(spacing) && spacing > 0.0 && spacing <= L))
    throw InputError("axi.spacing_factor", significant(spacing) + " m", "a ring spacing in (0, L = " + significant(L) + " m]");
  // at each end the spacings d end_ratio growth^i (i = 0..m-1, all below d), inwards from the
  // rim; between them `mid` uniform spacings d: L = d (mid + 2 c), c = sum_i end_ratio growth^i
  std::vector<double> ratios;
  for (double w = end_ratio; w < 1.0 - 1e-9; w *= growth) ratios.push_back(w);
  double c = 0.0;
  for (double w : ratios) c += w;
  const int mid = std::max(1, int(std::ceil(L / spacing - 2.0 * c - 1e-9)));
  const double d = L / (mid + 2.0 * c);
  std::vector<double> end;
  for (double w : ratios) end.push_back(w * d);
  std::vector<double> s{0.0};
  for (auto it = end.begin(); it != end.end(); ++it) s.push_back(s.back() + *it);
  const double a = s.back(), b = L - a;
  for (int i = 1; i < mid; ++i) s.push_back(a + (b - a) * i / mid);
  s.push_back(b);
  for (auto it = end.rbegin(); it != end.rend(); ++it) s.push_back(s.back() + *it);
  s.back() = L;
  for (size_t k = 1; k < s.size(); ++k)
    if (!(s[k] > s[k - 1]))
      throw InputError("axi.rim_refinement", significant(end_ratio), "too fine for the swimmer's length; use a larger ratio");
  return s;
}

double AxiWall::uniform_energy(double R) const {
  return 2.0 * kPi * p_.R0 * p_.L * stretching_density(p_.ks, 1.0, R / p_.R0, nullptr, nullptr, p_.poisson_coupling);
}

std::array<double, 2> AxiWall::energies(const Eigen::Matrix3Xd& X) const {
  std::array<double, 2> e{};
  evaluate(X, nullptr, &e);
  return e;
}

Eigen::Matrix3Xd AxiWall::forces(const Eigen::Matrix3Xd& X, std::array<double, 2>* energy) const {
  Eigen::Matrix3Xd F(3, n_);
  evaluate(X, &F, energy);
  return F;
}

double AxiWall::evaluate(const Eigen::Matrix3Xd& X, Eigen::Matrix3Xd* F, std::array<double, 2>* energy) const {
  if (X.cols() != n_)
    throw InputError("axi wall positions", std::to_string(X.cols()) + " columns",
                     "3 x " + std::to_string(n_) + " (one column per wall node)");
  const int n = n_, ne = n - 1;
  const double R0 = p_.R0, ks = p_.ks, D = p_.D, nu = kWallPoisson;
  const bool coupled = p_.poisson_coupling;
  const double inv_R0 = 1.0 / R0;
  const double G = kPi * R0 * D;   // 2 pi R0 * D/2
  const bool grad = F != nullptr;
  if (grad) F->setZero();

  // per segment: unit tangent (c, s) = (cos psi, sin psi), length l, k_t, dE/dk_t, dE/dpsi
  Eigen::Matrix<double, 6, Eigen::Dynamic> S(6, ne);
  double Es = 0.0;
  for (int e = 0; e < ne; ++e) {
    const double dx = X(0, e + 1) - X(0, e), dr = X(1, e + 1) - X(1, e);
    // (divisions, not a reciprocal: cos psi = 1 and lambda_s = 1 exactly on the reference)
    const double l = std::sqrt(dx * dx + dr * dr);
    const double c = dx / l, s = dr / l;
    S(0, e) = c;
    S(1, e) = s;
    S(2, e) = l;
    S(3, e) = (c - 1.0) / R0;
    S(4, e) = 0.0;
    S(5, e) = 0.0;
    // stretching
    const double ls = l / h0_[e];
    const double ws = kPi * R0 * h0_[e];  // 2 pi R0 h_e * (1/2): the Gauss weight of a segment
    const double ra = X(1, e);
    const double lt1 = (ra + kXi1 * dr) / R0, lt2 = (ra + kXi2 * dr) / R0;
    if (grad) {
      double ds1, dt1, ds2, dt2;
      Es += ws * (stretching_density(ks, ls, lt1, &ds1, &dt1, coupled) + stretching_density(ks, ls, lt2, &ds2, &dt2, coupled));
      const double dEdl = ws * (ds1 + ds2) / h0_[e];  // dE/dl
      const double fx = dEdl * c, fr = dEdl * s;  // dE/dX_{e+1} along the tangent
      (*F)(0, e) += fx;
      (*F)(1, e) += fr;
      (*F)(0, e + 1) -= fx;
      (*F)(1, e + 1) -= fr;
      const double g1 = ws * dt1 * inv_R0, g2 = ws * dt2 * inv_R0;  // dE/dr at the Gauss points
      (*F)(1, e) -= g1 * (1.0 - kXi1) + g2 * (1.0 - kXi2);
      (*F)(1, e + 1) -= g1 * kXi1 + g2 * kXi2;
    } else {
      Es += ws * (stretching_density(ks, ls, lt1, nullptr, nullptr, coupled) +
                  stretching_density(ks, ls, lt2, nullptr, nullptr, coupled));
    }
  }

  double Eb = 0.0;
  if (D > 0.0) {
    // hoop term, midpoint rule per segment
    for (int e = 0; e < ne; ++e) {
      const double kt = S(3, e);
      Eb += G * h0_[e] * kt * kt;
      S(4, e) += 2.0 * G * h0_[e] * kt;
    }
    // meridional and mixed terms at the interior nodes
    for (int k = 1; k <= n - 2; ++k) {
      const double w = w_[k], hb = 0.5 * (h0_[k - 1] + h0_[k]);
      const double c0 = S(0, k - 1), s0 = S(1, k - 1), c1 = S(0, k), s1 = S(1, k);
      const double dpsi = std::atan2(c0 * s1 - s0 * c1, c0 * c1 + s0 * s1);
      const double kap = dpsi / hb, ktm = 0.5 * (S(3, k - 1) + S(3, k));
      Eb += G * w * (kap * kap + 2.0 * nu * kap * ktm);
      const double dEdpsi = G * w * (2.0 * kap + 2.0 * nu * ktm) / hb;
      S(5, k) += dEdpsi;
      S(5, k - 1) -= dEdpsi;
      const double dEdkt = G * w * nu * kap;  // on each of the two segments (d ktm / d kt = 1/2)
      S(4, k - 1) += dEdkt;
      S(4, k) += dEdkt;
    }
    if (grad)
      for (int e = 0; e < ne; ++e) {
        // d k_t / d psi = -sin psi / R0;  d psi / d X_{e+1} = (-sin psi, cos psi) / l
        const double c = S(0, e), s = S(1, e), l = S(2, e);
        const double g = (S(5, e) - S(4, e) * s * inv_R0) / l;
        const double gx = -g * s, gr = g * c;  // dE/dX_{e+1}
        (*F)(0, e) += gx;
        (*F)(1, e) += gr;
        (*F)(0, e + 1) -= gx;
        (*F)(1, e + 1) -= gr;
      }
  }
  if (energy) *energy = {Es, Eb};
  return Es + Eb;
}

std::vector<double> segment_aligned_ring_positions(double L, double spacing, double end_ratio, double growth,
                                                   const std::vector<double>& cuts) {
  if (cuts.empty()) return graded_ring_positions(L, spacing, end_ratio, growth);
  (void)graded_ring_positions(L, spacing, end_ratio, growth);  // the same argument checks
  for (size_t i = 0; i < cuts.size(); ++i)
    if (!(cuts[i] > (i ? cuts[i - 1] : 0.0) && cuts[i] < L))
      throw InputError("protocol.segments", std::to_string(cuts.size() + 1), "segment boundaries inside the tube, increasing");
  // the interior intervals' cell size: the finest that keeps every interval's cells <= spacing
  double d = spacing;
  for (size_t i = 0; i + 1 < cuts.size(); ++i) {
    const double len = cuts[i + 1] - cuts[i];
    d = std::min(d, len / std::ceil(len / spacing - 1e-9));
  }
  if (cuts.size() == 1) d = std::min(spacing, std::min(cuts[0], L - cuts[0]));
  std::vector<double> ratios;  // the rim's graded spacings, in cells d, inwards from the rim
  for (double w = end_ratio; w < 1.0 - 1e-9; w *= growth) ratios.push_back(w);
  double c = 0.0;
  for (double w : ratios) c += w;
  // an end interval of length len: d/2 at the cut, then k equal cells of at most d, then the
  // rim's graded spacings (scaled down by sigma < 1 only when the interval is shorter than them)
  auto end_spacings = [&](double len) {
    const double room = len / d - 0.5;  // in cells
    if (!(room > 0.0))
      throw InputError("protocol.segments", "", "an end segment shorter than half a ring cell (" + significant(d) + " m)");
    std::vector<double> w;  // inwards from the rim
    // The uniform part holds what the graded spacings leave, in k equal cells; less than half a
    // cell left goes to the graded spacings instead (scaled by sigma <= 1 + 1/(2c)), so that no
    // sliver cell appears whose size jumps from grid to grid.
    double rest = room - c;
    const double sigma = (c > 0.0 && rest < 0.5) ? room / c : 1.0;
    if (sigma != 1.0) rest = 0.0;
    for (double r : ratios) w.push_back(sigma * r * d);
    const int k = rest > 1e-9 ? int(std::ceil(rest - 1e-9)) : 0;
    for (int i = 0; i < k; ++i) w.push_back(rest * d / k);
    return w;
  };
  std::vector<double> s{0.0};
  const std::vector<double> rear = end_spacings(cuts.front());
  for (double w : rear) s.push_back(s.back() + w);  // ends at cuts[0] - d/2
  for (size_t i = 0; i + 1 < cuts.size(); ++i) {
    const double a = cuts[i], len = cuts[i + 1] - a;
    const int m = int(std::lround(len / d));
    const double di = len / m;  // = d up to round-off when the lengths are multiples of d
    for (int j = 0; j < m; ++j) s.push_back(a + (j + 0.5) * di);
  }
  const std::vector<double> front = end_spacings(L - cuts.back());
  double x = L;
  std::vector<double> tail{L};
  for (double w : front) tail.push_back(x -= w);
  // tail: L, then inwards; its last entry is cuts.back() + d/2 (up to round-off)
  for (auto it = tail.rbegin(); it != tail.rend(); ++it) s.push_back(*it);
  s.back() = L;
  for (size_t k = 1; k < s.size(); ++k)
    if (!(s[k] > s[k - 1] + 1e-12 * L))
      throw InputError("axi.rim_refinement", significant(end_ratio), "rings that do not fit the protocol's segments; refine the grid");
  return s;
}

AxiPressureResponse relax_under_pressure(const AxiWall& wall, double P, double tol_force, int max_iterations) {
  if (!(P != 0.0) || !std::isfinite(P))
    throw InputError("pressure", significant(P), "a non-zero finite pressure in Pa (C1 = P / (R0 - R_mid))");
  const int n = wall.nodes();
  AxiPressureResponse out =
      relax_under_ring_pressures(wall, std::vector<double>(std::size_t(n), P), wall.reference(), tol_force, max_iterations);
  out.mid_radius = 0.5 * (out.X(1, (n - 1) / 2) + out.X(1, n / 2));
  out.c1 = P / (wall.params().R0 - out.mid_radius);
  return out;
}

AxiPressureResponse relax_under_ring_pressures(const AxiWall& wall, const std::vector<double>& P,
                                               const Eigen::Matrix3Xd& start, double tol_force, int max_iterations) {
  const int n = wall.nodes(), nu = 2 * n - 1;
  if (int(P.size()) != n)
    throw InputError("ring pressures", std::to_string(P.size()), "one pressure per ring (" + std::to_string(n) + ")");
  double p_max = 0.0;
  for (double p : P) {
    if (!std::isfinite(p)) throw InputError("ring pressure", significant(p), "a finite pressure in Pa");
    p_max = std::max(p_max, std::abs(p));
  }
  if (!(p_max > 0.0)) throw InputError("ring pressures", "all zero", "a non-zero pressure on some ring");
  if (max_iterations < 1)
    throw InputError("max_iterations", std::to_string(max_iterations), "an integer >= 1");
  if (start.cols() != n || start.rows() != 3 || !start.topRows(2).allFinite())
    throw InputError("start shape", std::to_string(start.cols()) + " columns", "3 x nodes, finite");
  const Eigen::VectorXd& A = wall.node_area();
  const double R0 = wall.params().R0;
  // (plain loops for the reductions here: see sum_sq)
  const double a_max = *std::max_element(A.data(), A.data() + n);
  if (!(tol_force > 0.0)) tol_force = 1e-9 * p_max * a_max;
  // unknowns: r_k -> 2k, x_k -> 2k - 1 (k >= 1); x_0 held
  auto dof = [](int k, int comp) { return comp == 1 ? 2 * k : 2 * k - 1; };

  // gradient g = -F + P_k A_k e_r of E + sum P_k A_k r_k (3 x n; row 2 unused)
  auto gradient = [&](const Eigen::Matrix3Xd& X) {
    Eigen::Matrix3Xd g = -wall.forces(X);
    for (int k = 0; k < n; ++k) g(1, k) += P[std::size_t(k)] * A[k];
    return g;
  };
  auto reduced = [&](const Eigen::Matrix3Xd& g) {
    Eigen::VectorXd v(nu);
    for (int k = 0; k < n; ++k) {
      v[dof(k, 1)] = g(1, k);
      if (k > 0) v[dof(k, 0)] = g(0, k);
    }
    return v;
  };
  auto max_node_force = [&](const Eigen::Matrix3Xd& gr) {
    double m = 0.0;
    for (int k = 0; k < n; ++k) {
      const double f = std::hypot(gr(0, k), gr(1, k));
      if (!(f <= m)) m = f;  // NaN propagates
    }
    return m;
  };

  Eigen::Matrix3Xd X = start;
  Eigen::Matrix3Xd g = gradient(X);
  Eigen::VectorXd res = reduced(g);
  const double eps = 1e-6 * R0;
  int it = 0;
  for (; it < max_iterations && !(max_node_force(g) <= tol_force); ++it) {
    // banded Jacobian dg/du by central differences, nodes k = colour mod 5 together
    BandLU J(nu, 5, 5);
    for (int comp = 0; comp < 2; ++comp)
      for (int colour = 0; colour < 5; ++colour) {
        Eigen::Matrix3Xd Xp = X, Xm = X;
        bool any = false;
        for (int k = colour; k < n; k += 5) {
          if (comp == 0 && k == 0) continue;
          any = true;
          Xp(comp, k) += eps;
          Xm(comp, k) -= eps;
        }
        if (!any) continue;
        const Eigen::Matrix3Xd d = (wall.forces(Xm) - wall.forces(Xp)) / (2.0 * eps);  // = dg
        for (int k = colour; k < n; k += 5) {
          if (comp == 0 && k == 0) continue;
          const int col = dof(k, comp);
          for (int j = std::max(0, k - 2); j <= std::min(n - 1, k + 2); ++j) {
            J.at(dof(j, 1), col) = d(1, j);
            if (j > 0) J.at(dof(j, 0), col) = d(0, j);
          }
        }
      }
    Eigen::VectorXd step = -res;
    if (!J.solve(step)) break;
    // backtracking on the residual norm
    double t = 1.0;
    bool accepted = false;
    for (int ls = 0; ls < 30; ++ls, t *= 0.5) {
      Eigen::Matrix3Xd Xn = X;
      for (int k = 0; k < n; ++k) {
        Xn(1, k) += t * step[dof(k, 1)];
        if (k > 0) Xn(0, k) += t * step[dof(k, 0)];
      }
      bool positive = true;
      for (int k = 0; k < n; ++k) positive = positive && Xn(1, k) > 0.0;
      if (!positive) continue;
      const Eigen::Matrix3Xd gn = gradient(Xn);
      const Eigen::VectorXd rn = reduced(gn);
      if (rn.allFinite() && (sum_sq(rn) < sum_sq(res) || max_node_force(gn) <= tol_force)) {
        X = Xn;
        g = gn;
        res = rn;
        accepted = true;
        break;
      }
    }
    if (!accepted) break;
  }
  AxiPressureResponse out;
  out.X = X;
  out.iterations = it;
  out.max_residual_force = max_node_force(g);
  if (!(out.max_residual_force <= tol_force))
    throw NumericalError("axisymmetric wall static relaxation stalled at residual force " +
                             significant(out.max_residual_force) + " N (tolerance " + significant(tol_force) + " N) after " +
                             std::to_string(it) + " Newton iterations",
                         "reduce the applied pressure (protocol.pressure sets the scale of the calibration loads)");
  return out;
}

Eigen::SparseMatrix<double> AxiWall::stiffness(const Eigen::Matrix3Xd& X, double eps) const {
  const int n = n_;
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(std::size_t(n) * 40);
  Eigen::Matrix3Xd Xp, Xm;
  for (int comp = 0; comp < 2; ++comp)
    for (int colour = 0; colour < 5; ++colour) {
      Xp = X;
      Xm = X;
      for (int k = colour; k < n; k += 5) Xp(comp, k) += eps, Xm(comp, k) -= eps;
      const Eigen::Matrix3Xd dF = (forces(Xp) - forces(Xm)) / (2.0 * eps);
      for (int k = colour; k < n; k += 5)
        for (int l = std::max(0, k - 2); l <= std::min(n - 1, k + 2); ++l)
          for (int c = 0; c < 2; ++c) trip.emplace_back(2 * l + c, 2 * k + comp, -dF(c, l));
    }
  Eigen::SparseMatrix<double> K(2 * n, 2 * n);
  K.setFromTriplets(trip.begin(), trip.end());
  const Eigen::SparseMatrix<double> Kt = K.transpose();
  return 0.5 * (K + Kt);
}

}  // namespace swim::axi
