// The 1D tier's end effects (reduced1d/outer_flow.hpp EndEffects and EndJunction,
// docs/outer-flow-1d.md §2b, §2c) against steady flows of the axisymmetric reference: a straight
// rigid tube towed through the periodic container (its drag F_b and the lumen flux relative to
// it) and the velocity a wall band gives. Steady figures like these are what the end coefficients
// are calibrated on; no dynamic (wave) run enters, and the one dynamic run here is a check.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "axi/prescribed_axi.hpp"
#include "axi/run_axi.hpp"
#include "axi_test_support.hpp"
#include "axi/scene_axi.hpp"
#include "axi/wall_axi.hpp"
#include "common/scene.hpp"
#include "common/scene_shared.hpp"
#include "reduced1d/outer_flow.hpp"
#include "reduced1d/params.hpp"
#include "reduced1d/scene1d.hpp"
#include "reduced1d/solver.hpp"

namespace {

using swim::scene::json;
namespace outer = swim::reduced1d::outer;

constexpr double kR0 = 0.125e-6;

struct Tow {
  double drag = 0, lumen_flux = 0, Rc = 0, P = 0, L = 0, mu = 0;
};

/// One steady solve on the axi tier: a straight tube of radius R0 and length L in the cylinder
/// Rc (period about 5 L), the fitted method's mesh of the prescribed-wave runs at `cells` across,
/// the wall's radial velocity from `kin` at t = 0.
swim::axi::PrescribedState axi_steady(double L, double Rc, int cells, swim::axi::RingKinematics kin, double& P,
                                      double& mu, double* dissipation = nullptr) {
  const double h = Rc / cells;
  P = std::round(5 * L / h) * h;
  auto um = [](double v) {
    char b[40];
    std::snprintf(b, sizeof b, "%.12g um", v * 1e6);
    return std::string(b);
  };
  json sc = {{"name", "steady"},
             {"swimmer", {{"radius", um(kR0)}, {"length", um(L)}}},
             {"container", {{"kind", "cylinder"}, {"radius", um(Rc)}, {"period", um(P)}}},
             {"wave", {{"kind", "sine"}, {"contracted_ratio", 0.55}, {"speed", "10 um/s"}, {"wavelength", um(L)}}},
             {"full3d", {{"membrane", {{"axisymmetric", true}}}}},
             {"axi", {{"method", "fitted"}, {"grid", {{"cells_across", cells}}}}}};
  json resolved;
  const swim::axi::ParamsAxi p = swim::axi::read_scene_axi(sc, resolved);
  mu = p.base.fluid.mu;
  swim::axi::AxiWall wall(swim::axi::AxiWallParams{p.base.R0, p.base.L, p.ks, p.D, p.wall_nodes, p.ring_s0});
  swim::axi::PrescribedSwimmer sw(swim::axi::fitted_mesh_params(p), mu, wall.reference_positions(), std::move(kin),
                                  p.x_start());
  const swim::axi::PrescribedState st = sw.evaluate(0.0);
  if (dissipation) *dissipation = sw.stokes().dissipation();
  return st;
}

/// The axi tier's towed straight tube (a rigid wall: U = 0, the drag and lumen flux of flow (b)).
Tow axi_tow(double L_over_R0, double Rc_over_R0, int cells) {
  Tow t;
  t.L = L_over_R0 * kR0, t.Rc = Rc_over_R0 * kR0;
  swim::axi::RingKinematics rigid = [](double, const std::vector<double>& z, Eigen::VectorXd& R,
                                       Eigen::VectorXd& Rt) {
    R = Eigen::VectorXd::Constant(Eigen::Index(z.size()), kR0);
    Rt = Eigen::VectorXd::Zero(Eigen::Index(z.size()));
  };
  const swim::axi::PrescribedState s = axi_steady(t.L, t.Rc, cells, rigid, t.P, t.mu);
  EXPECT_EQ(s.velocity, 0.0);
  t.drag = s.drag;
  t.lumen_flux = s.towed_lumen_flux;
  return t;
}

outer::TowedTube one_d_tow(const Tow& t, const outer::EndEffects& e) {
  return outer::confined_tow(kR0, t.L, 0.0, 0.0, t.Rc, t.P, t.mu, e);
}

}  // namespace

// Calibration and check on the towed tube. The drag of a straight tube towed through the
// container is mostly the annulus's; the annulus coefficient that makes the 1D drag (with the
// lumen's coefficient 0.2) equal to the axi drag is an end length per end, in gaps. Measured at
// 16 cells across, L/R0 = 6.4 and 12.8: 0.368 / 0.377 (Rc/R0 = 1.5), 0.213 / 0.212 (2), 0.313 /
// 0.317 (3), 0.321 / 0.325 (4): the same at both lengths, an end effect. kOpenEnds takes 0.25.
// The lumen's coefficient: the one that, with the drag's annulus coefficient, reproduces the
// towed lumen flux is 0.3-0.4 at Rc/R0 = 1.3-1.5 and 0.05 at 2 (both fitted together); 0.2 keeps
// the flux within 4 % there. In wider containers (Rc/R0 >= 2.5) the lubrication split of the
// towed flux between lumen and annulus misses by 20-55 % and the miss does not fall as 1/L: not
// an end effect, and not fitted.
// Asserted: the fitted annulus coefficient the same within 0.02 at both lengths and within
// [0.15, 0.45]; with kOpenEnds the 1D drag within 3 % of the axi drag (the plain junction: 2-18 %
// low) and closer than without; the towed lumen flux within 5 % at Rc/R0 <= 2.
TEST(EndEffects, TowedTubeDragWithTheOpenEnds) {
  for (double rc : {1.5, 2.0, 3.0, 4.0}) {
    double fitted[2];
    for (int i = 0; i < 2; ++i) {
      const double l = i == 0 ? 6.4 : 12.8;
      const Tow a = axi_tow(l, rc, 16);
      // drag(c_a) is linear in c_a at a fixed lumen coefficient: two evaluations
      const double d0 = one_d_tow(a, {outer::kOpenEnds.lumen, 0.0}).drag;
      const double d1 = one_d_tow(a, {outer::kOpenEnds.lumen, 1.0}).drag;
      fitted[i] = (a.drag - d0) / (d1 - d0);
      const outer::TowedTube plain = one_d_tow(a, {}), ends = one_d_tow(a, outer::kOpenEnds);
      std::printf("Rc/R0 %.1f L/R0 %.1f: axi drag %.5e N s/m, 1D %.5e (%+.2f %%) -> with the ends %.5e (%+.2f %%); "
                  "annulus coefficient from the drag %.3f; lumen flux axi %.4e, 1D %.4e -> %.4e m^3/s per m/s\n",
                  rc, l, a.drag, plain.drag, 100 * (plain.drag / a.drag - 1), ends.drag,
                  100 * (ends.drag / a.drag - 1), fitted[i], a.lumen_flux, plain.lumen_flux, ends.lumen_flux);
      EXPECT_LT(std::abs(ends.drag / a.drag - 1), 0.03) << "Rc/R0 " << rc << " L/R0 " << l;
      EXPECT_LT(std::abs(ends.drag / a.drag - 1), std::abs(plain.drag / a.drag - 1));
      EXPECT_GT(fitted[i], 0.15);
      EXPECT_LT(fitted[i], 0.45);
      if (rc <= 2.0) {
        EXPECT_LT(std::abs(ends.lumen_flux / a.lumen_flux - 1), 0.05) << "Rc/R0 " << rc;
      }
    }
    EXPECT_NEAR(fitted[0], fitted[1], 0.02) << "Rc/R0 " << rc;
  }
}

// The dynamic check the coefficients were not fitted to: a step wave (front L/8 wide) over one
// transit of a short tube (L = 0.4 um = 3.2 R0 in Rc = 2 R0, period 2 um, 8 cells across, about
// 2 s) on the axi tier and on the 1D tier with and without the open ends. Measured: axi 65.05 nm,
// 1D 40.39 nm -> 43.66 nm with the ends: axi/1D 1.61 -> 1.49. The ends move 1D towards the
// reference but close only a small part of the gap (docs/outer-flow-1d.md "Where lubrication
// holds"). Asserted: the ratio improves, and stays above 1.3 (the rest is not an end effect
// of the rigid-extension kind); the calibrated junction (§2c), fitted to steady flows only, gives
// 63.9 nm (axi/1D 1.02) and is asserted within 5 %.
TEST(EndEffects, PrescribedStepWaveMovesTowardsTheReference) {
  json sc = {{"name", "ends_step"},
             {"swimmer", {{"radius", "0.125 um"}, {"length", "0.4 um"}}},
             {"container", {{"kind", "cylinder"}, {"radius", "0.25 um"}, {"period", "2 um"}}},
             {"wave", {{"kind", "step"}, {"contracted_ratio", 0.55}, {"speed", "10 um/s"}, {"width", "0.05 um"}}},
             {"time", {{"output_interval", "0.005 s"}}},
             {"full3d", {{"membrane", {{"axisymmetric", true}}}}},
             {"axi", {{"method", "fitted"}, {"grid", {{"cells_across", 8}}}}}};
  json resolved;
  const swim::axi::ParamsAxi p = swim::axi::read_scene_axi(sc, resolved);
  swim::axi::testing::TempDir dir("swim-axi-end-effects");
  swim::axi::RunControlAxi ctl;
  ctl.progress = 0;
  const swim::axi::RunOutcomeAxi out = swim::axi::run_axi(p, resolved, dir.path.string(), ctl);
  ASSERT_FALSE(out.failed) << out.message;
  const double x_axi = out.summary["displacement_m"].get<double>();
  double x1[3];
  const char* ends[3] = {"none", "open_ends", "junction"};
  for (int i = 0; i < 3; ++i) {
    json s1 = sc, r1;
    s1["model1d"] = {{"end_effects", ends[i]}};
    const swim::reduced1d::Result r = swim::reduced1d::solve(swim::reduced1d::read_scene(s1, r1));
    ASSERT_FALSE(r.failure.has_value());
    x1[i] = r.series.back().X;
  }
  std::printf("step wave, L = 3.2 R0, Rc = 2 R0: axi %.4e m; 1D %.4e m -> %.4e m with the ends, %.4e m with the "
              "junction; axi/1D %.3f -> %.3f, %.3f\n",
              x_axi, x1[0], x1[1], x1[2], x_axi / x1[0], x_axi / x1[1], x_axi / x1[2]);
  EXPECT_LT(std::abs(x_axi / x1[1] - 1), std::abs(x_axi / x1[0] - 1));
  EXPECT_GT(x_axi / x1[1], 1.3);
  // the junction, fitted to steady flows only, brings this transit within 5 % (measured 1.02)
  EXPECT_NEAR(x_axi / x1[2], 1.0, 0.05);
}

// What the open ends' resistance leaves out, as a steady flow: a straight tube (L = 6.4 R0 in
// Rc = 2 R0) whose wall moves radially only in a band one R0 wide (dR/dt = -v cos^2), centred a
// distance d from the rear end; the force-free velocity U(d) on both tiers at that instant (one
// solve each). On a uniform tube the plain lubrication model gives U = 0 wherever the band is
// (the displaced flux leaves by lumen and annulus, and no pressure difference acts on the tube);
// in Stokes flow a band near an end propels the tube away from that end. Measured (16 cells
// across): U = 11.4, 8.10, 6.22, 4.40, 2.57 nm/s at d = 0.5, 1, 1.5, 2, 2.5 R0 (0 at the
// midplane, 3.2 R0, by symmetry); 1D plain: 1e-20 m/s (round-off); 1D with the open ends 1.70,
// 1.38, 1.07, 0.755, 0.440 nm/s: the right sign and shape (axi/1D 5.8 within 1 % for d >= 1 R0,
// 6.7 at 0.5 R0) and 6 times too small. This end thrust of a moving wall is what the steady end
// resistance cannot supply (docs/outer-flow-1d.md §6). The calibrated junction (§2c), fitted to
// such band responses on other tubes and on this one, the bands centred on the rims included:
// axi/1D 1.12 and 1.05 for the bands centred on the rim and 0.25 R0 inside it, 1.11 at 0.5 R0,
// 1.26-1.27 from 1 R0 on (the fit trades the interior of a uniform tube, 1.12 without the rim
// bands, for its rims, 1.55 and 1.29 without them). Asserted: the plain 1D U below 1e-10 of the
// axi U; the axi U positive and falling from 0.5 R0 to 2.5 R0 by more than a factor 3; with the
// ends, the same sign and axi/1D above 3 from 0.5 R0 on; with the junction, within 15 % of the axi
// U on the rim's bands (d <= 0.5 R0) and within 30 % further in.
TEST(EndEffects, WallBandNearAnEnd) {
  const double R0 = kR0, L = 6.4 * R0, Rc = 2 * R0, w = R0, v = 1e-6;
  auto band = [=](double z, double d) {
    const double x = (z - d) / w;
    return std::abs(x) < 0.5 ? std::pow(std::cos(M_PI * x), 2) : 0.0;
  };
  double U_near = 0, U_far = 0;
  for (double d_over_R0 : {0.0, 0.25, 0.5, 1.0, 1.5, 2.0, 2.5}) {
    const double d = d_over_R0 * R0;
    swim::axi::RingKinematics kin = [&](double, const std::vector<double>& z, Eigen::VectorXd& R, Eigen::VectorXd& Rt) {
      R = Eigen::VectorXd::Constant(Eigen::Index(z.size()), R0);
      Rt.resize(Eigen::Index(z.size()));
      for (std::size_t k = 0; k < z.size(); ++k) Rt[Eigen::Index(k)] = -v * band(z[k], d);
    };
    double P = 0, mu = 0;
    const double U_axi = axi_steady(L, Rc, 16, kin, P, mu).velocity;
    // 1D, N = 400 cells, the solver's point set
    const int N = 400;
    const double h = L / N;
    std::vector<double> dd(N + 1, h), R(N + 2, R0), s(N + 1, 0.0);
    dd[0] = dd[N] = 0.5 * h;
    double cum = 0;
    for (int i = 0; i < N; ++i) {
      s[i] = cum;
      cum += h * 2 * M_PI * R0 * (-v * band((i + 0.5) * h, d));
    }
    s[N] = cum;
    double U1[3];
    for (int e = 0; e < 3; ++e) {
      outer::ConfinedSystem sys(N + 2, dd, mu, 0.0, 0.0, Rc, P, L);
      if (e == 1) sys.ends = outer::kOpenEnds;
      if (e == 2) sys.junction = &outer::kCalibratedJunction;
      ASSERT_TRUE(sys.geometry(R.data()));
      sys.kinematic(s.data());
      U1[e] = sys.U;
    }
    std::printf("band at d = %.2f R0: U axi %.4e m/s, 1D %.4e, with the ends %.4e (axi/1D %.3f), with the junction "
                "%.4e (axi/1D %.3f)\n",
                d_over_R0, U_axi, U1[0], U1[1], U_axi / U1[1], U1[2], U_axi / U1[2]);
    EXPECT_GT(U_axi, 0.0);
    EXPECT_LT(std::abs(U1[0]), 1e-10 * U_axi) << "a band on a uniform tube: lubrication gives no thrust";
    if (d_over_R0 >= 0.5) {
      EXPECT_GT(U_axi / U1[1], 3.0);
    }
    EXPECT_NEAR(U_axi / U1[2], 1.0, d_over_R0 <= 0.5 ? 0.15 : 0.30) << "the junction at d = " << d_over_R0 << " R0";
    if (d_over_R0 == 0.5) U_near = U_axi;
    U_far = U_axi;
  }
  EXPECT_GT(U_near, 3.0 * U_far);
}

// The wall's resistance to a uniform expansion of a finite tube. Every ring of a straight tube of
// radius R moves outwards at w; the axi tier's viscous dissipation Phi gives the resistance
// Z = Phi / w^2 (N s/m). The 1D tier's plain junction: by symmetry U = W = 0 and half of each
// region's volume change passes each end, so the lumen and the annulus dissipate
// (8 pi / 3) mu R^2 L^3 (1 / R^4 + 1 / G) together (Poiseuille flux growing linearly from the
// tube's middle; G = Rc^4 - R^4 - (Rc^2 - R^2)^2 / ln(Rc / R)); the calibrated junction adds
// x^T M x at each end with x = pi R w L (1, -1, 0). The junction's fit holds these flows for
// L/R0 >= 3.2 (the L/R0 = 1.6 tube is outside it: its ends interact). Measured at 16 cells across
// (24 cells: within 0.35 %), Rc = 2 R0, Z_axi / Z_1D:
//   L/R0, R/R0:   1.6, 0.55   3.2, 0.55   6.4, 0.55   3.2, 1.0
//   plain:        3.29        1.88        1.38        3.02
//   junction:     1.14        0.97        0.94        1.12
// The plain junction's missing resistance is the flow around the rims at the open ends, which the
// junction carries: this is why the default 1D wall recovers 2.6 times too fast on the 1.6 R0 long
// tube (docs/outer-flow-1d.md §6b).
TEST(EndEffects, UniformExpansionDissipatesAsTheJunctionPredicts) {
  struct Case {
    double l, r, plain_min, junction_tol;
  };
  const double Rc = 2 * kR0, w = 1e-6;
  for (const Case& c : {Case{3.2, 0.55, 1.6, 0.08}, Case{6.4, 0.55, 1.3, 0.08}, Case{1.6, 0.55, 2.5, 0.20},
                        Case{3.2, 1.0, 2.5, 0.15}}) {
    const double L = c.l * kR0, R = c.r * kR0;
    swim::axi::RingKinematics kin = [&](double, const std::vector<double>& z, Eigen::VectorXd& Rv, Eigen::VectorXd& Rt) {
      Rv = Eigen::VectorXd::Constant(Eigen::Index(z.size()), R);
      Rt = Eigen::VectorXd::Constant(Eigen::Index(z.size()), w);
    };
    double P = 0, mu = 0, phi = 0;
    const swim::axi::PrescribedState st = axi_steady(L, Rc, 16, kin, P, mu, &phi);
    EXPECT_LT(std::abs(st.velocity), 1e-12 * w) << "a fore-aft symmetric motion does not swim";
    const double z_axi = phi / (w * w);
    const double d = Rc * Rc - R * R, G = Rc * Rc * Rc * Rc - R * R * R * R - d * d / std::log(Rc / R);
    const double z_plain = (8 * M_PI / 3) * mu * R * R * L * L * L * (1 / (R * R * R * R) + 1 / G);
    double M[3][3], rim = 0;
    outer::end_junction(outer::kCalibratedJunction, R, Rc, mu, M, rim);
    const double x[3] = {M_PI * R * w * L, -M_PI * R * w * L, 0.0};
    double xMx = 0;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) xMx += x[i] * M[i][j] * x[j];
    const double z_junction = z_plain + 2 * xMx / (w * w);
    std::printf("uniform expansion, L/R0 %.1f, R/R0 %.2f: Z axi %.4e N s/m, plain junction %.4e (axi/1D %.3f), "
                "calibrated junction %.4e (axi/1D %.3f)\n",
                c.l, c.r, z_axi, z_plain, z_axi / z_plain, z_junction, z_axi / z_junction);
    EXPECT_GT(z_axi / z_plain, c.plain_min) << "L/R0 " << c.l << ", R/R0 " << c.r;
    EXPECT_NEAR(z_axi / z_junction, 1.0, c.junction_tol) << "L/R0 " << c.l << ", R/R0 " << c.r;
  }
}

namespace {

/// The wall's inward volume rate per unit 2 pi R0 over the band [L - b, L] (the integral of the
/// radial velocity, positive inwards) from two radius snapshots (R0 and R1 at t1) at the rings z.
double band_rate(const std::vector<double>& z, const std::vector<double>& r0, const std::vector<double>& r1,
                 double t1, double L, double b) {
  const int n = 2000;
  double s = 0.0;
  for (int k = 0; k <= n; ++k) {
    const double zz = L - b + b * k / n;
    std::size_t i = 1;
    while (i + 1 < z.size() && z[i] < zz) ++i;
    const double w = std::clamp((zz - z[i - 1]) / (z[i] - z[i - 1]), 0.0, 1.0);
    const double v = ((1 - w) * (r1[i - 1] - r0[i - 1]) + w * (r1[i] - r0[i])) / t1;
    s += (k == 0 || k == n ? 0.5 : 1.0) * (-v) * b / n;
  }
  return s;
}

}  // namespace

// The short-wave traction's end condition (model1d.short_wave_traction_end, beta), calibrated on
// the steady response of a relaxed tube to a load on its end band: the paper's L = 0.8 um tube
// (L/R0 = 6.4, Rc = 2 R0; a case without a fitted reference, so no judged run enters), its
// protocol's first contraction under 0.5 Pa on a front segment 72.7 nm long (first_segment_ratio
// 1) and 25.8 nm long (1/3), the wall's inward volume rate over the loaded band in the first
// record (0.3 ms: the tube still relaxed, its stiffness below 1 % of the load). 1D: the calibrated
// end junction, sharp hydraulic radii. Measured (axi 24 cells across; 16 cells within 1 %),
// 1D/axi for the long and the short band: beta = 0 (mirror ends) 1.54 / 1.80, 0.5 1.14 / 1.08,
// 0.7 1.09 / 0.98, 1 (a wall at rest beyond the ends) 1.04 / 0.89; the velocity profile over
// three band widths from the end within 10 % rms at beta = 0.7 on both (0.58 and 0.83 at 0); the
// plain model (no junction) 1.42-2.7 times too mobile for any beta. Asserted: at beta = 0.7 the
// band's rate within 12 % of the axi tier's on both bands; the mirror's above 1.4; the rate falls
// as beta grows.
TEST(EndEffects, TractionEndConditionFromAnEndBandLoad) {
  const double L = 0.8e-6;
  for (const double ratio : {1.0, 1.0 / 3.0}) {
    const double band = L / (10.0 + ratio) * ratio;
    json sc = {{"name", "end_band_load"},
               {"swimmer", {{"radius", "0.125 um"}, {"length", "0.8 um"}}},
               {"container", {{"kind", "cylinder"}, {"radius", "0.25 um"}, {"period", "2 um"}}},
               {"wall", {{"spring_constant", "5.5e-8 N/m"}}},
               {"wave", {{"kind", "force_driven"}, {"contracted_ratio", 0.55}}},
               {"protocol", {{"segments", 11}, {"first_segment_ratio", ratio}, {"pressure", "0.5 Pa"}}},
               {"time", {{"duration", "0.3 ms"}, {"output_interval", "0.3 ms"}}},
               {"numerics1d", {{"cells", 200}}},
               {"full3d", {{"membrane", {{"axisymmetric", true}, {"bending_rigidity", "2.1184615504e-24 J"}}}}},
               {"axi", {{"method", "fitted"}, {"grid", {{"cells_across", 16}}}}}};
    json resolved;
    const swim::axi::ParamsAxi p = swim::axi::read_scene_axi(sc, resolved);
    swim::axi::testing::TempDir dir("swim-axi-end-band");
    swim::axi::RunControlAxi ctl;
    ctl.progress = 0;
    const swim::axi::RunOutcomeAxi out = swim::axi::run_axi(p, resolved, dir.path.string(), ctl);
    ASSERT_FALSE(out.failed) << out.message;
    // radius.csv: t_s, z_m, radius_m; the first two records
    std::ifstream in(dir.path / "radius.csv");
    std::string line;
    std::getline(in, line);
    std::vector<double> z, r0, r1;
    double t1 = -1;
    while (std::getline(in, line)) {
      double t, zz, r;
      if (std::sscanf(line.c_str(), "%lf,%lf,%lf", &t, &zz, &r) != 3) continue;
      if (t == 0.0) {
        z.push_back(zz);
        r0.push_back(r);
      } else if (t1 < 0 || t == t1) {
        t1 = t;
        r1.push_back(r);
      }
    }
    ASSERT_EQ(r1.size(), z.size());
    ASSERT_GT(t1, 0.0);
    const double q_axi = band_rate(z, r0, r1, t1, L, band);
    ASSERT_GT(q_axi, 0.0);

    std::vector<double> ratios;
    for (const double beta : {0.0, 0.7, 1.0}) {
      json s1 = sc, r1d;
      s1["model1d"] = {{"end_effects", "junction"},
                       {"short_wave_traction_end", beta},
                       {"axial_bending", {{"source", "scene"}, {"rigidity", "2.1184615504e-24 J"}}}};
      s1["time"]["output_interval"] = swim::scene::format_quantity(t1, "s");
      s1["time"]["duration"] = swim::scene::format_quantity(t1, "s");
      const swim::reduced1d::Result r = swim::reduced1d::solve(swim::reduced1d::read_scene(s1, r1d));
      ASSERT_FALSE(r.failure.has_value());
      const std::size_t n = r.z.size();
      ASSERT_GE(r.radius_times.size(), 2u);
      std::vector<double> a(r.radius.begin(), r.radius.begin() + long(n)),
          b(r.radius.begin() + long(n), r.radius.begin() + long(2 * n));
      const double q1 = band_rate(r.z, a, b, r.radius_times[1] - r.radius_times[0], L, band);
      ratios.push_back(q1 / q_axi);
    }
    std::printf("end band %.1f nm: axi %.4g m^2/s; 1D/axi at beta = 0, 0.7, 1: %.3f, %.3f, %.3f\n", band * 1e9,
                q_axi, ratios[0], ratios[1], ratios[2]);
    EXPECT_NEAR(ratios[1], 1.0, 0.12) << "band " << band;
    EXPECT_GT(ratios[0], 1.4) << "band " << band;
    EXPECT_GT(ratios[0], ratios[1]);
    EXPECT_GT(ratios[1], ratios[2]);
  }
}
