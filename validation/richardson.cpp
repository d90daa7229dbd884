#include "validation/richardson.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <cstdio>
#include <cstdlib>
#include <numeric>

#include <Eigen/Dense>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_roots.h>

#include "common/errors.hpp"

namespace swim::validation {

double bracketed_root(const std::function<double(double)>& f, double lo, double hi) {
  if (f(lo) == 0.0) return lo;
  if (f(hi) == 0.0) return hi;
  gsl_function F;
  F.function = [](double x, void* p) { return (*static_cast<const std::function<double(double)>*>(p))(x); };
  F.params = const_cast<std::function<double(double)>*>(&f);
  std::unique_ptr<gsl_root_fsolver, decltype(&gsl_root_fsolver_free)> s(gsl_root_fsolver_alloc(gsl_root_fsolver_brent),
                                                                        gsl_root_fsolver_free);
  if (gsl_root_fsolver_set(s.get(), &F, lo, hi) != GSL_SUCCESS)
    throw NumericalError("no sign change of the function on [" + std::to_string(lo) + ", " + std::to_string(hi) + "]",
                         "widen the bracket");
  for (int it = 0; it < 200; ++it) {
    gsl_root_fsolver_iterate(s.get());
    const double a = gsl_root_fsolver_x_lower(s.get()), b = gsl_root_fsolver_x_upper(s.get());
    if (gsl_root_test_interval(a, b, 0.0, 1e-14) == GSL_SUCCESS) break;
  }
  return gsl_root_fsolver_root(s.get());
}

std::string OrderRange::text() const {
  char b[64];
  std::snprintf(b, sizeof b, "[%g, %g]", lo, hi);
  return b;
}

namespace {

/// The series ordered from the coarsest grid to the finest; InputError for repeated spacings.
void coarse_to_fine(const std::vector<double>& h, const std::vector<double>& f, std::vector<double>& hs,
                    std::vector<double>& fs) {
  std::vector<std::size_t> idx(h.size());
  std::iota(idx.begin(), idx.end(), 0);
  std::sort(idx.begin(), idx.end(), [&](std::size_t a, std::size_t b) { return h[a] > h[b]; });
  hs.clear();
  fs.clear();
  for (std::size_t i : idx) {
    hs.push_back(h[i]);
    fs.push_back(f[i]);
  }
  for (std::size_t i = 1; i < hs.size(); ++i)
    if (!(hs[i] < hs[i - 1])) throw InputError("validation grids", std::to_string(hs[i]), "distinct grid spacings");
}

/// A fit's grids, checked and ordered from the coarsest to the finest (hs, fs), and what a
/// refused fit returns: the finest value with the spread of the finest three as its error.
Extrapolation finest_of_series(const std::vector<double>& h, const std::vector<double>& f, std::vector<double>& hs,
                               std::vector<double>& fs) {
  if (h.size() != f.size() || h.size() < 2)
    throw InputError("validation grids", std::to_string(h.size()), "two or more grids, one value per grid");
  coarse_to_fine(h, f, hs, fs);
  const std::size_t k3 = fs.size() >= 3 ? fs.size() - 3 : 0;
  Extrapolation e;
  e.value = fs.back();
  e.error = *std::max_element(fs.begin() + long(k3), fs.end()) - *std::min_element(fs.begin() + long(k3), fs.end());
  return e;
}

}  // namespace

Extrapolation richardson(std::vector<double> h, std::vector<double> f, double assumed_order, OrderRange range) {
  if (h.size() != f.size() || h.size() < 2)
    throw InputError("validation grids", std::to_string(h.size()), "two or more grids, one value per grid");
  if (!(range.lo > 0 && range.hi > range.lo && range.hi <= kOrderSearchMax))
    throw InputError("order range", range.text(),
                     "0 < lo < hi <= " + std::to_string(int(kOrderSearchMax)) + " (the orders the scheme can show)");
  if (!(assumed_order >= range.lo && assumed_order <= range.hi))
    throw InputError("assumed order", std::to_string(assumed_order), "inside the order range " + range.text());
  std::vector<double> hs, fs;
  coarse_to_fine(h, f, hs, fs);
  const std::size_t n = hs.size();
  const double f3 = fs[n - 1], f2 = fs[n - 2], h3 = hs[n - 1], h2 = hs[n - 2];
  Extrapolation e;
  auto extrapolate = [&](double p) { return f3 + (f3 - f2) / (std::pow(h2 / h3, p) - 1.0); };
  // a correction larger than half the finest value: the grids are too coarse for the error
  // expansion to hold (it would, for instance, extrapolate a cycle time to a negative one)
  auto too_large = [&](double value) { return std::abs(value - f3) > kMaxCorrection * std::abs(f3); };
  if (n == 2) {
    const double v = extrapolate(assumed_order);
    if (too_large(v)) {
      e.value = f3;
      e.error = std::abs(f3 - f2);
      e.note = "two grids too coarse (the extrapolation would change the finest value by more than half): finest "
               "grid, error = difference of the two";
      return e;
    }
    e.order = assumed_order;
    e.method = "richardson";
    e.value = v;
    // the order is assumed, not observed: the error is at least the difference of the two
    e.error = std::max(std::abs(e.value - f3), std::abs(f3 - f2));
    e.asymptotic = true;
    char b[32];
    std::snprintf(b, sizeof b, "%g", assumed_order);
    e.note = std::string("two grids, assumed order ") + b;
    return e;
  }
  const double f1 = fs[n - 3], h1 = hs[n - 3];
  const double d12 = f1 - f2, d23 = f2 - f3;
  const double spread = *std::max_element(fs.end() - 3, fs.end()) - *std::min_element(fs.end() - 3, fs.end());
  auto not_asymptotic = [&](const std::string& why) {
    e.value = f3;
    e.error = spread;
    e.order = 0;
    e.asymptotic = false;
    e.note = "not in the asymptotic range (" + why + "): finest grid, error = spread of the three";
    return e;
  };
  if (d23 == 0.0 && d12 == 0.0) {
    e.value = f3;
    e.asymptotic = true;
    e.method = "richardson";
    e.note = "identical on the three grids";
    return e;
  }
  if (!(d12 * d23 > 0)) return not_asymptotic("the differences change sign");
  const double ratio = d12 / d23;
  // spacings relative to the finest, so that h^p neither under- nor overflows
  const double a = h1 / h3, b = h2 / h3;
  auto g = [&](double p) { return (std::pow(a, p) - std::pow(b, p)) / (std::pow(b, p) - 1.0) - ratio; };
  char buf[160];
  // g grows with p: below the bracket's g the order is lower than its low end, above it higher
  if (g(kOrderSearchMin) > 0) {
    std::snprintf(buf, sizeof buf,
                  "observed order below %g (the differences do not shrink as h falls), outside the range %s of the "
                  "scheme",
                  kOrderSearchMin, range.text().c_str());
    return not_asymptotic(buf);
  }
  if (g(kOrderSearchMax) < 0) {
    std::snprintf(buf, sizeof buf, "observed order above %g, outside the range %s of the scheme", kOrderSearchMax,
                  range.text().c_str());
    return not_asymptotic(buf);
  }
  const double order = bracketed_root(g, kOrderSearchMin, kOrderSearchMax);
  e.observed_order = order;
  // round-off of the root (1e-14 relative) does not take an order on the range's end out of it
  const double slack = 1e-9 * range.hi;
  if (order < range.lo - slack || order > range.hi + slack) {
    // enough digits to show the order outside the range (2.005, not 2)
    int digits = 3;
    for (; digits < 8; ++digits) {
      std::snprintf(buf, sizeof buf, "%.*g", digits, order);
      const double shown = std::atof(buf);
      if (shown < range.lo || shown > range.hi) break;
    }
    std::snprintf(buf, sizeof buf, "observed order %.*g, outside the range %s of the scheme", digits, order,
                  range.text().c_str());
    return not_asymptotic(buf);
  }
  if (too_large(extrapolate(order))) return not_asymptotic("the extrapolation would change the finest value by more than half");
  e.order = order;
  e.value = extrapolate(e.order);
  e.error = std::abs(e.value - f3);
  e.asymptotic = true;
  e.method = "richardson";
  std::snprintf(buf, sizeof buf, "Richardson with the observed order (inside the range %s of the scheme)",
                range.text().c_str());
  e.note = buf;
  return e;
}

std::optional<Extrapolation> bound_within_time_error(std::vector<double> h, std::vector<double> f, double time_error,
                                                     OrderRange range) {
  if (h.size() != f.size())
    throw InputError("validation grids", std::to_string(h.size()), "one value per grid");
  if (h.size() < 3 || !(time_error > 0) || !std::isfinite(time_error)) return std::nullopt;
  std::vector<double> hs, fs;
  coarse_to_fine(h, f, hs, fs);
  const std::size_t n = hs.size();
  double bound = 0;
  for (std::size_t k = n - 3; k + 1 < n; ++k) {
    const double d = std::abs(fs[k] - fs[k + 1]);
    if (!(d <= 2.0 * time_error)) return std::nullopt;
    bound = std::max(bound, (d + 2.0 * time_error) / (std::pow(hs[k] / hs[k + 1], range.lo) - 1.0));
  }
  Extrapolation e;
  e.value = fs.back();
  e.error = bound + time_error;
  e.order = 0;
  e.asymptotic = false;
  e.within_time_error = true;
  e.method = "time_error_bound";
  char b[200];
  std::snprintf(b, sizeof b,
                "the grids' differences lie within the time integration's error (2 × %.3g): finest grid, its grid error "
                "bounded at the scheme's lowest order %g, plus the time integration's error",
                time_error, range.lo);
  e.note = b;
  return e;
}

namespace {

/// The least-squares fit f = f0 + a h + b h^2: (f0, a, b), with h in units of h_unit for the
/// solve (the coefficients returned are per m and per m^2).
Eigen::Vector3d expansion_coefficients(const std::vector<double>& h, const std::vector<double>& f, double h_unit) {
  Eigen::MatrixXd A(h.size(), 3);
  Eigen::VectorXd y(h.size());
  for (std::size_t i = 0; i < h.size(); ++i) {
    const double x = h[i] / h_unit;
    A(i, 0) = 1.0;
    A(i, 1) = x;
    A(i, 2) = x * x;
    y(i) = f[i];
  }
  const Eigen::Vector3d c = A.colPivHouseholderQr().solve(y);
  return {c(0), c(1) / h_unit, c(2) / (h_unit * h_unit)};
}

double expansion_f0(const std::vector<double>& h, const std::vector<double>& f, double h_unit) {
  return expansion_coefficients(h, f, h_unit)(0);
}

}  // namespace

Extrapolation expansion_fit(std::vector<double> h, std::vector<double> f, OrderRange range) {
  std::vector<double> hs, fs;
  Extrapolation e = finest_of_series(h, f, hs, fs);
  const std::size_t n = hs.size();
  const double finest = fs.back();
  auto refuse = [&](const std::string& why) {
    e.note = "no error-expansion fit (" + why + "): finest grid, error = spread of the finest three";
    return e;
  };
  if (n < 4) return refuse("fewer than four grids");
  if (!(range.lo <= 1.0 && 1.0 <= range.hi && range.hi <= kFirstOrderHighest))
    return refuse("the scheme's order range " + range.text() + " is not that of a first-order method");
  const double unit = hs.back();
  const Eigen::Vector3d coef = expansion_coefficients(hs, fs, unit);
  const double f0 = coef(0);
  double loo = 0;
  for (std::size_t i = 0; i < n; ++i) {
    std::vector<double> hh, ff;
    for (std::size_t j = 0; j < n; ++j)
      if (j != i) {
        hh.push_back(hs[j]);
        ff.push_back(fs[j]);
      }
    loo = std::max(loo, std::abs(expansion_f0(hh, ff, unit) - f0));
  }
  // the finest pair extrapolated with the lowest order the scheme can show and with first
  // order: an order below 1 on the affordable grids (a free rim's square-root singularity)
  // moves the limit that far, which no fit of integer powers sees
  const double hp = hs[n - 2], fp = fs[n - 2];
  double pair = 0;
  for (double p : {range.lo, 1.0}) {
    const double r = finest + (finest - fp) / (std::pow(hp / unit, p) - 1.0);
    pair = std::max(pair, std::abs(r - f0));
  }
  if (!std::isfinite(f0) || !std::isfinite(loo) || !std::isfinite(pair)) return refuse("the fit is singular");
  if (std::abs(f0 - finest) > kMaxCorrection * std::abs(finest))
    return refuse("it would change the finest value by more than half");
  e.value = f0;
  e.error = std::max(loo, pair);
  e.order = 1.0;
  e.asymptotic = false;
  e.method = "expansion_fit";
  e.expansion_a = coef(1);
  e.expansion_b = coef(2);
  char b[320];
  std::snprintf(b, sizeof b,
                "error expansion f0 + a h + b h^2 fitted to %zu grids (not in the asymptotic range); error = the largest "
                "change when one grid is left out, or to the finest pair's extrapolation at order 1 or %g",
                n, range.lo);
  e.note = b;
  return e;
}

namespace {

/// Least-squares line y = c0 + c1 h; false when the grids do not determine it.
bool fit_line(const std::vector<double>& h, const std::vector<double>& y, double& c0, double& c1) {
  const double n = double(h.size());
  double sh = 0, sy = 0, shh = 0, shy = 0;
  for (std::size_t i = 0; i < h.size(); ++i) {
    sh += h[i];
    sy += y[i];
    shh += h[i] * h[i];
    shy += h[i] * y[i];
  }
  const double det = n * shh - sh * sh;
  if (!(std::abs(det) > 0.0)) return false;
  c1 = (n * shy - sh * sy) / det;
  c0 = (sy - c1 * sh) / n;
  return std::isfinite(c0) && std::isfinite(c1);
}

/// T0 of the line through (h, T^-1/4); NaN when it has none (c0 <= 0).
double lumen_t0(const std::vector<double>& h, const std::vector<double>& T, double* a = nullptr) {
  std::vector<double> y(T.size());
  for (std::size_t i = 0; i < T.size(); ++i) y[i] = std::pow(T[i], -0.25);
  double c0 = 0, c1 = 0;
  if (!fit_line(h, y, c0, c1) || !(c0 > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  if (a) *a = -c1 / c0;
  return std::pow(c0, -4.0);
}

}  // namespace

Extrapolation lumen_fit(std::vector<double> h, std::vector<double> T) {
  std::vector<double> hs, ts;
  Extrapolation e = finest_of_series(h, T, hs, ts);
  const std::size_t n = hs.size();
  const double finest = ts.back();
  auto refuse = [&](const std::string& why) {
    e.note = "no lumen fit (" + why + "): finest grid, error = spread of the finest three";
    return e;
  };
  if (n < 3) return refuse("fewer than three grids");
  for (double t : ts)
    if (!(t > 0.0) || !std::isfinite(t)) return refuse("a cycle time that is not positive");
  double a = 0;
  const double t0 = lumen_t0(hs, ts, &a);
  if (!std::isfinite(t0)) return refuse("the line of T^-1/4 has no positive intercept");
  if (!(a > 0.0)) return refuse("the cycle does not lengthen towards the coarse grids");
  if (!(a * hs.front() < 1.0)) return refuse("the fitted lumen closes within the grids (a h >= 1)");
  double loo = 0;
  if (n >= 4)
    for (std::size_t i = 0; i < n; ++i) {
      std::vector<double> hh, tt;
      for (std::size_t j = 0; j < n; ++j)
        if (j != i) {
          hh.push_back(hs[j]);
          tt.push_back(ts[j]);
        }
      loo = std::max(loo, std::abs(lumen_t0(hh, tt) - t0));
    }
  const double pair = std::abs(lumen_t0({hs[n - 2], hs[n - 1]}, {ts[n - 2], ts[n - 1]}) - t0);
  if (!std::isfinite(loo) || !std::isfinite(pair)) return refuse("a refit without one grid has no intercept");
  if (std::abs(t0 - finest) > kMaxCorrection * std::abs(finest))
    return refuse("it would change the finest value by more than half");
  e.value = t0;
  e.error = std::max({loo, pair, kLumenModelShare * std::abs(t0 - finest)});
  e.order = 1.0;
  e.asymptotic = false;
  e.method = "lumen_fit";
  e.lumen_a = a;
  char b[360];
  std::snprintf(b, sizeof b,
                "lumen fit T0 (1 - a h)^-4 to %zu grids (the smearing narrows the lumen by a h = %.2f on the finest, "
                "%.2f on the coarsest; not in the asymptotic range); error = the largest change when one grid is left "
                "out, the distance to the two finest grids' line, or a quarter of the correction",
                n, a * hs.back(), a * hs.front());
  e.note = b;
  return e;
}

Extrapolation extrapolate_series(const std::vector<double>& h, const std::vector<double>& f, double assumed_order,
                                 OrderRange range) {
  const Extrapolation r = richardson(h, f, assumed_order, range);
  if (r.asymptotic || h.size() < 4) return r;
  Extrapolation e = expansion_fit(h, f, range);
  if (e.method != "expansion_fit") return r;  // refused: keep Richardson's own statement
  e.observed_order = r.observed_order;
  e.note += "; three finest grids: " + r.note;
  return e;
}

SumExtrapolation richardson_sum(const std::vector<double>& h, const std::vector<std::vector<double>>& parts,
                                double assumed_order, OrderRange range, double target) {
  if (parts.size() != h.size() || parts.empty())
    throw InputError("validation grids", std::to_string(parts.size()), "one list of parts per grid");
  const std::size_t np = parts.front().size();
  for (const auto& p : parts)
    if (p.size() != np || np < 2)
      throw InputError("parts of a figure", std::to_string(p.size()), "the same number (two or more) on every grid");
  SumExtrapolation s;
  for (std::size_t k = 0; k < np; ++k) {
    std::vector<double> f;
    for (const auto& p : parts) f.push_back(p[k]);
    s.parts.push_back(richardson(h, f, assumed_order, range));
    s.value += s.parts.back().value;
    s.error += std::abs(s.parts.back().error);
  }
  s.relative_error = std::abs(s.value) > 0 ? s.error / std::abs(s.value) : std::numeric_limits<double>::infinity();
  bool each = true;
  s.asymptotic = true;
  for (const Extrapolation& e : s.parts) {
    const bool ordered = e.asymptotic && std::isfinite(e.observed_order);
    const bool negligible = std::abs(e.error) <= 0.1 * target * std::abs(s.value);
    each = each && (ordered || negligible);
    s.asymptotic = s.asymptotic && e.asymptotic;
  }
  s.converged = each && s.relative_error <= target;
  return s;
}

}  // namespace swim::validation
