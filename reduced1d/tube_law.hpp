// Nonlinear static tube law of the 1D wall, calibrated from uniform loads on the 3D membrane
// (docs/tube-law.md).
//
// The wall pressure w(R) is the transmural pressure that holds the tube at radius R in static
// equilibrium: w(R0) = 0, w < 0 for a contracted tube. The linear law is w = C1 (R - R0). A
// calibrated law is the Steffen interpolant (GSL gsl_interp_steffen: monotone between the
// knots, continuous first derivative, no overshoot) of the knots (R_k, w_k), R_k ascending with
// the last knot at R0, w_k strictly increasing. Outside the knots the law continues linearly
// with the interpolant's end slopes (below the deepest knot: an extrapolation, stated in the
// calibration). w is strictly increasing with dw/dR > 0 everywhere, so every transmural load
// has exactly one static radius.
#pragma once

#include <memory>
#include <vector>

namespace swim::reduced1d {

class TubeLaw {
 public:
  /// Throws swim::InputError (key "wall.calibration") when the knots are fewer than three,
  /// not strictly increasing in R and w, not finite, or do not end at (R0, 0).
  TubeLaw(double R0, std::vector<double> R, std::vector<double> w);
  ~TubeLaw();
  TubeLaw(const TubeLaw&) = delete;
  TubeLaw& operator=(const TubeLaw&) = delete;

  double R0() const { return R0_; }
  const std::vector<double>& knots_R() const { return R_; }
  const std::vector<double>& knots_w() const { return w_; }
  /// dw/dR at R0 (the law's small-load stiffness, Pa/m)
  double slope_at_R0() const { return s_hi_; }

  /// w(R) [Pa] and dw/dR [Pa/m].
  double eval(double R, double& dw) const;
  double operator()(double R) const {
    double d;
    return eval(R, d);
  }
  /// Stored elastic energy per unit reference wall area, int_{R0}^{R} w(r) dr [J/m^2] (>= 0).
  double energy(double R) const;
  /// The static radius under an inward load P (w(R) = -P): the unique root.
  double static_radius(double P) const;

 private:
  /// Index k of the knot interval [R_k, R_{k+1}) holding R (R_front < R < R_back).
  std::size_t interval(double R) const;

  double R0_;
  std::vector<double> R_, w_;
  double s_lo_ = 0, s_hi_ = 0;  // end slopes
  // The interpolant's cubic on interval k, w = d_k + x (c_k + x (b_k + x a_k)) with
  // x = R - R_k (GSL's Steffen coefficients, computed here so that an evaluation is one
  // search and one Horner pass instead of two library calls), and the integral of w from
  // R_k to R0 (the energy's whole intervals).
  std::vector<double> a_, b_, c_, d_, int_to_R0_;
  struct Gsl;
  std::unique_ptr<Gsl> g_;
};

/// The 1D wall's static law as the force model uses it: the linear C1 (R - R0) when `law` is
/// null (the expressions of the linear tier, unchanged bit for bit), else the calibrated law.
struct WallLaw {
  double R0 = 0, C1 = 0;
  const TubeLaw* law = nullptr;
  /// w(R) [Pa] and dw/dR [Pa/m]
  double eval(double R, double& dw) const {
    if (!law) {
      dw = C1;
      return C1 * (R - R0);
    }
    return law->eval(R, dw);
  }
  double operator()(double R) const {
    double d;
    return eval(R, d);
  }
  /// int_{R0}^{R} w dr [J/m^2]
  double energy(double R) const { return law ? law->energy(R) : 0.5 * C1 * (R - R0) * (R - R0); }
  /// radius with w(R) = -P
  double static_radius(double P) const { return law ? law->static_radius(P) : R0 - P / C1; }
};

}  // namespace swim::reduced1d
