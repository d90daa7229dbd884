// The 3D run driver (full3d/run3d.hpp) on the small scene data/scenes/tiny_3d.json
// (32x12x12 duct, h = 40 nm): forward swimming, the stability guard with partial
// results, checkpoint/resume to round-off, dry-swimmer inertia, the protocol in dry mode.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/errors.hpp"
#include "common/output.hpp"
#include "common/run_folder.hpp"
#include "common/scene.hpp"
#include "full3d/fft.hpp"
#include "full3d/run3d.hpp"
#include "run3d_scenes.hpp"

using namespace swim;
using namespace swim::full3d;
namespace fs = std::filesystem;

namespace {

using run3d_test::read_csv;
using run3d_test::Scene;

Scene tiny(const std::vector<std::string>& sets) { return run3d_test::shipped_scene("tiny_3d.json", sets); }

std::string fresh_dir(const std::string& name) { return run3d_test::fresh_dir("out_run3d", name); }

// The strong, three-segment protocol that a 40 nm grid resolves (docs/full3d.md, "Run driver").
const std::vector<std::string> kStrong = {"protocol.total_force=null", "protocol.load_factor=3",
                                          "protocol.segments=3", "protocol.first_segment_ratio=1",
                                          "full3d.membrane.spacing_factor=0.5"};

}  // namespace

TEST(Run3d, ForceDrivenRunMovesSwimmerForward) {
  auto sets = kStrong;
  sets.insert(sets.end(), {"full3d.dt=\"1 ms\"", "time.duration=\"0.3 s\"", "time.output_interval=\"10 ms\""});
  const Scene s = tiny(sets);
  const std::string dir = fresh_dir("forward");
  RunControl ctl;
  ctl.progress = 0;
  ctl.quiet_vtk = true;
  const RunOutcome r = run3d(s.p, s.resolved, dir, ctl);
  ASSERT_FALSE(r.failed) << r.message;
  const double disp = r.summary["displacement_m"].get<double>();
  std::printf("displacement after 0.3 s: %.4g m = %.3g L; segments reached at", disp, disp / s.p.L);
  for (double t : r.summary["segment_reached_s"]) std::printf(" %.3g", t);
  std::printf(" s\n");
  EXPECT_GT(disp, 0.01 * s.p.L);  // measured 0.040 L (contraction complete at 0.28 s)
  EXPECT_EQ(r.summary["segment_reached_s"].size(), 3u);
}

TEST(Run3d, TimeStepBeyondStabilityFailsWithPartialResults) {
  const Scene s = tiny({"full3d.dt=\"50 ms\"", "time.duration=\"2 s\""});
  const std::string dir = fresh_dir("unstable");
  RunControl ctl;
  ctl.progress = 0;
  const RunOutcome r = run3d(s.p, s.resolved, dir, ctl);
  ASSERT_TRUE(r.failed);
  std::printf("%s\n", r.message.c_str());
  EXPECT_NE(r.message.find("full3d.dt"), std::string::npos);
  EXPECT_EQ(r.summary["status"].get<std::string>().rfind("failed: ", 0), 0u);
  for (const char* f : {"summary.json", "series.csv", "radius.csv", "checkpoint.bin", "membrane.pvd"})
    EXPECT_TRUE(fs::exists(dir + "/" + f)) << f;
  std::ifstream in(dir + "/series.csv");
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_EQ(ss.str().find("nan"), std::string::npos);
  EXPECT_EQ(ss.str().find("inf"), std::string::npos);
  for (const auto& row : read_csv(dir + "/series.csv"))
    for (double v : row) EXPECT_TRUE(std::isfinite(v));
}

TEST(Run3d, ResumeEqualsUninterruptedRun) {
  const std::vector<std::string> sets = {"full3d.dt=\"1 ms\"", "time.duration=\"30 ms\"",
                                         "time.output_interval=\"1 ms\"", "full3d.checkpoint_interval=\"10 ms\""};
  const Scene s = tiny(sets);
  RunControl ctl;
  ctl.progress = 0;
  ctl.quiet_vtk = true;
  const std::string a = fresh_dir("resume_a"), b = fresh_dir("resume_b");
  const RunOutcome ra = run3d(s.p, s.resolved, a, ctl);
  ASSERT_FALSE(ra.failed) << ra.message;
  RunControl stop = ctl;
  stop.stop_after_steps = 17;  // "killed" at step 17; the last checkpoint is at step 10
  const RunOutcome rb = run3d(s.p, s.resolved, b, stop);
  ASSERT_TRUE(rb.interrupted);
  // the killed run: its rows streamed to the part files, and its summary (written at the
  // checkpoint of step 10) says running and lists the part files as they were then
  {
    std::ifstream in(b + "/summary.json");
    const scene::json sb = scene::json::parse(in);
    EXPECT_EQ(sb["status"].get<std::string>().rfind("running", 0), 0u) << sb["status"];
    EXPECT_FALSE(std::filesystem::exists(b + "/series.csv"));
    bool listed = false;
    for (const auto& f : sb["files"])
      if (f["name"] == "series.csv.part") {
        listed = true;
        EXPECT_LT(f["bytes"].get<std::uintmax_t>(), std::filesystem::file_size(b + "/series.csv.part"));
      }
    EXPECT_TRUE(listed);
    // the summary is the checkpoint's last file: it lists checkpoint.bin as it is on disk
    bool checkpoint = false;
    for (const auto& f : sb["files"])
      if (f["name"] == "checkpoint.bin") {
        checkpoint = true;
        EXPECT_EQ(f["bytes"].get<std::uintmax_t>(), std::filesystem::file_size(b + "/checkpoint.bin"));
        EXPECT_EQ(f["fnv1a64"], output::file_checksum(b + "/checkpoint.bin"));
      }
    EXPECT_TRUE(checkpoint);
  }
  RunControl res = ctl;
  res.resume = true;
  const RunOutcome rc = run3d(s.p, s.resolved, b, res);
  ASSERT_FALSE(rc.failed) << rc.message;
  // the resumed run's folder verifies as a whole: every listed file with its size and checksum
  EXPECT_EQ(output::verify_folder(b, {"series.csv", "radius.csv", "scene.resolved.json", "checkpoint.bin"}), "");
  EXPECT_EQ(rc.steps, ra.steps);
  // the rows after the checkpoint are recomputed to the bit: the files are byte-identical
  for (const char* f : {"/series.csv", "/radius.csv"}) {
    std::ifstream fa(a + f, std::ios::binary), fc(b + f, std::ios::binary);
    const std::string A((std::istreambuf_iterator<char>(fa)), {}), C((std::istreambuf_iterator<char>(fc)), {});
    EXPECT_EQ(A, C) << f;
  }
  EXPECT_FALSE(std::filesystem::exists(b + "/series.csv.part"));
  const auto A = read_csv(a + "/series.csv"), C = read_csv(b + "/series.csv");
  ASSERT_EQ(A.size(), C.size());
  double worst = 0;
  for (size_t j = 0; j < A[0].size(); ++j) {
    double scale = 0;
    for (const auto& r : A) scale = std::max(scale, std::abs(r[j]));
    if (scale == 0) continue;
    for (size_t i = 0; i < A.size(); ++i) worst = std::max(worst, std::abs(A[i][j] - C[i][j]) / scale);
  }
  // series.csv carries 10 significant digits; compare the summary at full precision too
  EXPECT_LE(worst, 1e-9);
  const double da = ra.summary["displacement_m"].get<double>(), dc = rc.summary["displacement_m"].get<double>();
  std::printf("displacement uninterrupted %.17g, resumed %.17g, relative difference %.3g\n", da, dc,
              std::abs(da - dc) / std::abs(da));
  EXPECT_LE(std::abs(da - dc), 1e-12 * std::abs(da));
  EXPECT_EQ(ra.summary["pumped_volume_m3"].get<double>(), rc.summary["pumped_volume_m3"].get<double>());
}

// A resumed run's folder tells the whole run: its final summary.json lists the VTK frames
// written before the interruption too; a frame deleted before the resume is found before the
// folder is touched (exit 2 naming the frame).
TEST(Run3d, AResumedRunListsEveryFrameAndRefusesAMissingOne) {
  const std::vector<std::string> sets = {"full3d.dt=\"1 ms\"", "time.duration=\"12 ms\"",
                                         "time.output_interval=\"1 ms\"", "full3d.checkpoint_interval=\"4 ms\"",
                                         "full3d.output.vtk=true", "full3d.output.vtk_interval=\"2 ms\""};
  const Scene s = tiny(sets);
  RunControl stop;
  stop.progress = 0;
  stop.stop_after_steps = 9;  // "killed" at step 9; the last checkpoint is at step 8
  const std::string b = fresh_dir("resume_frames"), c = fresh_dir("resume_frames_deleted");
  ASSERT_TRUE(run3d(s.p, s.resolved, b, stop).interrupted);
  ASSERT_TRUE(fs::exists(b + "/vtk/membrane_000002.vtp"));
  fs::remove_all(c);
  fs::copy(b, c, fs::copy_options::recursive);
  fs::remove(c + "/vtk/membrane_000002.vtp");
  try {
    check_resumable(s.p, s.resolved, c);
    ADD_FAILURE() << "a missing frame was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "--resume");
    EXPECT_NE(std::string(e.what()).find("vtk/membrane_000002.vtp"), std::string::npos) << e.what();
  }
  RunControl res;
  res.progress = 0;
  res.resume = true;
  const RunOutcome r = run3d(s.p, s.resolved, b, res);
  ASSERT_FALSE(r.failed) << r.message;
  std::size_t frames = 0, listed = 0;
  for (const auto& e : fs::directory_iterator(b + "/vtk")) frames += e.path().extension() == ".vtp";
  std::ifstream in(b + "/summary.json");
  const scene::json sum = scene::json::parse(in);
  for (const auto& f : sum["files"]) listed += f["name"].get<std::string>().rfind("vtk/membrane_", 0) == 0;
  EXPECT_GE(frames, 6u);
  EXPECT_EQ(listed, frames);
  EXPECT_EQ(output::verify_folder(b, {"series.csv", "radius.csv", "membrane.pvd", "vtk/membrane_000000.vtp"}), "");
}

// The VTK frames count toward output.max_bytes with series.csv and radius.csv; a resumed run
// restores the count of the frames written before its checkpoint, so it stops at the same
// frame, with the same message, as the uninterrupted run.
TEST(Run3d, AResumedRunStopsAtTheOutputLimitWhereTheUninterruptedRunDid) {
  const std::vector<std::string> sets = {"full3d.dt=\"1 ms\"", "full3d.output.vtk_interval=\"2 ms\"",
                                         "full3d.checkpoint_interval=\"5 ms\"", "time.duration=\"auto\""};
  const Scene s = tiny(sets);  // time.duration auto: no estimate before the run
  RunControl ctl;
  ctl.progress = 0;
  ctl.max_output_bytes = 1450000;  // compressed frames of about 75 kB: one a few tens of steps in passes it
  const std::string a = fresh_dir("limit_a"), b = fresh_dir("limit_b");
  const RunOutcome ra = run3d(s.p, s.resolved, a, ctl);
  ASSERT_TRUE(ra.failed);
  std::printf("%s (step %ld)\n", ra.message.c_str(), ra.steps);
  EXPECT_NE(ra.message.find("output.max_bytes = 1450000"), std::string::npos) << ra.message;
  EXPECT_NE(ra.message.find("raise full3d.output.vtk_interval"), std::string::npos) << ra.message;
  ASSERT_GT(ra.steps, 7);  // past the checkpoint the resumed run starts from
  RunControl stop = ctl;
  stop.stop_after_steps = 7;  // "killed" at step 7; the last checkpoint is at step 5
  ASSERT_TRUE(run3d(s.p, s.resolved, b, stop).interrupted);
  RunControl res = ctl;
  res.resume = true;
  const RunOutcome rc = run3d(s.p, s.resolved, b, res);
  ASSERT_TRUE(rc.failed);
  EXPECT_EQ(rc.message, ra.message);
  EXPECT_EQ(rc.steps, ra.steps);
  EXPECT_EQ(rc.summary["status"], ra.summary["status"]);
  const auto slurp = [](const std::string& f) {
    std::ifstream in(f, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), {});
  };
  for (const char* f : {"/series.csv", "/radius.csv", "/membrane.pvd"}) EXPECT_EQ(slurp(a + f), slurp(b + f)) << f;
  const auto frames = [](const std::string& d) {
    int n = 0;
    for (const auto& e : fs::directory_iterator(d + "/vtk")) n += e.is_regular_file();
    return n;
  };
  EXPECT_EQ(frames(a), frames(b));
}

TEST(Run3d, ResumeRejectsAnotherScene) {
  const Scene s = tiny({"full3d.dt=\"1 ms\"", "time.duration=\"3 ms\""});
  const std::string d = fresh_dir("resume_other");
  RunControl ctl;
  ctl.progress = 0;
  ctl.quiet_vtk = true;
  ASSERT_FALSE(run3d(s.p, s.resolved, d, ctl).failed);
  const Scene o = tiny({"full3d.dt=\"0.5 ms\"", "time.duration=\"3 ms\""});
  ctl.resume = true;
  EXPECT_THROW(run3d(o.p, o.resolved, d, ctl), InputError);
}

// Node inertia: the free breathing oscillation of the undamped dry tube against the
// analytic estimate omega^2 = C1 / m (C1 = 2 ks / (sqrt(3) R0^2), plane stress; axially
// constrained (plane strain) the stiffness is 1/(1 - nu^2) = 9/8 larger for the lattice's
// Poisson ratio 1/3), and energy conservation of the Verlet integrator.
TEST(Run3d, DrySwimmerBreathingPeriodAndEnergy) {
  const Scene s = tiny({});
  const CylinderMesh mesh = make_mesh(s.p);
  const Eigen::VectorXd m = node_masses(mesh, s.p.mass_per_area);
  const Eigen::VectorXd nu = Eigen::VectorXd::Zero(mesh.nodes());
  IbState st;
  st.X = mesh.X0;
  const double a = 0.01;
  for (Eigen::Index i = 0; i < st.X.cols(); ++i)
    for (int c = 1; c < 3; ++c) st.X(c, i) = mesh.axis_start[c] + (1 + a) * (st.X(c, i) - mesh.axis_start[c]);
  st.V = Eigen::Matrix3Xd::Zero(3, mesh.nodes());
  st.V_prev = st.V;
  const double c1 = s.p.c1_estimate();
  const double T_est = 2 * M_PI * std::sqrt(s.p.mass_per_area / c1);
  const double dt = T_est / 400;
  auto energy = [&](const IbState& x) {
    double k = 0;
    for (Eigen::Index i = 0; i < x.V.cols(); ++i) k += 0.5 * m[i] * x.V.col(i).squaredNorm();
    return k + elastic_energy(mesh, x.X, s.p.membrane);
  };
  const double E0 = energy(st);
  // middle ring radius deviation; period from its upward zero crossings
  const int mid = mesh.n_rings / 2;
  auto dev = [&](const IbState& x) { return ring_radii(mesh, x.X)[mid] - mesh.radius; };
  (void)mid;
  std::vector<double> ups;
  double prev = dev(st), drift = 0;
  for (int k = 0; k < 4000 && ups.size() < 6; ++k) {
    dry_step(mesh, s.p.membrane, m, nu, nullptr, IbScheme::Midpoint, st, dt);
    const double d = dev(st);
    if (prev < 0 && d >= 0) ups.push_back(st.t - dt * d / (d - prev));
    prev = d;
    drift = std::max(drift, std::abs(energy(st) - E0) / E0);
  }
  ASSERT_GE(ups.size(), 2u);
  const double T = (ups.back() - ups[0]) / (ups.size() - 1);
  for (double u : ups) std::printf("  up-crossing at %.5g s\n", u);
  std::printf("breathing period %.4g s, estimate %.4g s (plane stress) .. %.4g s (plane strain); energy drift %.2g\n",
              T, T_est, T_est / std::sqrt(9.0 / 8.0), drift);
  // The middle ring of this short open tube (L = 3.2 R0) also carries axial modes, so single
  // periods scatter (3.2 .. 5.0 ms measured); the mean over five is 4.2 ms, 16 % below the
  // plane-strain estimate. The bound is therefore loose: it checks the mass and stiffness
  // scales of the inertia term, not the shell's mode shapes.
  EXPECT_GT(T, 0.75 * T_est / std::sqrt(9.0 / 8.0));
  EXPECT_LT(T, 1.15 * T_est);
  EXPECT_LT(drift, 1e-3);
}

// The paper's protocol tested on the dry swimmer: every segment reaches R_f, the
// contracted tube sits within delta of R_f, and the recovery ends the cycle.
TEST(Run3d, DryProtocolReachesTargetOnEverySegment) {
  const Scene s = tiny({"full3d.dry=true", "full3d.dt=\"2 us\"", "protocol.total_force=null", "protocol.load_factor=3",
                        "wave.contracted_ratio=0.82", "protocol.segments=3", "protocol.first_segment_ratio=1",
                        "time.output_interval=\"2 us\"", "full3d.checkpoint_interval=\"1 s\"", "time.duration=\"auto\""});
  const std::string dir = fresh_dir("dry_protocol");
  RunControl ctl;
  ctl.progress = 0;
  ctl.quiet_vtk = true;
  const RunOutcome r = run3d(s.p, s.resolved, dir, ctl);
  ASSERT_FALSE(r.failed) << r.message;
  EXPECT_EQ(r.summary["cycles_completed"].get<int>(), 1);
  const auto reached = r.summary["segment_reached_s"].get<std::vector<double>>();
  ASSERT_EQ(reached.size(), 3u);
  const CylinderMesh mesh = make_mesh(s.p);
  const Protocol3d proto(s.p.protocol, mesh, 1.0);
  const auto rad = read_csv(dir + "/radius.csv");
  const int nr = mesh.n_rings;
  auto segment_mean = [&](double t, int k) {  // mean ring radius of segment k at output time t
    double sum = 0;
    int n = 0;
    for (size_t i = 0; i + nr <= rad.size(); i += nr)
      if (std::abs(rad[i][0] - t) < 0.5 * s.p.dt)
        for (int q = 0; q < nr; ++q)
          if (proto.segment_of(mesh.node(q, 0)) == k) {
            sum += rad[i + q][2];
            ++n;
          }
    return n ? sum / n : NAN;
  };
  const double Rf = s.p.protocol.R_f, delta = s.p.protocol.delta;
  for (int e = 0; e < 3; ++e) {
    const int k = 2 - e;
    const double R = segment_mean(reached[e], k);
    std::printf("segment %d reached R_f at t = %.4g s: mean radius %.5g m (R_f %.5g, delta %.3g)\n", k, reached[e], R,
                Rf, delta);
    EXPECT_LE(std::abs(R - Rf), delta);
  }
  for (int k = 1; k < 3; ++k) {  // held segments at the end of the contraction
    const double R = segment_mean(reached[2], k);
    std::printf("held segment %d at the end of the contraction: %.5g m\n", k, R);
    EXPECT_LE(std::abs(R - Rf), 2 * delta);
  }
}

// Scene keys wired to StokesOptions: the paper's rigid circular container
// (container.kind = cylinder, fictitious domain inside a duct at least one cell wider on
// each side, padded to a fast transform size) and the Navier-Stokes advection sub-step (full3d.navier_stokes = true). Both are
// accepted, echoed, and a short force-driven run completes with finite results.
TEST(Run3d, CylinderAndNavierStokesScenesRun) {
  for (const bool ns : {false, true}) {
    const Scene s = tiny({"container.kind=\"cylinder\"", std::string("full3d.navier_stokes=") + (ns ? "true" : "false"),
                          "full3d.dt=\"1 ms\"", "time.duration=\"10 ms\"", "time.output_interval=\"1 ms\""});
    EXPECT_EQ(s.p.container, "cylinder");
    EXPECT_EQ(s.p.navier_stokes, ns);
    EXPECT_EQ(s.p.ny, fft_friendly_size(int(std::lround(2 * s.p.container_radius / s.p.h)) + 2));
    const std::string dir = fresh_dir(ns ? "cylinder_ns" : "cylinder");
    RunControl ctl;
    ctl.progress = 0;
    ctl.quiet_vtk = true;
    const RunOutcome r = run3d(s.p, s.resolved, dir, ctl);
    ASSERT_FALSE(r.failed) << r.message;
    const double disp = r.summary["displacement_m"].get<double>();
    std::printf("cylinder%s: displacement after 10 ms %.4g m\n", ns ? " + Navier-Stokes" : "", disp);
    EXPECT_TRUE(std::isfinite(disp));
    EXPECT_LT(std::abs(disp), 0.05 * s.p.L);
    EXPECT_EQ(r.steps, 10);
  }
}

// A complete fluid-coupled force-driven cycle on the tiny grid (h = 40 nm): contraction
// wave over three segments, five-band recovery, and the recovery end of
// full3d.recovery_end = dead_band (the default). R_f = 0.82 R0: at h = 40 nm (R0/h = 3.1)
// the grid does not resolve the deeper contractions (docs/full3d.md, "Resolution").
TEST(Run3d, FluidCoupledCycleCompletesAndSwimsForward) {
  const Scene s = tiny({"wave.contracted_ratio=0.82", "protocol.segments=3", "protocol.first_segment_ratio=1",
                        "protocol.total_force=null", "protocol.load_factor=2", "full3d.dt=\"1 ms\"",
                        "time.output_interval=\"5 ms\"", "full3d.time_limit=\"1.5 s\"",
                        "full3d.checkpoint_interval=\"1 s\"", "time.duration=\"auto\""});
  EXPECT_EQ(s.p.recovery_end, "dead_band");
  const std::string dir = fresh_dir("fluid_cycle");
  RunControl ctl;
  ctl.progress = 0;
  ctl.quiet_vtk = true;
  const RunOutcome r = run3d(s.p, s.resolved, dir, ctl);
  ASSERT_FALSE(r.failed) << r.message;
  ASSERT_EQ(r.summary["cycles_completed"].get<int>(), 1);
  const double disp = r.summary["displacement_m"].get<double>();
  const double t_cycle = r.summary["cycle_times_s"][0].get<double>();
  const auto rows = read_csv(dir + "/series.csv");
  const double e_end = rows.back()[3];
  const double e_thr = r.summary["derived"]["recovery_end_energy_J"].get<double>();
  const double e_ref = r.summary["derived"]["reference_energy_J"].get<double>();
  std::printf("fluid cycle: %.4g s, displacement %.4g m = %.3g L, end energy %.3g J = %.3g E_ref (threshold %.3g "
              "E_ref), max edge %.3g h\n",
              t_cycle, disp, disp / s.p.L, e_end, e_end / e_ref, e_thr / e_ref,
              r.summary["max_edge_over_h"].get<double>());
  EXPECT_LT(e_end, e_thr);
  EXPECT_LT(e_thr, 0.02 * e_ref);  // (delta / (R0 - R_f))^2 = 0.012 here
  EXPECT_GT(disp, 0.0);             // measured +7.0e-10 m (+8.8e-10 m at spacing factor 0.7)
  EXPECT_LT(t_cycle, 1.2);          // measured 0.73 s
  for (double v : rows.back()) EXPECT_TRUE(std::isfinite(v));
}

// The paper's rule (full3d.recovery_end = energy) is still selectable: the threshold is
// energy_tolerance * E_ref.
TEST(Run3d, PaperRecoveryEndIsSelectable) {
  const Scene s = tiny({"full3d.recovery_end=\"energy\""});
  const CylinderMesh mesh = make_mesh(s.p);
  const double e_ref = uniform_contraction_energy(mesh, s.p.membrane, s.p.protocol.R_f);
  const Protocol3d paper(effective_protocol(s.p, mesh), mesh, e_ref);
  EXPECT_DOUBLE_EQ(paper.end_threshold(), s.p.protocol.energy_tol * e_ref);
  const Scene d = tiny({});
  const Protocol3d band(effective_protocol(d.p, mesh), mesh, e_ref);
  const double e_delta = uniform_contraction_energy(mesh, d.p.membrane, mesh.radius - d.p.protocol.delta);
  EXPECT_DOUBLE_EQ(band.end_threshold(), std::max(d.p.protocol.energy_tol * e_ref, e_delta));
  std::printf("E_delta / E_ref = %.4g (R_f = %.2f R0, delta = %.2f R0)\n", e_delta / e_ref,
              s.p.protocol.R_f / s.p.R0, s.p.protocol.delta / s.p.R0);
}

// A run stopped by full3d.time_limit can be continued with a larger cap (time_limit is,
// with checkpoint_interval and threads, allowed to change on resume) and then ends exactly
// as a run that had the larger cap from the start.
TEST(Run3d, ResumeWithLargerTimeLimitFinishesTheCycle) {
  auto cycle_scene = [](const std::string& limit) {
    return run3d_test::shipped_scene("tiny_3d_cycle.json", {"full3d.time_limit=\"" + limit + "\"",
                                                         "full3d.checkpoint_interval=\"50 ms\"", "full3d.output.vtk=false"});
  };
  RunControl ctl;
  ctl.progress = 0;
  ctl.quiet_vtk = true;
  const Scene full = cycle_scene("1.5 s");
  const std::string a = fresh_dir("longer_limit_a"), b = fresh_dir("longer_limit_b");
  const RunOutcome ra = run3d(full.p, full.resolved, a, ctl);
  ASSERT_FALSE(ra.failed) << ra.message;
  const Scene capped = cycle_scene("0.3 s");
  const RunOutcome rb = run3d(capped.p, capped.resolved, b, ctl);
  ASSERT_TRUE(rb.failed);
  EXPECT_NE(rb.message.find("full3d.time_limit"), std::string::npos);
  RunControl res = ctl;
  res.resume = true;
  const RunOutcome rc = run3d(full.p, full.resolved, b, res);
  ASSERT_FALSE(rc.failed) << rc.message;
  EXPECT_EQ(rc.summary["cycles_completed"].get<int>(), 1);
  EXPECT_EQ(rc.steps, ra.steps);
  EXPECT_EQ(rc.summary["displacement_m"].get<double>(), ra.summary["displacement_m"].get<double>());
}

// full3d.recovery_end = shape: the geometric end of the recovery (ring radii and axial ring
// positions within delta of the reference, up to a rigid axial translation).
TEST(Run3d, ShapeRecoveryCriterion) {
  const Scene s = tiny({"full3d.recovery_end=\"shape\""});
  EXPECT_TRUE(s.p.protocol.shape_end);
  const CylinderMesh mesh = make_mesh(s.p);
  const Protocol3d proto(effective_protocol(s.p, mesh), mesh, 1.0);
  Eigen::Matrix3Xd X = mesh.X0;
  EXPECT_TRUE(proto.shape_recovered(X));
  X.row(0).array() += 3e-8;  // the swimmer has moved: still its reference shape
  EXPECT_TRUE(proto.shape_recovered(X));
  const double delta = s.p.protocol.delta;
  Eigen::Matrix3Xd Y = X;  // radius off by 1.5 delta on the last ring
  for (int i = 0; i < mesh.n_theta; ++i) {
    const int k = mesh.node(mesh.n_rings - 1, i);
    for (int c = 1; c < 3; ++c) Y(c, k) = mesh.axis_start[c] + (1 - 1.5 * delta / mesh.radius) * (Y(c, k) - mesh.axis_start[c]);
  }
  EXPECT_FALSE(proto.shape_recovered(Y));
  Y = X;  // last ring pushed 1.5 delta into the tube (a folded end)
  for (int i = 0; i < mesh.n_theta; ++i) Y(0, mesh.node(mesh.n_rings - 1, i)) -= 1.5 * delta;
  EXPECT_FALSE(proto.shape_recovered(Y));
}

// Any number of cycles: the energy (here dead-band) criterion ends the first recovery, the
// second cycle starts at once, and both cycles move the swimmer forward. The cycles are not
// copies of each other: the first starts from the reference tube at rest, the second from
// the end of a recovery whose wall is still up to 4 % of R0 in (the dead band ends it), so
// the second cycle is a transient towards a periodic regime. Measured (h = 40 nm): cycles of
// 0.713 and 1.155 s moving 0.55 and 1.33 nm. The bounds check the order of magnitude only.
TEST(Run3d, TwoFluidCoupledCyclesBothMoveForward) {
  const Scene s =
      run3d_test::shipped_scene("tiny_3d_cycle.json", {"protocol.cycles=2", "full3d.time_limit=\"3 s\"", "full3d.output.vtk=false"});
  const std::string dir = fresh_dir("two_cycles");
  RunControl ctl;
  ctl.progress = 0;
  ctl.quiet_vtk = true;
  const RunOutcome r = run3d(s.p, s.resolved, dir, ctl);
  ASSERT_FALSE(r.failed) << r.message;
  EXPECT_EQ(r.summary["cycles_completed"].get<int>(), 2);
  const auto starts = r.summary["cycle_start_times_s"].get<std::vector<double>>();
  const auto ends = r.summary["cycle_end_times_s"].get<std::vector<double>>();
  ASSERT_EQ(ends.size(), 2u);
  ASSERT_GE(starts.size(), 2u);
  EXPECT_NEAR(starts[1], ends[0], 1.5 * s.p.dt);  // the next cycle starts when the recovery ends
  // centre position at the end of each cycle, from the series (output every 5 ms)
  const auto rows = read_csv(dir + "/series.csv");
  auto x_at = [&](double t) {
    double best = 1e300, x = 0;
    for (const auto& row : rows)
      if (std::abs(row[0] - t) < best) best = std::abs(row[0] - t), x = row[1];
    return x;
  };
  const double d1 = x_at(ends[0]) - rows.front()[1], d2 = x_at(ends[1]) - x_at(ends[0]);
  std::printf("cycle ends %.3f, %.3f s; displacement per cycle %.4g, %.4g m\n", ends[0], ends[1], d1, d2);
  EXPECT_GT(d1, 0.0);
  EXPECT_GT(d2, 0.0);
  EXPECT_GT(d2 / d1, 1.0 / 3.0);
  EXPECT_LT(d2 / d1, 3.0);
  EXPECT_GT((ends[1] - ends[0]) / ends[0], 0.5);
  EXPECT_LT((ends[1] - ends[0]) / ends[0], 2.0);
}
