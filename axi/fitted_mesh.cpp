#include "axi/fitted_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "common/errors.hpp"

namespace swim::axi {

namespace {

std::string fmt(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.6g", v);
  return b;
}

// Gap column widths (see the header): w_i(q) = min(wl q^i, wr q^(m-1-i)), q in [1, growth] with
// sum = G; uniform G/m when no such q exists.
std::vector<double> gap_widths(double G, int m, double wl, double wr, double growth) {
  auto widths = [&](double q, std::vector<double>& w) {
    double s = 0.0;
    for (int i = 0; i < m; ++i) {
      w[i] = std::min(wl * std::pow(q, i), wr * std::pow(q, m - 1 - i));
      s += w[i];
    }
    return s;
  };
  std::vector<double> w(m);
  const double s1 = widths(1.0, w), s2 = widths(growth, w);
  if (!(s1 <= G && G <= s2)) {
    std::fill(w.begin(), w.end(), G / m);
    return w;
  }
  double lo = 1.0, hi = growth;
  for (int it = 0; it < 200 && hi - lo > 1e-15 * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    (widths(mid, w) < G ? lo : hi) = mid;
  }
  const double s = widths(0.5 * (lo + hi), w);
  for (double& v : w) v *= G / s;  // exact fill (relative correction ~1e-15)
  return w;
}

}  // namespace

void check_fitted_mesh_params(const FittedMeshParams& p, int membrane_nodes) {
  if (membrane_nodes < 3)
    throw std::invalid_argument("FittedMesh: at least 3 membrane nodes are needed (got " +
                                std::to_string(membrane_nodes) + ")");
  if (!(std::isfinite(p.Rc) && p.Rc > 0))
    throw InputError("container.radius", fmt(p.Rc) + " m", "must be a positive finite length");
  if (!(std::isfinite(p.period) && p.period > 0))
    throw InputError("container.period", fmt(p.period) + " m", "must be a positive finite length");
  if (p.cells_inner < 1)
    throw InputError("axi.fitted.cells_inner", std::to_string(p.cells_inner), "must be an integer >= 1");
  if (p.cells_outer < 1)
    throw InputError("axi.fitted.cells_outer", std::to_string(p.cells_outer), "must be an integer >= 1");
  if (!p.closed && p.gap_columns < 1)
    throw InputError("axi.fitted.gap_columns", std::to_string(p.gap_columns), "must be an integer >= 1");
  if (!(std::isfinite(p.gap_growth) && p.gap_growth >= 1.0))
    throw InputError("axi.fitted.gap_growth", fmt(p.gap_growth), "must be a finite ratio >= 1");
  const double cells = double(p.closed ? membrane_nodes : membrane_nodes - 1 + p.gap_columns) *
                       double(p.cells_inner + p.cells_outer);
  if (cells > 2e7)
    throw InputError("axi.fitted", fmt(cells) + " elements", "more than 2e7 elements; use fewer cells or nodes");
}

FittedMesh::FittedMesh(const FittedMeshParams& p, int membrane_nodes) : p_(p), n_(membrane_nodes) {
  check_fitted_mesh_params(p, membrane_nodes);
  nc_ = p.closed ? n_ : n_ - 1 + p.gap_columns;
  ny_ = p.cells_inner + p.cells_outer;
  xcol_.assign(nc_ + 1, 0.0);
  rho_.assign(nc_, 0.0);
  frac_.assign(size_t(nc_) * (ny_ + 1), 0.0);
}

double FittedMesh::vertex_r(int c, int j) const {
  c %= nc_;
  const double rho = rho_[c];
  const int ci = p_.cells_inner;
  if (j == ny_) return p_.Rc;
  const double f = frac_[size_t(c) * (ny_ + 1) + j];
  if (j <= ci) return rho * f;
  return rho + (p_.Rc - rho) * f;
}

void FittedMesh::fit(const Eigen::Matrix3Xd& X) {
  if (X.cols() != n_)
    throw std::invalid_argument("FittedMesh::fit: X has " + std::to_string(X.cols()) + " columns, the mesh " +
                                std::to_string(n_) + " membrane nodes");
  fitted_ = false;
  const double Rc = p_.Rc, P = p_.period;
  for (int k = 0; k < n_; ++k) {
    const double x = X(0, k), r = X(1, k);
    if (!std::isfinite(x) || !std::isfinite(r))
      throw NumericalError("membrane vertex " + std::to_string(k) + " has a non-finite position",
                           "reduce the time step (axi.dt_max, axi.tolerance)");
    if (!(r > 0.0 && r < Rc))
      throw NumericalError("membrane vertex " + std::to_string(k) + " at r = " + fmt(r) +
                               " m is outside (0, Rc = " + fmt(Rc) + " m): the wall collapsed onto the axis or "
                               "reached the container",
                           "reduce the load or the time step; the fitted mesh (axi.fitted.cells_inner, "
                           "axi.fitted.cells_outer) needs the wall strictly inside the container");
    if (k > 0 && !(x > X(0, k - 1)))
      throw NumericalError("membrane vertices " + std::to_string(k - 1) + " and " + std::to_string(k) +
                               " are not in increasing axial order (x = " + fmt(X(0, k - 1)) + ", " + fmt(x) +
                               " m): the meridian folded back",
                           "reduce the time step; the fitted mesh (axi.fitted.*) needs x strictly increasing "
                           "along the wall");
  }
  const double span = X(0, n_ - 1) - X(0, 0);
  if (!(span < P))
    throw NumericalError("the tube (length " + fmt(span) + " m) does not fit the period " + fmt(P) + " m",
                         "increase container.period; the fitted mesh (axi.fitted.gap_columns) needs a gap "
                         "between the tube's ends");

  const double x0 = X(0, 0);
  for (int k = 0; k < n_; ++k) {
    xcol_[k] = X(0, k);
    rho_[k] = X(1, k);
  }
  if (!p_.closed) {
    const int m = p_.gap_columns;
    const double G = x0 + P - X(0, n_ - 1);
    const auto w = gap_widths(G, m, X(0, n_ - 1) - X(0, n_ - 2), X(0, 1) - X(0, 0), p_.gap_growth);
    const double xa = X(0, n_ - 1), ra = X(1, n_ - 1), rb = X(1, 0);
    double x = xa;
    for (int i = 0; i < m - 1; ++i) {
      x += w[i];
      const int c = n_ + i;
      xcol_[c] = x;
      const double t = (x - xa) / G;
      rho_[c] = ra + (rb - ra) * t;
    }
  }
  xcol_[nc_] = x0 + P;

  // row fractions: uniform, or graded from the membrane line (heights w_i = eta q^i away from it)
  const int ci = p_.cells_inner, co = p_.cells_outer;
  for (int c = 0; c < nc_; ++c) {
    double* f = &frac_[size_t(c) * (ny_ + 1)];
    for (int j = 0; j <= ci; ++j) f[j] = double(j) / ci;
    for (int j = ci + 1; j <= ny_; ++j) f[j] = double(j - ci) / co;
    if (!(p_.wall_row_aspect > 0.0)) continue;
    const double wl = xcol_[c] - (c > 0 ? xcol_[c - 1] : xcol_[nc_ - 1] - P);
    const double wr = xcol_[c + 1] - xcol_[c];
    const double eta = p_.wall_row_aspect * std::min(wl, wr);
    const double in = rho_[c], out = Rc - rho_[c];
    const auto hi = gap_widths(in, ci, eta, INFINITY, 4.0), ho = gap_widths(out, co, eta, INFINITY, 4.0);
    double acc = 0.0;  // inside: from the membrane line down to the axis
    for (int i = 0; i < ci; ++i) {
      acc += hi[i];
      f[ci - 1 - i] = i == ci - 1 ? 0.0 : 1.0 - acc / in;
    }
    acc = 0.0;
    for (int i = 0; i < co; ++i) {
      acc += ho[i];
      f[ci + 1 + i] = i == co - 1 ? 1.0 : acc / out;
    }
  }

  // Jacobian x_xi r_eta at the four corners of every element (x_xi = half the column width,
  // r_eta = half the vertical side of the corner).
  min_jac_ = INFINITY;
  for (int c = 0; c < nc_; ++c) {
    const double hx = 0.5 * (xcol_[c + 1] - xcol_[c]);
    for (int j = 0; j < ny_; ++j) {
      const double dl = 0.5 * (vertex_r(c, j + 1) - vertex_r(c, j));
      const double dr = 0.5 * (vertex_r(c + 1, j + 1) - vertex_r(c + 1, j));
      const double jac = hx * std::min(dl, dr);
      min_jac_ = std::min(min_jac_, jac);
      if (!(jac > 0.0))
        throw NumericalError("element (column " + std::to_string(c) + ", row " + std::to_string(j) +
                                 ") of the fitted mesh has a non-positive Jacobian",
                             "change axi.fitted.gap_columns, axi.fitted.gap_growth or reduce the time step");
    }
  }
  fitted_ = true;
}

void FittedMesh::corners(int e, double x[4], double r[4]) const {
  const int c = element_column(e), j = element_row(e);
  x[0] = x[3] = xcol_[c];
  x[1] = x[2] = xcol_[c + 1];
  r[0] = vertex_r(c, j);
  r[1] = vertex_r(c + 1, j);
  r[2] = vertex_r(c + 1, j + 1);
  r[3] = vertex_r(c, j + 1);
}

Eigen::Vector2d FittedMesh::node_position(int I, int J) const {
  const int c = I / 2, j = J / 2;
  const bool mx = I % 2, mr = J % 2;
  const double x = mx ? 0.5 * (xcol_[c] + xcol_[c + 1]) : xcol_[c];
  auto rcol = [&](int cc) { return mr ? 0.5 * (vertex_r(cc, j) + vertex_r(cc, j + 1)) : vertex_r(cc, j); };
  const double r = mx ? 0.5 * (rcol(c) + rcol(c + 1)) : rcol(c);
  return {x, r};
}

int FittedMesh::locate(double& x, double r, double& xi, double& eta) const {
  if (!fitted_) throw std::logic_error("FittedMesh::locate before fit()");
  if (!std::isfinite(x) || !(r >= 0.0 && r <= p_.Rc))
    throw std::invalid_argument("FittedMesh::locate: the point (x = " + fmt(x) + " m, r = " + fmt(r) +
                                " m) is outside 0 <= r <= Rc");
  const double P = p_.period, x0 = xcol_[0];
  x = x0 + (x - x0) - P * std::floor((x - x0) / P);
  if (x >= x0 + P) x -= P;
  int c = int(std::upper_bound(xcol_.begin(), xcol_.end(), x) - xcol_.begin()) - 1;
  c = std::clamp(c, 0, nc_ - 1);
  const double t = (x - xcol_[c]) / (xcol_[c + 1] - xcol_[c]);
  xi = 2.0 * t - 1.0;
  auto line = [&](int j) { return vertex_r(c, j) * (1.0 - t) + vertex_r(c + 1, j) * t; };
  int lo = 0, hi = ny_;  // find j with line(j) <= r <= line(j + 1)
  while (hi - lo > 1) {
    const int mid = (lo + hi) / 2;
    (line(mid) <= r ? lo : hi) = mid;
  }
  const double rb = line(lo), rt = line(lo + 1);
  eta = std::clamp(2.0 * (r - rb) / (rt - rb) - 1.0, -1.0, 1.0);
  return element(c, lo);
}

}  // namespace swim::axi
