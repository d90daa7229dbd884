#include "axi/prescribed_axi.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>
#include <string>

#include "common/errors.hpp"
#include "common/si_format.hpp"
#include "reduced1d/discretisation.hpp"

namespace swim::axi {

namespace {

constexpr int kMaxDepth = 30;  // pieces down to 2^-30 ~ 1e-9 of the output interval

struct Vals {
  double u = 0, qr = 0, qf = 0;
};
Vals vals(const PrescribedState& s) { return {s.velocity, s.flux_rear, s.flux_front}; }
Vals simpson(double h, const Vals& a, const Vals& m, const Vals& b) {
  return {h / 6.0 * (a.u + 4.0 * m.u + b.u), h / 6.0 * (a.qr + 4.0 * m.qr + b.qr),
          h / 6.0 * (a.qf + 4.0 * m.qf + b.qf)};
}

struct Simpson {
  PrescribedSwimmer& s;
  double tol_x_rate, tol_v_rate;  // tolerance per second of piece
  QuadratureStats& st;

  Vals run(double a, double b, const Vals& fa, const Vals& fm, const Vals& fb, const Vals& whole, int depth) {
    const double m = 0.5 * (a + b);
    const Vals fl = vals(s.evaluate(0.5 * (a + m))), fr = vals(s.evaluate(0.5 * (m + b)));
    const Vals left = simpson(m - a, fa, fl, fm), right = simpson(b - m, fm, fr, fb);
    const double du = left.u + right.u - whole.u, dr = left.qr + right.qr - whole.qr,
                 df = left.qf + right.qf - whole.qf;
    const double tx = tol_x_rate * (b - a), tv = tol_v_rate * (b - a);
    if (std::abs(du) <= 15.0 * tx && std::abs(dr) <= 15.0 * tv && std::abs(df) <= 15.0 * tv) {
      ++st.pieces;
      st.smallest = st.smallest > 0 ? std::min(st.smallest, b - a) : b - a;
      return {left.u + right.u + du / 15.0, left.qr + right.qr + dr / 15.0, left.qf + right.qf + df / 15.0};
    }
    if (depth >= kMaxDepth)
      throw NumericalError("the time quadrature of the prescribed wave did not converge on a piece of " + significant(b - a, 4) +
                               " s (velocity change " + significant(du / (b - a), 4) + " m/s over it)",
                           "raise axi.tolerance, or smooth the wave (wave.width)", a);
    const Vals l = run(a, m, fa, fl, fm, left, depth + 1), r = run(m, b, fm, fr, fb, right, depth + 1);
    return {l.u + r.u, l.qr + r.qr, l.qf + r.qf};
  }
};

}  // namespace

RingKinematics wave_kinematics(const scene::WaveSpec& w, double R0, double L) {
  if (!w.prescribed()) throw std::invalid_argument("wave_kinematics: a prescribed wave (step or sine) is needed");
  reduced1d::disc::PrescribedShape sh;
  sh.kind = w.kind == "step" ? reduced1d::WaveKind::Step : reduced1d::WaveKind::Sine;
  sh.R0 = R0;
  sh.L = L;
  sh.s = w.speed;
  if (w.kind == "step") {
    sh.Rmin = w.R_f;
    sh.w = w.width;
  } else {
    sh.a = R0 - w.R_f;
    sh.lambda = w.wavelength;
  }
  return [sh](double t, const std::vector<double>& z, Eigen::VectorXd& R, Eigen::VectorXd& Rt) {
    const int n = int(z.size());
    R.resize(n);
    Rt.resize(n);
    for (int k = 0; k < n; ++k) sh.eval(z[k], t, R[k], Rt[k]);
  };
}

double lumen_volume(const std::vector<double>& z, const Eigen::VectorXd& R) {
  double v = 0.0;
  for (std::size_t k = 0; k + 1 < z.size(); ++k) {
    const double a = R[Eigen::Index(k)], b = R[Eigen::Index(k + 1)];
    v += std::numbers::pi / 3.0 * (z[k + 1] - z[k]) * (a * a + a * b + b * b);
  }
  return v;
}

PrescribedSwimmer::PrescribedSwimmer(const FittedMeshParams& mp, double mu, std::vector<double> z,
                                     RingKinematics kinematics, double x_start)
    : z_(std::move(z)), kin_(std::move(kinematics)), x_start_(x_start) {
  stokes_ = std::make_unique<FittedStokes>(mp, mu, int(z_.size()));
}

Eigen::Matrix3Xd PrescribedSwimmer::rings(const Eigen::VectorXd& R) const {
  const int n = int(z_.size());
  Eigen::Matrix3Xd X = Eigen::Matrix3Xd::Zero(3, n);
  for (int k = 0; k < n; ++k) X(0, k) = x_start_ + z_[k], X(1, k) = R[k];
  return X;
}

PrescribedState PrescribedSwimmer::evaluate(double t) {
  PrescribedState s;
  s.t = t;
  kin_(t, z_, s.R, s.Rt);
  const int n = int(z_.size());
  if (s.R.size() != n || s.Rt.size() != n || !s.R.allFinite() || !s.Rt.allFinite() || !(s.R.minCoeff() > 0.0))
    throw NumericalError("the prescribed wave gives a non-finite or non-positive ring radius",
                         "check wave.contracted_ratio and the wave's parameters", t);
  Eigen::Matrix3Xd V = Eigen::Matrix3Xd::Zero(3, n);
  V.row(1) = s.Rt.transpose();
  const FittedStokes::PrescribedWall w = stokes_->prescribed_wall_velocity(rings(s.R), V);
  ++evaluations_;
  s.velocity = w.velocity;
  s.drag = w.drag;
  s.towed_lumen_flux = w.towed_lumen_flux;
  s.flux_rear = stokes_->end_disc_flux(0, w.velocity);
  s.flux_front = stokes_->end_disc_flux(1, w.velocity);
  s.volume = lumen_volume(z_, s.R);
  if (!std::isfinite(s.velocity) || !std::isfinite(s.flux_rear) || !std::isfinite(s.flux_front))
    throw NumericalError("non-finite swimmer velocity or end-disc flux", "change axi.grid", t);
  return s;
}

PrescribedIntegrals integrate(PrescribedSwimmer& s, const PrescribedState& a, const PrescribedState& b, double tol_X,
                              double tol_V, QuadratureStats& stats) {
  PrescribedIntegrals r;
  const double h = b.t - a.t;
  if (!(h > 0.0)) return r;
  const Vals fa = vals(a), fb = vals(b), fm = vals(s.evaluate(0.5 * (a.t + b.t)));
  Simpson q{s, tol_X / h, tol_V / h, stats};
  const Vals v = q.run(a.t, b.t, fa, fm, fb, simpson(h, fa, fm, fb), 0);
  r.X = v.u;
  r.V_rear = v.qr;
  r.V_front = v.qf;
  return r;
}

}  // namespace swim::axi
