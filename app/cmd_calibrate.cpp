// swim calibrate SCENE: the 1D tier's wall stiffness from the 3D membrane under uniform loads, and
// the hydraulic offsets of the immersed wall (profile fits of a held tube; a_out also from the
// drag of the towed tube).
#include <chrono>
#include <cstdio>
#include <string>

#include "app/app.hpp"
#include "app/scene_checks.hpp"
#include "common/errors.hpp"
#include "common/output.hpp"
#include "common/progress.hpp"
#include "common/run_folder.hpp"
#include "common/scene.hpp"
#include "common/si_format.hpp"
#include "full3d/scene3d.hpp"
#include "validation/calibration.hpp"
#include "validation/hydraulic.hpp"

namespace swim::app {

int calibrate(const std::string& scene_path, const std::vector<std::string>& sets, const std::string& out_opt,
              bool wet, bool overwrite, int threads, bool tube_law, int progress_mode) {
  scene::json sc = scene::load_file(scene_path);
  for (const auto& s : sets) scene::apply_override(sc, s);
  if (threads > 0) scene::apply_override(sc, "full3d.threads=" + std::to_string(threads));
  scene::json resolved;
  const full3d::Params3d p = full3d::read_scene3d(sc, resolved);
  check_other_tier(sc, "3d");  // the whole scene, as a 3D run checks it
  const std::string out = out_opt.empty() ? "out/" + p.name + "-calibration" : out_opt;
  // The folder belongs to this calibration from the start: a folder in use, or holding another
  // run's results (without --overwrite), is refused before minutes of 3D runs.
  scene::json identity = {{"scene", resolved}, {"wet", wet}};
  if (tube_law) identity["tube_law"] = true;  // (absent without it: earlier folders stay this calibration's)
  output::RunFolder folder(out, {"calibration", identity, overwrite, false, "--out", "calibration.json"});
  const auto t0 = std::chrono::steady_clock::now();
  const auto loads = validation::default_loads(p);
  // progress in steps: the loads, then the axial stiffness, the hydraulic radii and the towed
  // tube (one each)
  const std::size_t steps = loads.size() + 3;
  Progress progress("calibrate " + p.name, double(steps), progress_mode);
  const validation::StaticCalibration c =
      validation::calibrate_static(p, loads, [&](std::size_t done) {
        progress.step(done, steps, "load " + std::to_string(done) + "/" + std::to_string(loads.size()));
      });
  // the wall's stiffness along the axis, C(k) (a long round tube of the same wall)
  // (a failure leaves the section with its reason and no axial_bending_rigidity_J: C1 and the
  // offsets are still measured)
  const validation::AxialStiffnessOutcome axial_outcome = validation::try_measure_axial_stiffness(p);
  progress.step(loads.size() + 1, steps, "axial stiffness");
  validation::HydraulicRadii hr;
  validation::TowedCalibration tow;
  try {
    hr = validation::measure_hydraulic_radii(p);
    progress.step(loads.size() + 2, steps, "hydraulic radii");
    tow = validation::calibrate_towed(p, hr);
    progress.step(steps, steps, "towed tube");
    progress.done();
  } catch (const NumericalError& e) {
    progress.done();
    // the wall stiffness is measured: keep it, say the offsets are missing and why (exit 3)
    output::make_dir(out);
    scene::json j = validation::to_json(c, p, resolved);
    j.update(axial_outcome.entries());
    j["status"] = "failed: hydraulic radii: " + std::string(e.what());
    j["wall_time_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    output::write_json(out + "/calibration.json", j);
    plot("plot_calibration.py", {out});
    std::fprintf(stderr,
                 "swim: %s: C1 = %s +- %s measured and written; the hydraulic radii failed: %s\n  partial results "
                 "in %s/calibration.json (no hydraulic offsets: a 1D scene reading them from this file is refused)\n",
                 p.name.c_str(), si(c.fit.c1, "Pa/m", 5).c_str(), si(c.fit.c1_stderr, "Pa/m").c_str(), e.what(),
                 out.c_str());
    return 3;
  }
  validation::TubeLawCalibration law;
  if (tube_law) law = validation::calibrate_tube_law(p, c.fit.c1, c.fit.c1_stderr);
  // wet confirmation at the largest load of the fit
  validation::WetConfirmation w;
  const validation::LoadPoint* confirm = nullptr;
  for (const auto& lp : c.loads)
    if (lp.in_linear_range && lp.stable()) confirm = &lp;
  if (wet && confirm) w = validation::confirm_wet(p, confirm->pressure_Pa, confirm->displacement_m);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  output::make_dir(out);
  scene::json j = validation::to_json(c, p, resolved);
  j.update(axial_outcome.entries());
  j["status"] = "ok";
  j["wall_time_s"] = wall;
  scene::json hj = validation::to_json(hr);
  hj["hydraulic_wall_time_s"] = hj["wall_time_s"];
  hj.erase("wall_time_s");
  j.update(hj);
  j.update(tow.json);
  if (tube_law) j["tube_law"] = validation::to_json(law, p.R0);
  if (wet && confirm)
    j["wet_confirmation"] = {{"pressure_Pa", w.pressure_Pa},
                             {"displacement_m", w.displacement_m},
                             {"static_displacement_m", w.static_displacement_m},
                             {"relative_difference", w.relative_difference},
                             {"steady", w.steady},
                             {"steps", w.steps},
                             {"dt_s", w.dt_s},
                             {"simulated_time_s", w.simulated_time_s},
                             {"wall_time_s", w.wall_time_s},
                             {"axisymmetric_wall", w.axisymmetric_wall},
                             {"method", "fluid-coupled immersed-boundary run of the same uniform load, stepped until "
                                        "the middle radius is steady; the wall moves in ring motions only (the "
                                        "symmetric branch of the static path)"}};
  output::write_json(out + "/calibration.json", j);
  plot("plot_calibration.py", {out});
  int stable = 0;
  double stable_up_to = 0;
  for (const auto& lp : c.loads)
    if (lp.stable()) {
      ++stable;
      stable_up_to = lp.pressure_Pa;
    }
  std::printf("%s: C1 = %s +- %s (through the origin, %d of %zu loads, R^2 = %.6f); spring-network value %s "
              "(%+.2f %%)\n  response linear within 1 %% %s %s; stable to ring buckling up to %s (%d loads)\n"
              "  %d membrane nodes; wall time %s -> %s/calibration.json\n",
              p.name.c_str(), si(c.fit.c1, "Pa/m", 5).c_str(), si(c.fit.c1_stderr, "Pa/m").c_str(), c.fit.points,
              c.loads.size(), c.fit.r2, si(c.spring_network_c1, "Pa/m", 5).c_str(),
              100.0 * (c.fit.c1 / c.spring_network_c1 - 1.0),
              c.fit.linear_over_all_loads ? "over every load, up to" : "up to",
              si(c.fit.linear_over_all_loads ? c.loads.back().pressure_Pa : c.fit.linear_up_to_Pa, "Pa").c_str(),
              si(stable_up_to, "Pa").c_str(), stable, c.nodes, si(wall, "s").c_str(), out.c_str());
  if (!axial_outcome.measured) {
    std::printf("  axial stiffness C(k): failed (%s)\n", axial_outcome.failure.c_str());
  } else {
    const validation::AxialStiffness& axial = *axial_outcome.measured;
    std::string table;
    for (std::size_t k = 0; k < axial.wavelengths_m.size(); ++k)
      table += (k ? ", " : "") + si(axial.wavelengths_m[k], "m", 3) + " " +
               si(axial.C_Pa_per_m[k], "Pa/m", 4) + " (" + significant(axial.C_Pa_per_m[k] / axial.c1, 4) + " C1)";
    std::printf("  axial stiffness C(k) = C1 + D K^4 on a %s tube (%d rings): C1 = %s; %s\n"
                "  D from C(k) = %s +- %s against the wall's D = %s (%+.2f %%); bending length %s; %s\n",
                si(axial.tube_length_m, "m", 3).c_str(), axial.n_rings, si(axial.c1, "Pa/m", 5).c_str(),
                table.c_str(), (significant(axial.d_fit, 4) + " J").c_str(),
                (significant(axial.d_fit_stderr, 2) + " J").c_str(), (significant(axial.d_wall, 4) + " J").c_str(),
                axial.d_wall > 0 ? 100.0 * (axial.d_fit / axial.d_wall - 1.0) : 0.0,
                si(axial.bending_length_m, "m", 3).c_str(), si(axial.wall_time_s, "s").c_str());
  }
  std::printf("  hydraulic offsets: a_in = %s +- %s, a_out = %s +- %s (h = %s; held-tube solve %d CG iterations, %s)\n",
              si(hr.a_in_m, "m").c_str(), si(hr.a_in_uncertainty_m, "m").c_str(), si(hr.a_out_m, "m").c_str(),
              si(hr.a_out_uncertainty_m, "m").c_str(), si(p.h, "m").c_str(), hr.cg_iterations,
              si(hr.wall_time_s, "s").c_str());
  const validation::TowedTube& tt = tow.tube;
  if (!tow.measured)
    std::printf("  towed tube: failed (%s)\n", tow.error.c_str());
  else if (tow.nominal.found)
    std::printf("  towed tube: drag coefficient %s +- %s (%d CG iterations, %s) -> a_out = %s +- %s from the drag "
                "(%+.2f h from the profile's; %s with the container's effective radius %s)\n",
                si(tt.drag_coefficient_N_s_per_m, "N s/m", 4).c_str(),
                si(tt.drag_coefficient_uncertainty_N_s_per_m, "N s/m").c_str(), tt.cg_iterations,
                si(tt.wall_time_s, "s").c_str(), si(tow.nominal.a_out_m, "m").c_str(),
                si(tow.nominal.uncertainty_m, "m").c_str(), (tow.nominal.a_out_m - hr.a_out_m) / p.h,
                tow.effective.found ? si(tow.effective.a_out_m, "m").c_str() : "no root",
                si(hr.container_radius_effective_m, "m").c_str());
  else
    std::printf("  towed tube: drag coefficient %s +- %s (%d CG iterations, %s); no a_out from the drag: %s\n",
                si(tt.drag_coefficient_N_s_per_m, "N s/m", 4).c_str(),
                si(tt.drag_coefficient_uncertainty_N_s_per_m, "N s/m").c_str(), tt.cg_iterations,
                si(tt.wall_time_s, "s").c_str(), tow.nominal.note.c_str());
  if (tube_law) {
    std::printf("  tube law, round branch: %zu loads to R_mid = %.3f R0 (%s), slope at R0 %s (C1 %+.3f %%), closed form "
                "of the ring of springs within %.2f %%\n",
                law.round.points.size(), law.round.knots_R.front() / p.R0, law.round.stopped_because.c_str(),
                si(law.round.slope_at_R0, "Pa/m", 5).c_str(), 100.0 * (law.round.slope_at_R0 / c.fit.c1 - 1.0),
                100.0 * law.round_max_rel_dev_closed_form);
    if (law.buckled_computed)
      std::printf("  tube law, buckled branch: buckling load %s (ring mode n = %d); %zu loads to R_mid = %.3f R0 (%s); "
                  "leave-one-out residual max %s\n",
                  si(law.buckling_load_Pa, "Pa").c_str(), law.buckling_mode, law.buckled.points.size(),
                  law.buckled.knots_R.front() / p.R0, law.buckled.stopped_because.c_str(),
                  si(law.buckled.loo_max_abs_Pa, "Pa").c_str());
    else
      std::printf("  tube law, buckled branch: absent (%s)\n", law.buckled_absent_because.c_str());
  }
  if (wet && confirm)
    std::printf("  wet confirmation at %s (axisymmetric wall): displacement %s against %s static (%+.2f %%), %s after %d "
                "steps of %s\n",
                si(w.pressure_Pa, "Pa").c_str(), si(w.displacement_m, "m").c_str(),
                si(w.static_displacement_m, "m").c_str(), 100.0 * w.relative_difference,
                w.steady ? "steady" : "NOT steady", w.steps, si(w.dt_s, "s").c_str());
  return 0;
}

}  // namespace swim::app
