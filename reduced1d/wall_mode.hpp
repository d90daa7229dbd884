// The viscous resistance of an axisymmetric wall mode on an infinitely long straight tube:
// exact Stokes flow in the lumen and in the annulus of a rigid coaxial container, and the 1D
// tier's model of it (the lubrication pressures plus the short-wave traction). The reference
// that bounds the 1D tier's wall dynamics on a uniform tube (docs/outer-flow-1d.md §3b).
#pragma once

namespace swim::reduced1d {

/// Normal stress on the wall per unit radial wall velocity, Pa s/m, of the wall mode
/// u_r = w sin(kz), u_z = 0 at r = R (the wall moves radially only), split by the fluid it
/// comes from. The force on the wall is -(lumen + annulus) w sin(kz): the mode is resisted.
struct WallModeResistance {
  double lumen = 0.0;    ///< from the lumen, 0 <= r < R
  double annulus = 0.0;  ///< from the outside, R < r < Rc (no slip at Rc), or unbounded
  double total() const { return lumen + annulus; }
};

/// Exact axisymmetric Stokes solution (stream function r I1(kr), r^2 I0(kr) in the lumen, with
/// r K1(kr), r^2 K0(kr) outside; Bessel functions from GSL, scaled so that no term overflows).
/// k > 0 [1/m], 0 < R < Rc [m] (Rc = +infinity: unbounded outside), mu > 0 [Pa s].
/// Limits: kR -> 0, the lubrication resistances below; kR -> infinity, 2 mu k from each side
/// (a plane wall moving normal to itself). Round-off grows as the wave lengthens (the basis
/// solutions cancel): below 10^-7 relative for kR >= 10^-3, about 10^-5 at kR = 10^-4, where
/// lubrication is exact to (k Rc)^2 anyway. Throws std::invalid_argument outside the domain.
WallModeResistance stokes_wall_mode_resistance(double k, double R, double Rc, double mu);

/// The confined 1D tier's resistance of the same mode: lumen lubrication 16 mu / (k^2 R^3),
/// annulus lubrication 16 mu R / (k^2 G) with G = Rc^4 - R^4 - (Rc^2 - R^2)^2 / ln(Rc/R) (none
/// when Rc is infinite: the unbounded outer flow is not a lubrication model), and,
/// when `traction` (model1d.short_wave_traction), 2 mu |k| on each side.
WallModeResistance lubrication_wall_mode_resistance(double k, double R, double Rc, double mu, bool traction);

}  // namespace swim::reduced1d
