#include "axi/fitted_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
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
  std::vector<double> w(m), qi(m);  // qi: the powers q^i, by products (pow per entry cost 3 % of a run)
  auto widths = [&](double q, std::vector<double>& w) {
    double p = 1.0;
    for (int i = 0; i < m; ++i, p *= q) qi[i] = p;
    double s = 0.0;
    for (int i = 0; i < m; ++i) {
      w[i] = std::min(wl * qi[i], wr * qi[m - 1 - i]);
      s += w[i];
    }
    return s;
  };
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
  vx_.assign(size_t(nc_) * (ny_ + 1), 0.0);
  vr_.assign(size_t(nc_) * (ny_ + 1), 0.0);
  vertical_.assign(nc_, 1);
}

namespace {

constexpr double kA0 = 0.6107259643892086;  // atan(0.7): steeper wall-line segments tilt the lines
constexpr double kA1 = 1.2490457723982544;  // atan(3): fully steep
constexpr double kBandOffsets = 3.0;  // band height per offset (initial slope 2/3 of the offset term)
constexpr double kBandRows = 3.0;     // and in uniform rows (the side's distance over its row count)
constexpr double kLeanMargin = 0.2617993877991494;  // 15 deg
constexpr double kLeanRamp = 0.17453292519943295;   // 10 deg
constexpr double kLeanMax = 1.3089969389957472;     // 75 deg
constexpr double kGamma = 0.5;                  // axial room given to a steep segment, per length
constexpr double kWindow = 48;                  // at most this many gentle segments give the room back,
constexpr double kCapacity = 4.0;               // or as many as have kCapacity times the room
constexpr double kRowRatio = 1.1;               // where the lines tilt, the first rows grow by at most this per column
constexpr double kLeanSlope = 1.0;              // lambda changes by at most this times length / band per segment
constexpr double kTiltFull = 0.2;               // line slope |dx/dr| from which that limit holds fully
constexpr int kSmoothingHalfWidth = 48;         // the widest smoothing window: this many columns either side
constexpr int kSmoothingSweeps = 4000;          // at most this many Gauss-Seidel sweeps per window

double smoothstep01(double t) {
  t = std::clamp(t, 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

double steepness(double a) {
  const double t = std::clamp((a - kA0) / (kA1 - kA0), 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

// Width of a wall-line segment for sizing the gap's first columns and the rows graded towards
// the wall: its axial extent, or 0.8 of its length when that is larger (a segment steeper than
// 37 degrees, whose elements along the wall are that long).
double sizing_width(double dx, double dr) {
  const double l = 0.8 * std::hypot(dx, dr);
  return dx >= l ? dx : l;
}

}  // namespace

void FittedMesh::fit(const Eigen::Matrix3Xd& X) {
  if (X.cols() != n_)
    throw std::invalid_argument("FittedMesh::fit: X has " + std::to_string(X.cols()) + " columns, the mesh " +
                                std::to_string(n_) + " membrane nodes");
  fitted_ = false;
  walkable_ = true;
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
  }
  const double span = X(0, n_ - 1) - X(0, 0);
  if (!(span < P))
    throw NumericalError("the tube (length " + fmt(span) + " m) does not fit the period " + fmt(P) + " m",
                         "increase container.period; the fitted mesh (axi.fitted.gap_columns) needs a gap "
                         "between the tube's ends");
  if (!(span > 0.0))
    throw NumericalError("the tube's front end (x = " + fmt(X(0, n_ - 1)) + " m) is not ahead of its rear end (x = " +
                             fmt(X(0, 0)) + " m): the meridian folded back over its whole length",
                         "reduce the time step");

  const double x0 = X(0, 0);
  for (int k = 0; k < n_; ++k) {
    xcol_[k] = X(0, k);
    rho_[k] = X(1, k);
  }
  if (!p_.closed) {
    const int m = p_.gap_columns;
    const double G = x0 + P - X(0, n_ - 1);
    const auto w = gap_widths(G, m, sizing_width(X(0, n_ - 1) - X(0, n_ - 2), X(1, n_ - 1) - X(1, n_ - 2)),
                              sizing_width(X(0, 1) - X(0, 0), X(1, 1) - X(1, 0)), p_.gap_growth);
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
  // wall-line segment c (vertex columns c, c + 1): axial width, radial rise
  auto seg_dx = [&](int c) { return xcol_[c + 1] - xcol_[c]; };
  auto seg_dr = [&](int c) { return rho_[(c + 1) % nc_] - rho_[c]; };
  auto seg_w = [&](int c) { return sizing_width(seg_dx(c), seg_dr(c)); };

  // Steepness of the wall-line segments and the extra axial room they get (see the header).
  std::vector<double> st(nc_), extra(nc_, 0.0);
  bool steep = false;
  for (int c = 0; c < nc_; ++c) {
    st[c] = steepness(std::atan2(std::abs(seg_dr(c)), seg_dx(c)));
    if (st[c] > 0.0) {
      steep = true;
      // gamma l, plus the axial width a turned-back segment loses (smoothly: (|dx| - dx)/2 with
      // |dx| rounded at 0.1 l)
      const double l = std::hypot(seg_dx(c), seg_dr(c));
      extra[c] = st[c] * (kGamma * l + 0.5 * (std::hypot(seg_dx(c), 0.1 * l) - seg_dx(c)));
    }
  }
  auto wrap = [&](int c) { return ((c % nc_) + nc_) % nc_; };
  const double M = kWindow;
  double etot = 0.0;
  for (double e : extra) etot += e;
  // Offsets of the lines' far positions, outside (side 1) and inside (side 0). A steep segment's
  // room is taken back from the gentle segments on the side its normal points to on that side of
  // the wall: outside, where the wall rises (dr > 0) the outward normal points to -x, so from the
  // segments before it; inside, from those after it (and the reverse where the wall falls).
  std::vector<double> off[2] = {std::vector<double>(nc_, 0.0), std::vector<double>(nc_, 0.0)};
  if (steep) {
    int start = 0, best = -1;  // the column farthest from any steep segment
    for (int c = 0; c < nc_; ++c) {
      int dist = nc_;
      for (int m = 0; m < nc_; ++m)
        if (extra[m] > 0.0) dist = std::min({dist, wrap(c - m), wrap(m + 1 - c)});
      if (dist > best) {
        best = dist;
        start = c;
      }
    }
    for (int side = 0; side < 2; ++side) {
      std::vector<double> back(nc_, 0.0), donor;
      for (int m = 0; m < nc_; ++m) {
        if (extra[m] == 0.0) continue;
        const double dr = seg_dr(m);
        const bool before = side ? dr > 0.0 : dr < 0.0;
        // the donors: the segments met walking away from m until M gentle ones (counting a
        // segment as 1 - s of one) have been passed or their axial widths reach kCapacity times
        // the whole wall line's extra room
        // The last donor counts with the fraction f of itself that reaches either limit exactly,
        // so that the offsets are continuous in the shape (a donor enters or leaves with zero
        // weight).
        const double cap = kCapacity * etot;
        double tot = 0.0, gentle = 0.0;
        donor.clear();
        for (int i = 1; i < nc_ && gentle < M && tot < cap; ++i) {
          const int k = wrap(before ? m - i : m + i);
          const double g = 1.0 - st[k], a = g * std::max(seg_dx(k), 0.0);
          double f = 1.0;
          if (gentle + g > M) f = std::min(f, (M - gentle) / g);
          if (tot + a > cap) f = std::min(f, (cap - tot) / a);
          gentle += f * g;
          tot += f * a;
          donor.push_back(f * a);
          if (f < 1.0) break;
        }
        if (!(tot > 0.0))
          throw NumericalError("the wall line near vertex column " + std::to_string(m) +
                                   " has no gentle segment to give room to its steep ones",
                               "reduce the time step or refine axi.grid");
        for (int i = 1; i <= int(donor.size()); ++i) {
          const int k = wrap(before ? m - i : m + i);
          back[k] += extra[m] * donor[i - 1] / tot;
        }
      }
      double o = 0.0;
      for (int i = 0; i < nc_; ++i) {
        const int c = wrap(start + i);
        off[side][c] = o;
        o += extra[c] - back[c];
      }
    }
  }
  // Lean of the lines at the wall. The straight line through W_c with direction angle beta
  // (from +x) enters the fluid on the correct side of both adjacent segments (angles a_in,
  // a_out) when max(a_in, a_out) < beta < min(a_in, a_out) + pi. beta = pi/2 (vertical) unless
  // that is within kLeanMargin of either bound; then it is pushed away from the bound (C^1
  // ramp). The leans are then spread to the neighbours (the largest within 2 columns, then two
  // [1 2 1]/4 passes; each sign separately), so that neighbouring lines stay nearly parallel;
  // the spread lean is never smaller than the vertex's own.
  std::vector<double> lean_pos(nc_, 0.0), lean_neg(nc_, 0.0);
  bool leaning = false;
  {
    auto ramp = [](double z) {
      return z <= 0.0 ? 0.0 : z < kLeanRamp ? 0.5 * z * z / kLeanRamp : z - 0.5 * kLeanRamp;
    };
    const double half_pi = 0.5 * std::numbers::pi;
    for (int c = 0; c < nc_; ++c) {
      const int cm = c > 0 ? c - 1 : nc_ - 1;
      const double a_in = std::atan2(seg_dr(cm), seg_dx(cm)), a_out = std::atan2(seg_dr(c), seg_dx(c));
      lean_pos[c] = ramp(std::max(a_in, a_out) + kLeanMargin - half_pi);
      lean_neg[c] = ramp(half_pi + kLeanMargin - (std::min(a_in, a_out) + std::numbers::pi));
      leaning = leaning || lean_pos[c] > 0.0 || lean_neg[c] > 0.0;
    }
    if (leaning)
      for (auto* v : {&lean_pos, &lean_neg}) {
        std::vector<double> t(nc_);
        for (int c = 0; c < nc_; ++c) {
          double m = 0.0;
          for (int i = -2; i <= 2; ++i) m = std::max(m, (*v)[wrap(c + i)]);
          t[c] = m;
        }
        for (int pass = 0; pass < 2; ++pass) {
          for (int c = 0; c < nc_; ++c) (*v)[c] = 0.25 * (t[wrap(c - 1)] + 2.0 * t[c] + t[wrap(c + 1)]);
          t = *v;
        }
      }
  }
  // The lines' tilt: lean lambda_c and, per side, the far offset o and its band b (see the header).
  std::vector<double> lam(nc_), band[2] = {std::vector<double>(nc_), std::vector<double>(nc_)};
  const int ci = p_.cells_inner, co = p_.cells_outer;
  for (int c = 0; c < nc_; ++c) {
    lam[c] = -std::tan(std::clamp(lean_pos[c] - lean_neg[c], -kLeanMax, kLeanMax));
    for (int side = 0; side < 2; ++side) {
      const double d = side ? Rc - rho_[c] : rho_[c], first = d / (side ? co : ci);
      band[side][c] = std::min(std::max(kBandOffsets * std::abs(off[side][c]), kBandRows * first), 0.9 * d);
    }
  }
  // The leans' spread in physical space: lines leaning differently diverge by up to 0.29 b
  // times the difference of their lambdas, so between neighbouring columns lambda may change by at
  // most kLeanSlope times the segment's length over the larger band: lambda_c's positive and
  // negative parts are each raised to the upper envelope max over k of (part_k - kLeanSlope times
  // the lengths between k and c over the bands). Continuous; nothing on a wall without leans.
  if (leaning) {
    std::vector<double> step(nc_);
    for (int c = 0; c < nc_; ++c) {
      const int d = wrap(c + 1);
      const double B = std::max({band[0][c], band[1][c], band[0][d], band[1][d]});
      step[c] = kLeanSlope * std::hypot(seg_dx(c), seg_dr(c)) / B;
    }
    std::vector<double> pos(nc_), neg(nc_);
    for (int c = 0; c < nc_; ++c) pos[c] = std::max(lam[c], 0.0), neg[c] = std::max(-lam[c], 0.0);
    for (auto* v : {&pos, &neg})
      for (int round = 0; round < 2; ++round) {
        for (int c = 0; c < nc_; ++c) (*v)[c] = std::max((*v)[c], (*v)[wrap(c - 1)] - step[wrap(c - 1)]);
        for (int c = nc_ - 1; c >= 0; --c) (*v)[c] = std::max((*v)[c], (*v)[wrap(c + 1)] - step[c]);
      }
    // never beyond what the column's own segments admit (the line within kLeanMargin of either
    // segment's direction), unless the column's own lean already is
    for (int c = 0; c < nc_; ++c) {
      const int cm = wrap(c - 1);
      const double a_in = std::atan2(seg_dr(cm), seg_dx(cm)), a_out = std::atan2(seg_dr(c), seg_dx(c));
      const double hp = std::tan(std::clamp(0.5 * std::numbers::pi - std::max(a_in, a_out) - kLeanMargin, 0.0, kLeanMax));
      const double hn = std::tan(std::clamp(std::min(a_in, a_out) + 0.5 * std::numbers::pi - kLeanMargin, 0.0, kLeanMax));
      pos[c] = std::min(pos[c], std::max(std::max(lam[c], 0.0), hp));
      neg[c] = std::min(neg[c], std::max(std::max(-lam[c], 0.0), hn));
    }
    for (int c = 0; c < nc_; ++c) lam[c] = pos[c] - neg[c];
  }
  // row fractions: uniform, or graded from the membrane line (heights w_i = eta_c q^i away from it)
  std::vector<double> eta(nc_, 0.0);
  if (p_.wall_row_aspect > 0.0) {
    for (int c = 0; c < nc_; ++c) eta[c] = p_.wall_row_aspect * std::min(seg_w(wrap(c - 1)), seg_w(c));
    // Where the lines tilt, rows graded on each column's own width (1.5 times apart per column
    // at the refined rims) are crossed by lines leaning or fanning across them. There the first
    // rows' heights may grow by at most kRowRatio per column: eta_c = min over k of eta_k times
    // the product of the ratios allowed between c and k, the ratio between columns c, c + 1 being
    // kRowRatio 2^((1 - tau) / tau), tau = smoothstep(T / kTiltFull) of the larger line slope
    // T = |lambda| + 2 max(|o| / b) of the two columns (unlimited for tau = 0, on vertical lines:
    // a gentle wall's rows are unchanged). Continuous in the shape (a minimum over continuous
    // terms, which grow without bound as tau -> 0).
    std::vector<double> lr(nc_);  // log of the ratio allowed between columns c and c + 1
    bool any = false;
    auto slope = [&](int c) {
      return std::abs(lam[c]) + 2.0 * std::max(std::abs(off[0][c]) / band[0][c], std::abs(off[1][c]) / band[1][c]);
    };
    for (int c = 0; c < nc_; ++c) {
      const double T = std::max(slope(c), slope(wrap(c + 1)));
      const double tau = smoothstep01(T / kTiltFull);
      any = any || tau > 0.0;
      lr[c] = tau > 0.0 ? std::log(kRowRatio) + std::log(2.0) * (1.0 - tau) / tau : INFINITY;
    }
    if (any) {
      std::vector<double> le(nc_);
      for (int c = 0; c < nc_; ++c) le[c] = std::log(eta[c]);
      for (int round = 0; round < 2; ++round) {  // twice around the periodic line, each way
        for (int c = 0; c < nc_; ++c) le[c] = std::min(le[c], le[wrap(c - 1)] + lr[wrap(c - 1)]);
        for (int c = nc_ - 1; c >= 0; --c) le[c] = std::min(le[c], le[wrap(c + 1)] + lr[c]);
      }
      for (int c = 0; c < nc_; ++c)
        if (le[c] < std::log(eta[c])) eta[c] = std::exp(le[c]);
    }
  }
  for (int c = 0; c < nc_; ++c) {
    double* f = &frac_[size_t(c) * (ny_ + 1)];
    for (int j = 0; j <= ci; ++j) f[j] = double(j) / ci;
    for (int j = ci + 1; j <= ny_; ++j) f[j] = double(j - ci) / co;
    if (!(p_.wall_row_aspect > 0.0)) continue;
    const double in = rho_[c], out = Rc - rho_[c];
    const auto hi = gap_widths(in, ci, eta[c], INFINITY, 4.0), ho = gap_widths(out, co, eta[c], INFINITY, 4.0);
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
  // radii (the lines' radii do not depend on their tilt)
  for (int c = 0; c < nc_; ++c) {
    const double rho = rho_[c];
    const double* f = &frac_[size_t(c) * (ny_ + 1)];
    double* vr = &vr_[size_t(c) * (ny_ + 1)];
    for (int j = 0; j < ny_; ++j) vr[j] = j <= ci ? rho * f[j] : rho + (Rc - rho) * f[j];
    vr[ny_] = Rc;
  }

  // The lines: x = x_c + lambda (r - rho) (1 - u^2)^2 + o u (2 - u), u = |r - rho| / b < 1;
  // x_c + o beyond.
  for (int c = 0; c < nc_; ++c) {
    const double xc = xcol_[c], rho = rho_[c];
    double* vx = &vx_[size_t(c) * (ny_ + 1)];
    const double* vr = &vr_[size_t(c) * (ny_ + 1)];
    const double lambda = lam[c];
    vertical_[c] = (off[0][c] == 0.0 && off[1][c] == 0.0 && lambda == 0.0);
    if (vertical_[c]) {
      for (int j = 0; j <= ny_; ++j) vx[j] = xc;
      continue;
    }
    for (int side = 0; side < 2; ++side) {  // 0 inside, 1 outside
      const double o = off[side][c], b = band[side][c];
      const int j0 = side ? ci + 1 : 0, j1 = side ? ny_ : ci - 1;
      for (int j = j0; j <= j1; ++j) {
        const double u = std::abs(vr[j] - rho) / b;
        vx[j] = u >= 1.0 ? xc + o : xc + lambda * (vr[j] - rho) * (1.0 - u * u) * (1.0 - u * u) + o * u * (2.0 - u);
      }
    }
    vx[ci] = xc;
  }

  int bad_c = -1, bad_j = -1;
  if (!find_fold(bad_c, bad_j)) {
    // Where the tilted lines cross but the wall line still advances along the axis (x strictly
    // increasing), the vertical-line mesh is valid: use it. Otherwise (or when it is not valid)
    // smooth the tilted mesh around its folds.
    bool increasing = true;
    for (int c = 0; c < nc_; ++c) increasing = increasing && seg_dx(c) > 0.0;
    bool valid = false;
    if (increasing) {
      const std::vector<double> tilted = vx_;
      const std::vector<char> tilted_vertical = vertical_;
      for (int c = 0; c < nc_; ++c) {
        vertical_[c] = 1;
        for (int j = 0; j <= ny_; ++j) vx_[size_t(c) * (ny_ + 1) + j] = xcol_[c];
      }
      int c2 = -1, j2 = -1;
      valid = find_fold(c2, j2);
      if (!valid) {
        vx_ = tilted;
        vertical_ = tilted_vertical;
      }
    }
    if (!valid && !smooth_where_folded(bad_c, bad_j)) {
      const int c = bad_c, j = bad_j;
      const int k = c < n_ ? c : (c - n_ < (nc_ - n_) / 2 ? n_ - 1 : 0);
      throw NumericalError("element (column " + std::to_string(c) + ", row " + std::to_string(j) +
                               ") of the fitted mesh has a non-positive Jacobian, near membrane vertex " +
                               std::to_string(k) + " at (" + fmt(xcol_[c]) + ", " + fmt(rho_[c]) +
                               ") m: the mesh cannot follow the wall's shape there",
                           "reduce the time step or refine axi.grid; change axi.fitted.gap_columns or "
                           "axi.fitted.gap_growth");
    }
  }
  fitted_ = true;
}

// Elliptic smoothing where the algebraic lines fold (see the header): Winslow's equations for the
// interior vertices of a window of columns on one side of the wall line, the window's edge
// columns, the axis (or container) row and the wall line held, the rows kept graded as the
// algebraic mesh grades them by the Thomas-Middlecoff control term. ξ(x) harmonic maps the window
// one-to-one onto the logical rectangle (Rado's theorem), so the discrete solution unfolds the
// lines wherever the window's boundary is valid. Windows of 2 x 6 columns around the first folded
// element, doubled while a fold stays inside the last window, up to 2 x 48.
bool FittedMesh::smooth_where_folded(int& bad_c, int& bad_j) {
  if (!p_.elliptic_smoothing) return false;
  const std::vector<double> vx0 = vx_, vr0 = vr_;
  const std::vector<char> vertical0 = vertical_;
  const int ci = p_.cells_inner;
  const double P = p_.period;
  auto wrap = [&](int c) { return ((c % nc_) + nc_) % nc_; };
  // vertex (c, j) with c unwrapped (the periodic image's x shifted by P)
  auto at = [&](int c, int j) { return size_t(wrap(c)) * (ny_ + 1) + j; };
  auto shift = [&](int c) { return P * std::floor(double(c) / nc_); };
  int half = 6, centre = bad_c, side = bad_j < ci ? 0 : 1, lo = 0, hi = -1;
  for (int attempt = 0; attempt < 16; ++attempt) {
    const int s = bad_j < ci ? 0 : 1;
    // a fold inside the last window (same side): widen it; elsewhere: a new window
    const bool inside = s == side && wrap(bad_c - lo) < hi - lo;
    if (attempt > 0 && inside) {
      if (2 * half + 2 >= nc_ || half >= kSmoothingHalfWidth) break;
      half = std::min(2 * half, kSmoothingHalfWidth);
    } else if (attempt > 0) {
      half = 6;
      centre = bad_c;
      side = s;
    }
    half = std::min(half, (nc_ - 2) / 2);
    lo = centre - half;
    hi = centre + 1 + half;  // vertex columns lo..hi, lo and hi held
    const int j0 = side ? ci : 0, j1 = side ? ny_ : ci;  // rows j0, j1 held
    const int nw = hi - lo - 1, nr = j1 - j0 - 1;
    if (nw < 1 || nr < 1) break;
    // unwrapped working copies of the window, rows j0..j1
    const int W = hi - lo + 1, H = j1 - j0 + 1;
    std::vector<double> x(size_t(W) * H), r(size_t(W) * H), q(size_t(W) * H, 0.0);
    auto id = [&](int a, int b) { return size_t(a) * H + b; };
    for (int a = 0; a < W; ++a)
      for (int b = 0; b < H; ++b) {
        x[id(a, b)] = vx_[at(lo + a, j0 + b)] + shift(lo + a);
        r[id(a, b)] = vr_[at(lo + a, j0 + b)];
      }
    // the control term: each column's own algebraic row distribution, q = -s_bb / s_b
    for (int a = 1; a < W - 1; ++a)
      for (int b = 1; b < H - 1; ++b) {
        const double sm = r[id(a, b - 1)], s0 = r[id(a, b)], sp = r[id(a, b + 1)];
        q[id(a, b)] = -(sp - 2.0 * s0 + sm) / (0.5 * (sp - sm));
      }
    double scale = INFINITY;  // the smallest edge of the window, for the stopping rule
    for (int a = 0; a + 1 < W; ++a)
      for (int b = 0; b + 1 < H; ++b)
        scale = std::min({scale, std::hypot(x[id(a + 1, b)] - x[id(a, b)], r[id(a + 1, b)] - r[id(a, b)]),
                          std::hypot(x[id(a, b + 1)] - x[id(a, b)], r[id(a, b + 1)] - r[id(a, b)])});
    if (!(scale > 0.0)) scale = 1e-3 * (P + p_.Rc) / (nc_ + ny_);
    const int sweeps = std::min(40 * (W * W + H * H) + 200, kSmoothingSweeps);
    for (int it = 0; it < sweeps; ++it) {
      double moved = 0.0;
      for (int a = 1; a < W - 1; ++a)
        for (int b = 1; b < H - 1; ++b) {
          const double xe = x[id(a + 1, b)], xw = x[id(a - 1, b)], xn = x[id(a, b + 1)], xs = x[id(a, b - 1)];
          const double re = r[id(a + 1, b)], rw = r[id(a - 1, b)], rn = r[id(a, b + 1)], rs = r[id(a, b - 1)];
          const double xxi = 0.5 * (xe - xw), rxi = 0.5 * (re - rw), xet = 0.5 * (xn - xs), ret = 0.5 * (rn - rs);
          const double al = xet * xet + ret * ret, be = xxi * xet + rxi * ret, ga = xxi * xxi + rxi * rxi;
          const double xc = 0.25 * (x[id(a + 1, b + 1)] - x[id(a - 1, b + 1)] - x[id(a + 1, b - 1)] + x[id(a - 1, b - 1)]);
          const double rc = 0.25 * (r[id(a + 1, b + 1)] - r[id(a - 1, b + 1)] - r[id(a + 1, b - 1)] + r[id(a - 1, b - 1)]);
          const double d = 2.0 * (al + ga), qq = q[id(a, b)];
          if (!(d > 0.0)) continue;
          const double nx = (al * (xe + xw) + ga * (xn + xs + qq * xet) - 2.0 * be * xc) / d;
          const double nrr = (al * (re + rw) + ga * (rn + rs + qq * ret) - 2.0 * be * rc) / d;
          moved = std::max(moved, std::hypot(nx - x[id(a, b)], nrr - r[id(a, b)]));
          x[id(a, b)] = nx;
          r[id(a, b)] = nrr;
        }
      if (moved < 1e-9 * scale) break;
    }
    for (int a = 1; a < W - 1; ++a) {
      vertical_[wrap(lo + a)] = 0;
      for (int b = 1; b < H - 1; ++b) {
        vx_[at(lo + a, j0 + b)] = x[id(a, b)] - shift(lo + a);
        vr_[at(lo + a, j0 + b)] = r[id(a, b)];
      }
    }
    // the smoothed lines need not be graphs over r, nor ordered along the axis at every radius:
    // the point location searches the elements instead of walking the columns
    walkable_ = false;
    if (find_fold(bad_c, bad_j)) return true;
  }
  vx_ = vx0;
  vr_ = vr0;
  vertical_ = vertical0;
  walkable_ = true;
  return false;
}

// Jacobian x_xi r_eta - x_eta r_xi at the four corners of every element (bilinear map: positive
// at the corners implies positive everywhere); false and the first element where it is not
// positive when there is one.
bool FittedMesh::find_fold(int& bad_c, int& bad_j) {
  min_jac_ = INFINITY;
  for (int c = 0; c < nc_; ++c)
    for (int j = 0; j < ny_; ++j) {
      const double worst = corner_jacobian(c, j);
      min_jac_ = std::min(min_jac_, worst);
      if (!(worst > 0.0)) {
        bad_c = c;
        bad_j = j;
        return false;
      }
    }
  return true;
}

double FittedMesh::corner_jacobian(int c, int j) const {
  double x[4], r[4];
  corners(element(c, j), x, r);
  double worst = INFINITY;
  for (int i = 0; i < 4; ++i) {
    // derivatives at corner i (times 2): along xi the edge (0,1) at eta = -1 or (3,2) at
    // eta = +1; along eta the edge (0,3) at xi = -1 or (1,2) at xi = +1
    const double xx = i <= 1 ? x[1] - x[0] : x[2] - x[3], rx = i <= 1 ? r[1] - r[0] : r[2] - r[3];
    const bool left = i == 0 || i == 3;
    const double xe = left ? x[3] - x[0] : x[2] - x[1], re = left ? r[3] - r[0] : r[2] - r[1];
    worst = std::min(worst, 0.25 * (xx * re - xe * rx));
  }
  return worst;
}

void FittedMesh::corners(int e, double x[4], double r[4]) const {
  const int c = element_column(e), j = element_row(e);
  x[0] = vertex_x(c, j);
  x[1] = vertex_x(c + 1, j);
  x[2] = vertex_x(c + 1, j + 1);
  x[3] = vertex_x(c, j + 1);
  r[0] = vertex_r(c, j);
  r[1] = vertex_r(c + 1, j);
  r[2] = vertex_r(c + 1, j + 1);
  r[3] = vertex_r(c, j + 1);
}

void FittedMesh::rim_path(int end, std::vector<RimPathEdge>& path) const {
  const int c = end == 0 ? 0 : n_ - 1;
  path.resize(std::size_t(p_.cells_inner));
  for (int j = 0; j < p_.cells_inner; ++j) {
    RimPathEdge& s = path[std::size_t(j)];
    for (int m = 0; m < 3; ++m) s.node[m] = node(2 * c, 2 * j + m);
    s.x0 = vertex_x(c, j);
    s.r0 = vertex_r(c, j);
    s.x1 = vertex_x(c, j + 1);
    s.r1 = vertex_r(c, j + 1);
  }
}

Eigen::Vector2d FittedMesh::node_position(int I, int J) const {
  const int c = I / 2, j = J / 2;
  const bool mx = I % 2, mr = J % 2;
  auto at = [&](int cc) -> Eigen::Vector2d {
    if (!mr) return {vertex_x(cc, j), vertex_r(cc, j)};
    return {0.5 * (vertex_x(cc, j) + vertex_x(cc, j + 1)), 0.5 * (vertex_r(cc, j) + vertex_r(cc, j + 1))};
  };
  return mx ? Eigen::Vector2d(0.5 * (at(c) + at(c + 1))) : at(c);
}

int FittedMesh::locate(double& x, double r, double& xi, double& eta) const {
  if (!fitted_) throw std::logic_error("FittedMesh::locate before fit()");
  if (!std::isfinite(x) || !(r >= 0.0 && r <= p_.Rc))
    throw std::invalid_argument("FittedMesh::locate: the point (x = " + fmt(x) + " m, r = " + fmt(r) +
                                " m) is outside 0 <= r <= Rc");
  // x of vertex column c's line (piecewise linear in r between its vertices) at radius r
  auto line_x = [&](int c) {
    int lo = 0, hi = ny_;
    while (hi - lo > 1) {
      const int mid = (lo + hi) / 2;
      (vertex_r(c, mid) <= r ? lo : hi) = mid;
    }
    const double r0 = vertex_r(c, lo), r1 = vertex_r(c, lo + 1);
    const double t = std::clamp((r - r0) / (r1 - r0), 0.0, 1.0);
    return vertex_x(c, lo) + t * (vertex_x(c, lo + 1) - vertex_x(c, lo));
  };
  const double P = p_.period, x0 = line_x(0);
  x = x0 + (x - x0) - P * std::floor((x - x0) / P);
  if (x >= x0 + P) x -= P;
  if (!walkable_) return search(x, r, xi, eta);
  int lo = 0, hi = nc_;  // column strip: line_x(lo) <= x < line_x(hi), line_x(nc_) = x0 + P
  while (hi - lo > 1) {
    const int mid = (lo + hi) / 2;
    (line_x(mid) <= x ? lo : hi) = mid;
  }
  const int c = lo;
  // row: the point lies above (to the left of, along xi) row line j between (c, j) and (c+1, j)
  auto above = [&](int j) {
    const double ax = vertex_x(c, j), ar = vertex_r(c, j);
    const double bx = vertex_x(c + 1, j), br = vertex_r(c + 1, j);
    return (bx - ax) * (r - ar) - (br - ar) * (x - ax) >= 0.0;
  };
  int jl = 0, jh = ny_;
  while (jh - jl > 1) {
    const int mid = (jl + jh) / 2;
    (above(mid) ? jl : jh) = mid;
  }
  const int e = element(c, jl);
  double cx[4], cr[4];
  corners(e, cx, cr);
  if (column_vertical(c) && column_vertical(c + 1)) {  // vertical sides: explicit
    const double t = (x - cx[0]) / (cx[1] - cx[0]);
    xi = 2.0 * t - 1.0;
    const double rb = cr[0] * (1.0 - t) + cr[1] * t, rt = cr[3] * (1.0 - t) + cr[2] * t;
    eta = std::clamp(2.0 * (r - rb) / (rt - rb) - 1.0, -1.0, 1.0);
    return e;
  }
  // Newton on the bilinear map
  xi = 0.0;
  eta = 0.0;
  for (int it = 0; it < 50; ++it) {
    double dxi, deta;
    newton_step(cx, cr, x, r, xi, eta, dxi, deta);
    xi = std::clamp(xi - dxi, -1.0, 1.0);
    eta = std::clamp(eta - deta, -1.0, 1.0);
    if (std::abs(dxi) + std::abs(deta) < 1e-14) break;
  }
  return e;
}

// The reference coordinates of (x, r) in element e by Newton's method on the bilinear map,
// unclamped; false when they do not converge.
bool FittedMesh::invert(int e, double x, double r, double& xi, double& eta) const {
  double cx[4], cr[4];
  corners(e, cx, cr);
  const double lo_x = std::min({cx[0], cx[1], cx[2], cx[3]}), hi_x = std::max({cx[0], cx[1], cx[2], cx[3]});
  const double lo_r = std::min({cr[0], cr[1], cr[2], cr[3]}), hi_r = std::max({cr[0], cr[1], cr[2], cr[3]});
  const double tol = 1e-9 * (hi_x - lo_x + hi_r - lo_r);
  if (x < lo_x - tol || x > hi_x + tol || r < lo_r - tol || r > hi_r + tol) return false;
  static constexpr double cs[4] = {-1, 1, 1, -1}, ct[4] = {-1, -1, 1, 1};
  for (int start = 0; start < 5; ++start) {  // from the centre, then from each corner
    xi = start ? 0.9 * cs[start - 1] : 0.0;
    eta = start ? 0.9 * ct[start - 1] : 0.0;
    if (newton(cx, cr, x, r, xi, eta)) return true;
  }
  return false;
}

// One Newton step on the bilinear map of the corners (cx, cr) towards (x, r) from (xi, eta):
// the update (dxi, deta); false where the map's Jacobian vanishes (the update is then not finite).
bool FittedMesh::newton_step(const double cx[4], const double cr[4], double x, double r, double xi, double eta,
                             double& dxi, double& deta) {
  const BilinearPoint b = bilinear_map(cx, cr, xi, eta);
  const double fx = b.x - x, fr = b.r - r, xx = b.xx, xe = b.xe, rx = b.rx, re = b.re;
  const double det = xx * re - xe * rx;
  dxi = (re * fx - xe * fr) / det;
  deta = (-rx * fx + xx * fr) / det;
  return det != 0.0;
}

bool FittedMesh::newton(const double cx[4], const double cr[4], double x, double r, double& xi, double& eta) {
  for (int it = 0; it < 50; ++it) {
    double dxi, deta;
    if (!newton_step(cx, cr, x, r, xi, eta, dxi, deta)) return false;
    xi -= dxi;
    eta -= deta;
    if (!(std::abs(xi) < 4.0 && std::abs(eta) < 4.0)) return false;
    // converged far below the inside tolerance (1e-14 can lie below the round-off of a thin element)
    if (std::abs(dxi) + std::abs(deta) < 1e-11) return std::max(std::abs(xi), std::abs(eta)) <= 1.0 + 1e-9;
  }
  return false;
}

// Point location on a mesh smoothed around a fold (its lines need not be graphs over r, nor
// ordered along the axis at every radius): every element (and its periodic image) is tried.
int FittedMesh::search(double& x, double r, double& xi, double& eta) const {
  for (double xs : {x, x + p_.period, x - p_.period})
    for (int e = 0; e < elements(); ++e)
      if (invert(e, xs, r, xi, eta)) {
        xi = std::clamp(xi, -1.0, 1.0);
        eta = std::clamp(eta, -1.0, 1.0);
        x = xs;
        return e;
      }
  throw std::invalid_argument("FittedMesh::locate: the point (x = " + fmt(x) + " m, r = " + fmt(r) +
                              " m) lies in no element");
}

}  // namespace swim::axi
