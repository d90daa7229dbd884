// The 1D tier's end effects (reduced1d/outer_flow.hpp EndEffects, docs/outer-flow-1d.md §2b)
// against steady flows of the axisymmetric reference: a straight rigid tube towed through the
// periodic container, its drag F_b and the lumen flux relative to it. These two steady figures
// are what the end coefficients are calibrated on; no dynamic (wave) run enters.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <cstdio>
#include <string>

#include "axi/prescribed_axi.hpp"
#include "axi/run_axi.hpp"
#include "axi_test_support.hpp"
#include "axi/scene_axi.hpp"
#include "axi/wall_axi.hpp"
#include "common/scene.hpp"
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

/// The axi tier's towed straight tube (radius R0, length L in Rc, period about 5 L), the fitted
/// method's mesh of the prescribed-wave runs at `cells` across.
Tow axi_tow(double L_over_R0, double Rc_over_R0, int cells) {
  const double L = L_over_R0 * kR0, Rc = Rc_over_R0 * kR0, h = Rc / cells;
  const double P = std::round(5 * L / h) * h;
  auto um = [](double v) {
    char b[40];
    std::snprintf(b, sizeof b, "%.12g um", v * 1e6);
    return std::string(b);
  };
  json sc = {{"name", "tow"},
             {"swimmer", {{"radius", um(kR0)}, {"length", um(L)}}},
             {"container", {{"kind", "cylinder"}, {"radius", um(Rc)}, {"period", um(P)}}},
             {"wave", {{"kind", "sine"}, {"contracted_ratio", 0.55}, {"speed", "10 um/s"}, {"wavelength", um(L)}}},
             {"full3d", {{"membrane", {{"axisymmetric", true}}}}},
             {"axi", {{"method", "fitted"}, {"grid", {{"cells_across", cells}}}}}};
  json resolved;
  const swim::axi::ParamsAxi p = swim::axi::read_scene_axi(sc, resolved);
  swim::axi::AxiWall wall(swim::axi::AxiWallParams{p.base.R0, p.base.L, p.ks, p.D, p.wall_nodes, p.ring_s0});
  swim::axi::RingKinematics rigid = [](double, const std::vector<double>& z, Eigen::VectorXd& R,
                                       Eigen::VectorXd& Rt) {
    R = Eigen::VectorXd::Constant(Eigen::Index(z.size()), kR0);
    Rt = Eigen::VectorXd::Zero(Eigen::Index(z.size()));
  };
  swim::axi::PrescribedSwimmer sw(swim::axi::fitted_mesh_params(p), p.base.fluid.mu, wall.reference_positions(),
                                  rigid, p.x_start());
  const swim::axi::PrescribedState s = sw.evaluate(0.0);
  EXPECT_EQ(s.velocity, 0.0);
  return {s.drag, s.towed_lumen_flux, Rc, P, L, p.base.fluid.mu};
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
// holds"). Asserted: the ratio improves, and stays above 1.3 (the rest is not an end effect).
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
  double x1[2];
  for (int i = 0; i < 2; ++i) {
    json s1 = sc, r1;
    s1["model1d"] = {{"end_effects", i == 0 ? "none" : "open_ends"}};
    const swim::reduced1d::Result r = swim::reduced1d::solve(swim::reduced1d::read_scene(s1, r1));
    ASSERT_FALSE(r.failure.has_value());
    x1[i] = r.series.back().X;
  }
  std::printf("step wave, L = 3.2 R0, Rc = 2 R0: axi %.4e m; 1D %.4e m -> %.4e m with the ends; axi/1D %.3f -> %.3f\n",
              x_axi, x1[0], x1[1], x_axi / x1[0], x_axi / x1[1]);
  EXPECT_LT(std::abs(x_axi / x1[1] - 1), std::abs(x_axi / x1[0] - 1));
  EXPECT_GT(x_axi / x1[1], 1.3);
}
