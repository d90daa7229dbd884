// Stability at the extremes of the design space (1D tier, through the scene layer, the
// force-free default with the short-wave wall traction): R_f/R0 from 0.1 to 0.95,
// eps = R0/L from 0.02 to 3.2, C1 and viscosity
// over four decades, container radius from 1.2 R0 to 20 R0. Each case states its outcome: a
// valid result (finite outputs, the protocol completed), a numerical failure naming its cause
// and a remedy, or (unreachable by construction) a rejection as input before running.
// The table printed here is the one recorded in docs/stability-1d.md.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "common/errors.hpp"
#include "common/output.hpp"
#include "reduced1d/report.hpp"
#include "reduced1d/scene1d.hpp"
#include "reduced1d/solver.hpp"

using swim::scene::json;

namespace {

struct Outcome {
  std::string kind;  // "ok", "failed", "rejected"
  std::string text;
};

Outcome run_case(const std::vector<std::string>& sets) {
  json sc = json::object();
  swim::scene::apply_override(sc, "numerics1d.cells=40");
  for (const auto& s : sets) swim::scene::apply_override(sc, s);
  json resolved;
  swim::reduced1d::Params p;
  try {
    p = swim::reduced1d::read_scene(sc, resolved);
  } catch (const swim::InputError& e) {
    return {"rejected", e.what()};
  }
  // the samples stream through the run record, which refuses a non-finite value (the run then
  // fails naming the column); memory stays small however many samples a long swimmer makes
  swim::reduced1d::SolveOptions so;
  so.keep_samples = false;
  const auto r = swim::reduced1d::solve(p, so);
  if (!r.failure) {
    EXPECT_GT(r.record.series.count(), 0u);
  }
  EXPECT_EQ(r.record.radius.count(), r.record.series.count());
  if (r.record.series.count() > 0) {
    for (const auto& c : r.record.series.columns()) {
      EXPECT_TRUE(std::isfinite(r.record.series.min(c)) && std::isfinite(r.record.series.max(c))) << c;
    }
  }
  const auto m = swim::reduced1d::metrics(p, r);
  char b[160];
  if (r.failure) {
    EXPECT_FALSE(r.failure->cause().empty());
    EXPECT_FALSE(r.failure->remedy().empty());
    return {"failed", r.failure->what()};
  }
  if (p.wave == swim::reduced1d::WaveKind::ForceDriven) {
    EXPECT_EQ(m.cycles_completed, 1);
  }
  std::snprintf(b, sizeof b, "X = %.3g m, cycle %.3g s, min R/R0 = %.3f", m.displacement_m, m.t_end_s,
                m.min_radius_m / p.geometry.R0);
  return {"ok", b};
}

void report(const std::string& label, const Outcome& o) {
  std::printf("| %s | %s | %s |\n", label.c_str(), o.kind.c_str(), o.text.c_str());
}

}  // namespace

// Expected outcome of a case: completes one cycle ("ok"), stops with a numerical failure
// whose message contains `cause` ("failed"), or is rejected as input ("rejected").
struct Expect {
  std::string kind, cause;
};

void check(const std::string& label, const std::vector<std::string>& sets, const Expect& e) {
  const auto o = run_case(sets);
  report(label, o);
  EXPECT_EQ(o.kind, e.kind) << label << ": " << o.text;
  if (!e.cause.empty()) {
    EXPECT_NE(o.text.find(e.cause), std::string::npos) << label << ": " << o.text;
  }
}

TEST(Extremes, ForceDrivenWithActuationScaledToTheTarget) {
  // load_factor 1.5: the actuation is 1.5 x the static load that holds R_f. Below
  // R_f/R0 = 1/3 that load exceeds C1 R0, so the open ends have no positive rest radius: the
  // default then carries the end cells to the mouths (numerics1d.open_end = "continued"),
  // and what remains is whether the cells stay open until the segment's mean radius reaches
  // R_f. At R_f/R0 = 0.3 (q = 1.05 C1 R0) every length completes its cycle; at 0.1
  // (q = 1.35 C1 R0) the 0.4 and 6.25 um tubes close a cell first and stop naming the
  // collapse, while the 0.125 um tube completes its cycle (its smallest radius 0.004 R0).
  // Every other target completes its cycle on the static ends.
  for (const char* ratio : {"0.1", "0.3", "0.55", "0.8", "0.95"})
    for (const char* length : {"6.25 um", "0.4 um", "0.125 um"}) {
      const bool collapses = std::string(ratio) == "0.1" && std::string(length) != "0.125 um";
      check(std::string("force_driven, R_f/R0 = ") + ratio + ", L = " + length,
            {"protocol.load_factor=1.5", std::string("wave.contracted_ratio=") + ratio,
             std::string("swimmer.length=") + length, "container.period=25 um"},
            collapses ? Expect{"failed", "collapsed"} : Expect{"ok", ""});
    }
  // C1 and viscosity over four decades: Stokes flow rescales time, not the stroke.
  for (const char* c1 : {"4.06e4 Pa/m", "4.06e8 Pa/m"})
    for (const char* mu : {"1.2e-5 Pa*s", "1.2e-1 Pa*s"})
      check(std::string("force_driven, C1 = ") + c1 + ", mu = " + mu,
            {"protocol.load_factor=1.5", std::string("wall.C1=") + c1, std::string("fluid.viscosity=") + mu},
            {"ok", ""});
  // container radius from a tight 1.2 R0 to 20 R0 (period 40 L for the widest)
  for (const char* rc : {"0.15 um", "0.1875 um", "0.5 um", "2.5 um"})
    check(std::string("force_driven, Rc = ") + rc,
          {"protocol.load_factor=1.5", std::string("container.radius=") + rc, "container.period=16 um"}, {"ok", ""});
  // the unbounded outer flow at the same extremes of shape
  for (const char* ratio : {"0.55", "0.95"})
    for (const char* length : {"6.25 um", "0.125 um"})
      check(std::string("force_driven unbounded, R_f/R0 = ") + ratio + ", L = " + length,
            {"protocol.load_factor=1.5", "model1d.outer_flow=unbounded", std::string("wave.contracted_ratio=") + ratio,
             std::string("swimmer.length=") + length, "container.period=25 um"},
            {"ok", ""});
}

TEST(Extremes, ForceDrivenWithoutTheShortWaveTraction) {
  // The lubrication-only wall (model1d.short_wave_traction = false, CVODE) at the same
  // extremes: the same outcomes as the default, the collapse below R_f/R0 = 1/3 included.
  const std::string tr = "model1d.short_wave_traction=false";
  for (auto [ratio, length] : {std::pair{"0.1", "0.125 um"}, std::pair{"0.55", "6.25 um"}, std::pair{"0.55", "0.125 um"},
                               std::pair{"0.95", "0.125 um"}}) {
    const bool collapses = std::stod(ratio) < 1.0 / 3.0;
    check(std::string("force_driven lubrication wall, R_f/R0 = ") + ratio + ", L = " + length,
          {tr, "protocol.load_factor=1.5", std::string("wave.contracted_ratio=") + ratio,
           std::string("swimmer.length=") + length, "container.period=25 um"},
          collapses ? Expect{"failed", "collapsed"} : Expect{"ok", ""});
  }
  // (not the soft, viscous corner: its 2 840 s cycle is slow to sample; the default covers it)
  for (auto [c1, mu] : {std::pair{"4.06e4 Pa/m", "1.2e-5 Pa*s"}, std::pair{"4.06e8 Pa/m", "1.2e-5 Pa*s"},
                        std::pair{"4.06e8 Pa/m", "1.2e-1 Pa*s"}})
    check(std::string("force_driven lubrication wall, C1 = ") + c1 + ", mu = " + mu,
          {tr, "protocol.load_factor=1.5", std::string("wall.C1=") + c1, std::string("fluid.viscosity=") + mu},
          {"ok", ""});
  for (const char* rc : {"0.15 um", "2.5 um"})
    check(std::string("force_driven lubrication wall, Rc = ") + rc,
          {tr, "protocol.load_factor=1.5", std::string("container.radius=") + rc, "container.period=16 um"}, {"ok", ""});
  check("force_driven lubrication wall unbounded, R_f/R0 = 0.55, L = 0.125 um",
        {tr, "protocol.load_factor=1.5", "model1d.outer_flow=unbounded", "swimmer.length=0.125 um",
         "container.period=25 um"},
        {"ok", ""});
}

TEST(Extremes, ForceDrivenWithStaticEndsAskedForBeyondTheirLoad) {
  // numerics1d.open_end = "drainage" given: the static ends the default leaves below
  // R_f/R0 = 1/3 (above) have no positive rest radius there, and the run stops at t = 0 naming
  // the collapse and the continued ends as the remedy.
  for (const char* ratio : {"0.1", "0.3"})
    for (const char* length : {"6.25 um", "0.125 um"}) {
      const std::string r = ratio, l = length;
      check("force_driven drainage ends asked for, R_f/R0 = " + r + ", L = " + l,
            {"protocol.load_factor=1.5", "numerics1d.open_end=drainage", "wave.contracted_ratio=" + r,
             "swimmer.length=" + l, "container.period=25 um"},
            Expect{"failed", "open_end = \"continued\""});
    }
}

TEST(Extremes, ForceDrivenWithThePapersFixedForce) {
  // The paper's fixed F_ext = 0.1 pN: deep targets and stiff walls are unreachable (exit 2). On
  // a wall 100 times softer the load is 60 times C1 R0: the open ends have no static radius,
  // the default carries the end cells to the mouths, and the held segments complete the cycle
  // (their cells down to 0.41 R0); with the static ends asked for, the ends collapse (exit 3).
  check("force_driven 0.1 pN, R_f/R0 = 0.1", {"wave.contracted_ratio=0.1"}, {"rejected", "protocol.total_force"});
  check("force_driven 0.1 pN, R_f/R0 = 0.95", {"wave.contracted_ratio=0.95"}, {"ok", ""});
  check("force_driven 0.1 pN, C1 = 4.06e4 Pa/m", {"wall.C1=4.06e4 Pa/m"}, {"ok", ""});
  check("force_driven 0.1 pN, C1 = 4.06e4 Pa/m, drainage ends asked for",
        {"wall.C1=4.06e4 Pa/m", "numerics1d.open_end=drainage"}, {"failed", "collapsed"});
  check("force_driven 0.1 pN, C1 = 4.06e8 Pa/m", {"wall.C1=4.06e8 Pa/m"}, {"rejected", "protocol.total_force"});
}

TEST(Extremes, PrescribedWavesOverTheWholeRange) {
  // Prescribed kinematics always complete: every model of the tier over the range of shapes.
  for (const char* kind : {"step", "sine"})
    for (const char* ratio : {"0.1", "0.95"})
      for (const char* length : {"6.25 um", "0.125 um"})
        for (const char* model : {"confined", "unbounded", "paper"}) {
          std::vector<std::string> sets = {std::string("wave.kind=") + kind, "protocol=null",
                                           std::string("wave.contracted_ratio=") + ratio,
                                           std::string("swimmer.length=") + length, "container.period=25 um",
                                           std::string(kind) == "step" ? "wave.width=0.01 um" : "wave.wavelength=0.1 um"};
          if (std::string(model) == "paper") sets.push_back("model1d.model=paper");
          else sets.push_back(std::string("model1d.outer_flow=") + model);
          check(std::string(kind) + ", R_f/R0 = " + ratio + ", L = " + length + ", " + model, sets, {"ok", ""});
        }
}

TEST(Extremes, ForceDrivenOnTheCalibratedWallAndWithAxialBending) {
  // The nonlinear wall measured on the 3D membrane (docs/tube-law/calibration.json, R0 =
  // 0.125 um), its buckled branch: w(R) rises to 0.020 Pa by 0.96 R0, stays on a plateau of
  // 0.020 to 0.023 Pa down to 0.285 R0 and stiffens below. On the plateau the local law has no
  // unique radius: under the same load one cell collapses to the law's stiff part while its
  // neighbour stays near R0, so a segment's mean radius can stay above R_f although its
  // deepest cell is below it. Cases:
  //  - R_f = 0.1 R0, load factor 1.5: the open ends' static radius on the law is below the
  //    collapse radius, so the default carries the end cells to the mouths, and both lengths
  //    complete (the 0.4 um tube in a 27.5 s cycle, its cells down to 0.011 R0, slowed by the
  //    lumen's R^-4 resistance near closing);
  //  - R_f = 0.3 R0 (the load factor's 1.5 x 0.022 Pa is only 0.011 Pa above the plateau) and
  //    the tube as short as it is wide (L = 0.125 um: segments of 3 to 10 cells) at 0.55 and
  //    0.8 R0: the plateau's localisation keeps the active segment's mean above R_f, and the
  //    stall guard stops the run naming the actuation to raise (numerical failure);
  //  - everything else completes, beyond the buckling load (the paper's 0.32 Pa, 15 times the
  //    plateau) and with the viscosity over four decades (the cycle scales with mu);
  //  - 1 Pa exceeds the law's static load at the collapse radius (0.35 Pa): the default's end
  //    cells are continued to the mouths, and both targets complete their cycles; with the
  //    static ends asked for (numerics1d.open_end = "drainage") the open ends collapse at t = 0
  //    (numerical failure naming the load).
  // The wall's bending along the axis (D = 2.1e-24 J, bending length 27 nm) on the linear
  // wall: at R_f = 0.1 R0 the active 75 nm segment's middle closes (a beam on an elastic
  // foundation) before its mean reaches R_f, and the run stops at t = 0 naming the collapse
  // (without the check it grinds to the step budget); on the shortest tube (segments of 20 to
  // 40 nm, shorter than the bending length) the active segment cannot bend down to R_f and the
  // run stalls (numerical failure); the
  // longer tubes complete. On the buckled law the bending, 30 times stiffer than the plateau
  // at the segments' scale, holds the segment above R_f: stall.
  const std::string cal = std::string("wall.calibration=") + SWIM_SOURCE_DIR "/docs/tube-law/calibration.json";
  const std::string buckled = "wall.law=calibrated_buckled";
  const Expect ok{"ok", ""}, collapse{"failed", "collapsed"}, stall{"failed", "did not complete"};
  struct Case {
    const char* ratio;
    const char* length;
    Expect e;
  };
  for (const Case& c : {Case{"0.1", "0.4 um", ok}, Case{"0.1", "0.125 um", ok},
                        Case{"0.3", "0.4 um", stall}, Case{"0.3", "0.125 um", stall},
                        Case{"0.55", "6.25 um", ok}, Case{"0.55", "0.4 um", ok}, Case{"0.55", "0.125 um", stall},
                        Case{"0.8", "0.4 um", ok}, Case{"0.8", "0.125 um", stall},
                        Case{"0.95", "6.25 um", ok}, Case{"0.95", "0.4 um", ok}, Case{"0.95", "0.125 um", ok}})
    check(std::string("force_driven buckled law, R_f/R0 = ") + c.ratio + ", L = " + c.length,
          {cal, buckled, "protocol.load_factor=1.5", std::string("wave.contracted_ratio=") + c.ratio,
           std::string("swimmer.length=") + c.length, "container.period=25 um"},
          c.e);
  for (const char* ratio : {"0.35", "0.55"}) {
    check(std::string("force_driven buckled law, 0.32 Pa, R_f/R0 = ") + ratio,
          {cal, buckled, "protocol.pressure=0.32 Pa", std::string("wave.contracted_ratio=") + ratio}, ok);
    check(std::string("force_driven buckled law, 1 Pa, R_f/R0 = ") + ratio,
          {cal, buckled, "protocol.pressure=1 Pa", std::string("wave.contracted_ratio=") + ratio}, ok);
    check(std::string("force_driven buckled law, 1 Pa, drainage ends asked for, R_f/R0 = ") + ratio,
          {cal, buckled, "protocol.pressure=1 Pa", "numerics1d.open_end=drainage",
           std::string("wave.contracted_ratio=") + ratio},
          collapse);
  }
  for (const char* mu : {"1.2e-5 Pa*s", "1.2e-1 Pa*s"})
    check(std::string("force_driven buckled law, mu = ") + mu,
          {cal, buckled, "protocol.load_factor=1.5", std::string("fluid.viscosity=") + mu}, ok);
  const std::string bend = "model1d.axial_bending.source=scene", D = "model1d.axial_bending.rigidity=2.1184615504e-24 J";
  for (const Case& c : {Case{"0.1", "0.4 um", collapse}, Case{"0.55", "6.25 um", ok}, Case{"0.55", "0.4 um", ok},
                        Case{"0.55", "0.125 um", stall}, Case{"0.95", "6.25 um", ok}, Case{"0.95", "0.4 um", ok},
                        Case{"0.95", "0.125 um", stall}})
    check(std::string("force_driven axial bending, R_f/R0 = ") + c.ratio + ", L = " + c.length,
          {bend, D, "protocol.load_factor=1.5", std::string("wave.contracted_ratio=") + c.ratio,
           std::string("swimmer.length=") + c.length, "container.period=25 um"},
          c.e);
  check("force_driven axial bending on the buckled law, R_f/R0 = 0.55",
        {cal, buckled, bend, D, "protocol.load_factor=1.5", "wave.contracted_ratio=0.55"}, stall);
}
