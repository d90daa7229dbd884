// The wall's stiffness along the axis, C(k) (validation::measure_axial_stiffness): the 3D
// membrane of the paper's aspect-ratio scene at its default grid under axial load profiles
// p0 cos(k x), against the thin-shell law C(k) = C1 + D k^4.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "common/output.hpp"
#include "common/scene.hpp"
#include "full3d/scene3d.hpp"
#include "validation/calibration.hpp"

using namespace swim;

namespace {

full3d::Params3d aspect_scene(const std::vector<std::string>& sets = {}) {
  scene::json sc = scene::load_file(SWIM_SOURCE_DIR "/data/scenes/paper_aspect_L0.2.json");
  for (const auto& s : sets) scene::apply_override(sc, s);
  scene::json resolved;
  return full3d::read_scene3d(sc, resolved);
}

void print(const char* what, const validation::AxialStiffness& a) {
  std::printf("%s: tube %.4g m, %d rings x %d, dx %.4g m, window %.4g m, margin %.4g m, %.2f s\n", what,
              a.tube_length_m, a.n_rings, a.n_theta, a.ring_spacing_m, a.window_m, a.end_margin_m, a.wall_time_s);
  std::printf("  C1 = %.6g Pa/m, D_wall = %.6g J, l_b = %.4g m\n", a.c1, a.d_wall, a.bending_length_m);
  for (std::size_t j = 0; j < a.C_Pa_per_m.size(); ++j) {
    const double k = a.lattice_wavenumbers_per_m[j], shell = a.c1 + a.d_wall * std::pow(k, 4);
    std::printf("  lambda %.4g m: C = %.6g Pa/m = %.4f C1, shell law %.6g (%+.3f %%), D_k %.5g J, quad %.2g, "
                "resid %.2g, it %d\n",
                a.wavelengths_m[j], a.C_Pa_per_m[j], a.C_Pa_per_m[j] / a.c1, shell,
                100.0 * (a.C_Pa_per_m[j] / shell - 1.0), (a.C_Pa_per_m[j] - a.c1) / std::pow(k, 4),
                a.quadrature_ratio[j], a.profile_residual_ratio[j], a.iterations[j]);
  }
  std::printf("  D_fit = %.6g +- %.2g J (%+.3f %% of D_wall, r2 %.8f); on k^4 %.6g +- %.2g J (%+.3f %%)\n"
              "  with k^2: A = %.4g +- %.2g N/m (%.3f D/R0^2), D = %.6g +- %.2g J (%+.3f %%)\n",
              a.d_fit, a.d_fit_stderr, 100.0 * (a.d_fit / a.d_wall - 1.0), a.d_fit_r2, a.d_fit_continuum_k,
              a.d_fit_continuum_k_stderr, 100.0 * (a.d_fit_continuum_k / a.d_wall - 1.0), a.k2_coefficient,
              a.k2_coefficient_stderr, a.k2_coefficient * 0.125e-6 * 0.125e-6 / a.d_wall, a.d_fit_k2,
              a.d_fit_k2_stderr, 100.0 * (a.d_fit_k2 / a.d_wall - 1.0));
}

}  // namespace

// The thin-shell law on the paper's round wall (D = 2.1184615504e-24 J, R0 = 0.125 um, default
// grid: 169 nodes per ring, rings 4.02 nm apart; bending length 26.9 nm; wavelengths 40, 81, 161,
// 322 nm on a 1.18 um tube). Measured C(k) against C1 + D K^4 (K the ring lattice's wavenumber):
// -0.27, -1.02, -2.09, -1.05 %. The shortfall is the shell's k^2 term, the bending coupling of the
// axial and hoop curvatures (A k^2 with A = -0.90 D / R0^2: -2.1 % of C at 161 nm, where D K^4 is
// half of C); the fit with it, C - C1 = A k^2 + D K^4, gives D within 0.06 % of the wall's, and the
// one-term fit C - C1 = D K^4 (the 1D tier's law) -1.13 %. Tolerances: 3 % on each C (the largest
// deviation, 2.1 %, plus margin), 2 % on D_axial, 0.5 % on the D of the fit with the k^2 term, and
// A between -1.2 and -0.6 D / R0^2. Without the lattice wavenumber (D on k^4) D would be 4.8 % low.
TEST(AxialStiffness, TheRoundWallFollowsTheShellLaw) {
  const full3d::Params3d p = aspect_scene({"full3d.membrane.bending_rigidity=\"2.1184615504e-24 J\""});
  const validation::AxialStiffness a = validation::measure_axial_stiffness(p);
  print("round wall", a);
  EXPECT_DOUBLE_EQ(a.d_wall, 2.1184615504e-24);
  ASSERT_EQ(a.C_Pa_per_m.size(), 4u);
  // the wavelengths span the bending length, each at least 8 rings long, the window away from the ends
  const double lb = a.bending_length_m;
  EXPECT_NEAR(lb, 26.9e-9, 0.3e-9);
  EXPECT_LT(a.wavelengths_m.front(), 2.0 * lb);
  EXPECT_GT(a.wavelengths_m.back(), 10.0 * lb);
  EXPECT_GE(a.wavelengths_m.front(), 8.0 * a.ring_spacing_m * (1 - 1e-9));
  EXPECT_GE(0.5 * (a.tube_length_m - a.window_m), 10.0 * lb * 0.99);
  // C1 on the long tube is the spring network's (within 0.5 %; D / R0^4 adds 0.2 %)
  EXPECT_NEAR(a.c1 / p.c1_estimate(), 1.0, 0.005);
  for (std::size_t j = 0; j < a.C_Pa_per_m.size(); ++j) {
    const double shell = a.c1 + a.d_wall * std::pow(a.lattice_wavenumbers_per_m[j], 4);
    EXPECT_NEAR(a.C_Pa_per_m[j] / shell, 1.0, 0.03) << "lambda " << a.wavelengths_m[j];
    EXPECT_LT(a.quadrature_ratio[j], 1e-6);        // the response is the load's cosine
    EXPECT_LT(a.profile_residual_ratio[j], 0.02);  // (0.8 % at the shortest wavelength)
  }
  // stiffening from 1.06 C1 at the longest wavelength to ~290 C1 at the shortest
  EXPECT_GT(a.C_Pa_per_m.front() / a.c1, 200.0);
  EXPECT_LT(a.C_Pa_per_m.back() / a.c1, 1.1);
  EXPECT_NEAR(a.d_fit / a.d_wall, 1.0, 0.02);
  EXPECT_NEAR(a.d_fit_k2 / a.d_wall, 1.0, 0.005);
  const double a_unit = a.d_wall / (p.R0 * p.R0);
  EXPECT_GT(a.k2_coefficient / a_unit, -1.2);
  EXPECT_LT(a.k2_coefficient / a_unit, -0.6);
}

// D_axial follows the wall's rigidity: on the scene's own wall (the paper's k_b = 1e-15 N mapped
// at the reference edge, D = 1.009e-24 J) the fit gives D within 2 % (measured -0.58 %), and with
// D four times larger four times that (measured ratio 3.97; tolerance 3 %). A measurement blind to
// the rigidity (k_b kept, or the bending left out) fails both.
TEST(AxialStiffness, TheFittedRigidityScalesWithTheWalls) {
  const full3d::Params3d p = aspect_scene();
  full3d::Params3d q = p;
  q.bending_rigidity = 4.0 * p.bending_rigidity;
  q.membrane.kb = 4.0 * p.membrane.kb;
  const validation::AxialStiffness a = validation::measure_axial_stiffness(p), b = validation::measure_axial_stiffness(q);
  print("scene wall", a);
  print("scene wall, 4 D", b);
  EXPECT_NEAR(a.d_fit / a.d_wall, 1.0, 0.02);
  EXPECT_NEAR(b.d_fit / a.d_fit, 4.0, 0.12);
  EXPECT_NEAR(b.d_fit / b.d_wall, 1.0, 0.02);
  EXPECT_NEAR(b.c1 / a.c1, 1.0, 0.01);  // the hoop stiffness does not change
}

// calibration.json carries the measurement: add_axial_stiffness writes the "axial_stiffness"
// section and the top-level "axial_bending_rigidity_J" (= the fit's D), and they read back from
// the written file with their values.
TEST(AxialStiffness, TheCalibrationFileCarriesTheSection) {
  validation::AxialStiffness a;
  a.wavelengths_m = {40e-9, 80e-9, 160e-9, 320e-9};
  for (double l : a.wavelengths_m) {
    const double k = 2 * M_PI / l;
    a.wavenumbers_per_m.push_back(k);
    a.lattice_wavenumbers_per_m.push_back(0.99 * k);
    a.C_Pa_per_m.push_back(4e6 + 2e-24 * std::pow(k, 4));
    a.load_amplitudes_Pa.push_back(1e-3);
    a.response_amplitudes_m.push_back(1e-3 / a.C_Pa_per_m.back());
    a.quadrature_ratio.push_back(0);
    a.profile_residual_ratio.push_back(1e-3);
    a.iterations.push_back(3);
  }
  a.c1 = 4e6;
  a.d_fit = 2.01e-24;
  a.d_fit_stderr = 1e-26;
  a.d_wall = 2e-24;
  a.d_fit_k2 = 2.002e-24;
  a.k2_coefficient = -1e-10;
  a.tube_length_m = 1.2e-6;
  a.bending_length_m = 26.6e-9;
  scene::json j = {{"C1_Pa_per_m", 4e6}, {"status", "ok"}};
  validation::add_axial_stiffness(j, a);
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "swim_axial_stiffness_json";
  std::filesystem::create_directories(dir);
  const std::string file = (dir / "calibration.json").string();
  output::write_json(file, j);
  const scene::json r = scene::load_file(file);
  std::filesystem::remove_all(dir);
  ASSERT_TRUE(r.contains("axial_bending_rigidity_J"));
  EXPECT_EQ(r["axial_bending_rigidity_J"].get<double>(), 2.01e-24);
  ASSERT_TRUE(r.contains("axial_stiffness"));
  const scene::json& s = r["axial_stiffness"];
  for (const char* k : {"wavelengths_m", "wavenumbers_per_m", "lattice_wavenumbers_per_m", "C_Pa_per_m", "C_over_C1",
                        "shell_law_C_Pa_per_m", "C1_Pa_per_m", "bending_rigidity_fit_J", "bending_rigidity_fit_stderr_J",
                        "bending_rigidity_wall_J", "bending_length_m", "fit_with_k2", "fit_on_k4", "tube_length_m",
                        "method"})
    EXPECT_TRUE(s.contains(k)) << k;
  EXPECT_EQ(s["wavelengths_m"].get<std::vector<double>>(), a.wavelengths_m);
  EXPECT_EQ(s["C_Pa_per_m"].get<std::vector<double>>(), a.C_Pa_per_m);
  EXPECT_EQ(s["bending_rigidity_fit_J"].get<double>(), a.d_fit);
  EXPECT_EQ(s["bending_rigidity_wall_J"].get<double>(), a.d_wall);
  EXPECT_EQ(s["C1_Pa_per_m"].get<double>(), a.c1);
  EXPECT_EQ(s["fit_with_k2"]["bending_rigidity_J"].get<double>(), a.d_fit_k2);
  EXPECT_EQ(s["fit_with_k2"]["k2_coefficient_N_per_m"].get<double>(), a.k2_coefficient);
  EXPECT_NEAR(s["C_over_C1"][3].get<double>(), a.C_Pa_per_m[3] / a.c1, 1e-15);
}

// The paper's literal eq. (8), a fixed k_b on every mesh, is another wall on another mesh
// (D = (sqrt 3 / 8) k_b a): at 24 cells across D = 1.342e-24 J, at 32 cells 1.009e-24 J. The
// axial measurement sees the same: D_axial follows each mesh's D within 2 % (measured -0.77 %
// and -0.58 %), and the two differ by the ratio of the meshes' D (1.33) within 3 % (0.2 %).
TEST(AxialStiffness, AFixedKbWallHasAnotherAxialRigidityOnAnotherMesh) {
  const full3d::Params3d coarse = aspect_scene({"full3d.membrane.bending_model=\"fixed_kb\"",
                                                "full3d.grid.cells_across=24"});
  const full3d::Params3d fine = aspect_scene({"full3d.membrane.bending_model=\"fixed_kb\""});
  const validation::AxialStiffness a = validation::measure_axial_stiffness(coarse),
                                   b = validation::measure_axial_stiffness(fine);
  print("fixed k_b, 24 cells", a);
  print("fixed k_b, 32 cells", b);
  EXPECT_NEAR(a.d_fit / a.d_wall, 1.0, 0.02);
  EXPECT_NEAR(b.d_fit / b.d_wall, 1.0, 0.02);
  EXPECT_GT(a.d_wall / b.d_wall, 1.25);
  EXPECT_NEAR((a.d_fit / b.d_fit) / (a.d_wall / b.d_wall), 1.0, 0.03);
}
