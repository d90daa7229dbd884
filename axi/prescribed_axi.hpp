// Prescribed waves on the axisymmetric tier's fitted method: the force-free swimmer of a given
// radius wave R(z, t) (docs/axi.md "Prescribed waves").
//
// Kinematics (as the 1D tier's): the ring at reference position z_k (0..L along the tube, in the
// swimmer's frame) has the radius R(z_k, t) and moves axially with the swimmer only:
//     x_k(t) = x_start + z_k + X(t),   dX/dt = U(t).
// Fluid: steady Stokes flow with the wall's velocity (U, dR_k/dt) prescribed on the wall line
// (FittedStokes::prescribed_wall_velocity); U is the velocity that makes the total axial force
// on the tube vanish, U = -F_a / F_b. The container is a uniform periodic cylinder, so the flow
// and U do not depend on X: U(t) is a function of the shape and its rate at t alone, and
//     X(t) = int_0^t U,   V_rear(t) = int_0^t Q_rear,   V_front(t) = int_0^t Q_front
// are plain integrals (no ODE): adaptive Simpson per output interval.
#pragma once

#include <Eigen/Core>

#include <functional>
#include <memory>
#include <vector>

#include "axi/fe_stokes_axi.hpp"
#include "axi/fitted_mesh.hpp"
#include "common/scene_shared.hpp"

namespace swim::axi {

/// Ring radii R (m) and their rates Rt (m/s) at time t (s) at the reference positions z (m).
using RingKinematics =
    std::function<void(double t, const std::vector<double>& z, Eigen::VectorXd& R, Eigen::VectorXd& Rt)>;

/// The 1D tier's step and sine waves (reduced1d/discretisation.hpp PrescribedShape::eval, the
/// same formulas) on a tube of radius R0 and length L. std::invalid_argument for force_driven.
RingKinematics wave_kinematics(const scene::WaveSpec& w, double R0, double L);

/// The swimmer's instantaneous state.
struct PrescribedState {
  double t = 0;             ///< s
  double velocity = 0;      ///< U, m/s
  double drag = 0;          ///< F_b, the towed tube's drag, N s/m
  double towed_lumen_flux = 0;  ///< lumen flux of the towed tube relative to it, m^3/s per m/s
  double flux_rear = 0;     ///< through the rear end disc, relative to the rings, towards +x, m^3/s
  double flux_front = 0;    ///< through the front end disc, likewise, m^3/s
  double volume = 0;        ///< lumen volume inside the rings' meridian polygon (frustums), m^3
  Eigen::VectorXd R, Rt;    ///< ring radii (m) and rates (m/s)
};

/// Lumen volume of the meridian polygon through the rings (exact for the piecewise-linear
/// wall: sum of frustums pi/3 dx (r_k^2 + r_k r_{k+1} + r_{k+1}^2)), m^3.
double lumen_volume(const std::vector<double>& z, const Eigen::VectorXd& R);

class PrescribedSwimmer {
 public:
  /// z: the rings' reference positions (strictly increasing, z.front() = 0), m; x_start: the
  /// rear ring's axial position in the container (the flow does not depend on it). Throws what
  /// FittedStokes' constructor throws.
  PrescribedSwimmer(const FittedMeshParams& mp, double mu, std::vector<double> z, RingKinematics kinematics,
                    double x_start);

  /// One prescribed-velocity solve at time t (one factorisation, two solves). Throws
  /// swim::NumericalError (non-finite or non-positive radius, a shape the mesh cannot follow).
  PrescribedState evaluate(double t);

  const std::vector<double>& z() const { return z_; }
  const FittedStokes& stokes() const { return *stokes_; }
  long evaluations() const { return evaluations_; }
  /// The rings (3 x n: x, r, 0) of radii R at x_start + z_k.
  Eigen::Matrix3Xd rings(const Eigen::VectorXd& R) const;

 private:
  std::vector<double> z_;
  RingKinematics kin_;
  double x_start_;
  std::unique_ptr<FittedStokes> stokes_;
  long evaluations_ = 0;
};

/// The integrals of U, Q_rear and Q_front over [a.t, b.t].
struct PrescribedIntegrals {
  double X = 0, V_rear = 0, V_front = 0;
};
struct QuadratureStats {
  long pieces = 0;        ///< Simpson pieces accepted
  double smallest = 0;    ///< shortest accepted piece, s (0 before any)
};

/// Adaptive Simpson (with Richardson's correction) from the states at the interval's ends: a
/// piece is accepted when its two halves' Simpson sum differs from its own Simpson value by at
/// most 15 times its share of the tolerance (tol_X for X, m; tol_V for the volumes, m^3; shares
/// proportional to the piece's length). Throws swim::NumericalError (key axi.tolerance) when a
/// piece would be shorter than 1e-9 of the interval.
PrescribedIntegrals integrate(PrescribedSwimmer& s, const PrescribedState& a, const PrescribedState& b, double tol_X,
                              double tol_V, QuadratureStats& stats);

}  // namespace swim::axi
