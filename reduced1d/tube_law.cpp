#include "reduced1d/tube_law.hpp"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_interp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "common/errors.hpp"
#include "common/si_format.hpp"

namespace swim::reduced1d {

struct TubeLaw::Gsl {
  gsl_interp* interp = nullptr;
  ~Gsl() {
    if (interp) gsl_interp_free(interp);
  }
};

namespace {
}  // namespace

TubeLaw::TubeLaw(double R0, std::vector<double> R, std::vector<double> w)
    : R0_(R0), R_(std::move(R)), w_(std::move(w)), g_(std::make_unique<Gsl>()) {
  const char* key = "wall.calibration";
  const std::size_t n = R_.size();
  if (n < 3 || w_.size() != n)
    throw InputError(key, std::to_string(n) + " tube-law knots",
                     "a tube law needs at least three knots (R, w) of equal count");
  for (std::size_t k = 0; k < n; ++k) {
    if (!std::isfinite(R_[k]) || !std::isfinite(w_[k]) || !(R_[k] > 0))
      throw InputError(key, "knot " + std::to_string(k) + " (" + significant(R_[k]) + " m, " + significant(w_[k]) + " Pa)",
                       "tube-law knots must be finite with a positive radius");
    if (k > 0 && !(R_[k] > R_[k - 1] && w_[k] > w_[k - 1]))
      throw InputError(key, "knot " + std::to_string(k) + " (" + significant(R_[k]) + " m, " + significant(w_[k]) + " Pa)",
                       "tube-law knots must be strictly increasing in both radius and wall pressure (a monotone law)");
  }
  if (!(R_.back() == R0_) || !(w_.back() == 0.0))
    throw InputError(key, "last knot (" + significant(R_.back()) + " m, " + significant(w_.back()) + " Pa)",
                     "the last tube-law knot must be the undeformed tube (R0 = " + significant(R0_) + " m, 0 Pa)");
  g_->interp = gsl_interp_alloc(gsl_interp_steffen, n);
  if (!g_->interp || gsl_interp_init(g_->interp, R_.data(), w_.data(), n) != GSL_SUCCESS)
    throw InputError(key, "tube-law knots", "GSL could not build the Steffen interpolant");
  s_lo_ = gsl_interp_eval_deriv(g_->interp, R_.data(), w_.data(), R_.front(), nullptr);
  s_hi_ = gsl_interp_eval_deriv(g_->interp, R_.data(), w_.data(), R_.back(), nullptr);
  // The Steffen coefficients (M. Steffen, Astron. Astrophys. 239, 443 (1990), as GSL's
  // gsl_interp_steffen computes them): y'_k from the neighbouring secants with the limiter,
  // the end knots' y' their secants.
  std::vector<double> yp(n);
  yp[0] = (w_[1] - w_[0]) / (R_[1] - R_[0]);
  for (std::size_t k = 1; k + 1 < n; ++k) {
    const double hk = R_[k + 1] - R_[k], hm = R_[k] - R_[k - 1];
    const double sk = (w_[k + 1] - w_[k]) / hk, sm = (w_[k] - w_[k - 1]) / hm;
    const double pk = (sm * hk + sk * hm) / (hm + hk);
    // both secants are positive (strictly increasing knots): sign factor 2
    yp[k] = 2.0 * std::min(std::abs(sm), std::min(std::abs(sk), 0.5 * std::abs(pk)));
  }
  yp[n - 1] = (w_[n - 1] - w_[n - 2]) / (R_[n - 1] - R_[n - 2]);
  a_.resize(n - 1), b_.resize(n - 1), c_.resize(n - 1), d_.resize(n - 1);
  for (std::size_t k = 0; k + 1 < n; ++k) {
    const double hk = R_[k + 1] - R_[k], sk = (w_[k + 1] - w_[k]) / hk;
    a_[k] = (yp[k] + yp[k + 1] - 2.0 * sk) / hk / hk;
    b_[k] = (3.0 * sk - 2.0 * yp[k] - yp[k + 1]) / hk;
    c_[k] = yp[k];
    d_[k] = w_[k];
  }
  int_to_R0_.assign(n, 0.0);
  for (std::size_t k = n - 1; k-- > 0;) {
    const double x = R_[k + 1] - R_[k];
    int_to_R0_[k] = int_to_R0_[k + 1] + x * (d_[k] + x * (0.5 * c_[k] + x * (b_[k] / 3.0 + x * 0.25 * a_[k])));
  }
  // Steffen's end slope may be zero (the secants' limiter); the law must keep a positive slope
  // so that the static radius is unique: fall back to the end secant
  if (!(s_lo_ > 0)) s_lo_ = (w_[1] - w_[0]) / (R_[1] - R_[0]);
  if (!(s_hi_ > 0)) s_hi_ = (w_[n - 1] - w_[n - 2]) / (R_[n - 1] - R_[n - 2]);
}

TubeLaw::~TubeLaw() = default;

std::size_t TubeLaw::interval(double R) const {
  // the largest k with R_k <= R (R_front < R < R_back: 0 <= k <= n - 2)
  return std::size_t(std::upper_bound(R_.begin(), R_.end(), R) - R_.begin()) - 1;
}

double TubeLaw::eval(double R, double& dw) const {
  if (R <= R_.front()) {
    dw = s_lo_;
    return w_.front() + s_lo_ * (R - R_.front());
  }
  if (R >= R_.back()) {
    dw = s_hi_;
    return s_hi_ * (R - R0_);
  }
  const std::size_t k = interval(R);
  const double x = R - R_[k];
  dw = c_[k] + x * (2.0 * b_[k] + x * 3.0 * a_[k]);
  return d_[k] + x * (c_[k] + x * (b_[k] + x * a_[k]));
}

double TubeLaw::energy(double R) const {
  if (R >= R0_) return 0.5 * s_hi_ * (R - R0_) * (R - R0_);
  const double a = std::max(R, R_.front());
  // int_{R0}^{R} w = -int_{a}^{R0} w - int_{R}^{a} w; int_{a}^{R0} w = int_{R_k}^{R0} w - int_{R_k}^{a} w
  const std::size_t k = a <= R_.front() ? 0 : interval(a);
  const double x = a - R_[k];
  double e = -(int_to_R0_[k] - x * (d_[k] + x * (0.5 * c_[k] + x * (b_[k] / 3.0 + x * 0.25 * a_[k]))));
  if (R < a) {
    const double d = a - R;  // linear piece below the deepest knot: w = w0 + s_lo (r - a)
    e += -w_.front() * d + 0.5 * s_lo_ * d * d;  // -int_{R}^{a} w
  }
  return e;
}

double TubeLaw::static_radius(double P) const {
  const double target = -P;
  if (target <= w_.front()) return R_.front() + (target - w_.front()) / s_lo_;
  if (target >= 0.0) return R0_ + target / s_hi_;
  // bracketed Newton on the monotone interpolant
  double a = R_.front(), b = R0_;
  double x = a + (b - a) * (target - w_.front()) / (0.0 - w_.front());
  for (int it = 0; it < 200; ++it) {
    double d;
    const double f = eval(x, d) - target;
    if (f > 0) b = x;
    else a = x;
    if (f == 0 || b - a <= 1e-15 * R0_) break;
    double xn = x - f / d;
    if (!(xn > a && xn < b) || !std::isfinite(xn)) xn = 0.5 * (a + b);
    if (std::abs(xn - x) <= 1e-16 * R0_) {
      x = xn;
      break;
    }
    x = xn;
  }
  return x;
}

}  // namespace swim::reduced1d
