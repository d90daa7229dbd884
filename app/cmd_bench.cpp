// swim bench: performance figures, measured in one run so that ratios are meaningful on a
// shared machine. 3D part at the end (full3d). 1D part: wall time of one force-driven cycle at N = 50, 200, 800 and,
// at N = 200, with the lubrication-only wall, the unbounded outer flow and in the paper mode (best
// of several repetitions) and screening throughput (designs per second) on all cores and on
// one thread, with the process CPU time per design.
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "app/app.hpp"
#include "axi/fe_stokes_axi.hpp"
#include "axi/run_axi.hpp"
#include "axi/scene_axi.hpp"
#include "axi/wall_axi.hpp"
#include "common/errors.hpp"
#include "common/output.hpp"
#include "common/scene.hpp"
#include "reduced1d/report.hpp"
#include "reduced1d/scene1d.hpp"
#include "reduced1d/screen.hpp"
#include "reduced1d/solver.hpp"
#include "full3d/fft.hpp"
#include "full3d/protocol3d.hpp"
#include "full3d/reference/duct_fft.hpp"
#include "full3d/run3d.hpp"
#include "full3d/scene3d.hpp"
#include "full3d/world3d.hpp"

namespace swim::app {

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// CPU time of the whole process (all threads) [s].
double process_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

/// Best wall time of `reps` solves of p; r receives the last result.
double best_solve_time(const reduced1d::Params& p, int reps, reduced1d::Result& r) {
  double best = 1e300;
  for (int k = 0; k < reps; ++k) {
    const auto t0 = std::chrono::steady_clock::now();
    r = reduced1d::solve(p);
    best = std::min(best, seconds_since(t0));
  }
  return best;
}

reduced1d::Params demo_params(const std::vector<std::string>& sets) {
  scene::json sc = scene::load_file(data_dir() + "/scenes/demo.json");
  for (const auto& s : sets) scene::apply_override(sc, s);
  scene::json resolved;
  return reduced1d::read_scene(sc, resolved, data_dir() + "/scenes");
}

/// One field of an FFTW floor: the {z, y} extents of its transformed cross-section and the
/// forward and inverse r2r kinds across.
struct FloorField {
  std::array<int, 2> n;
  std::array<fftw_r2r_kind, 2> fwd, inv;
};

/// 8 transforms, each field forward and inverse: a batched 2D transform over the cross
/// sections and a batched 1D real transform along x, in a plain C-order layout (x
/// outermost), FFTW_MEASURE, `threads` FFTW threads. Best of `reps` repetitions, s per step.
double time_floor(int nx, const std::array<FloorField, 4>& fields, int threads, int reps) {
  using namespace swim::full3d;
  if (threads > 1) fftw_threads_init_once();
  const FftOptions o{threads, PlanRigor::Measure};
  int plane_max = 0;
  for (const FloorField& fd : fields) plane_max = std::max(plane_max, fd.n[0] * fd.n[1]);
  FftwBuffer a(std::size_t(nx) * plane_max), c(std::size_t(2) * (nx / 2 + 1) * plane_max);
  struct Plans {
    FftwPlan f, i, fx, bx;
  };
  std::vector<Plans> plans;
  for (const FloorField& fd : fields) {
    const int plane = fd.n[0] * fd.n[1];
    plans.push_back({plan_many_r2r(2, fd.n.data(), nx, a.data(), nullptr, 1, plane, a.data(), nullptr, 1, plane,
                                   fd.fwd.data(), o),
                     plan_many_r2r(2, fd.n.data(), nx, a.data(), nullptr, 1, plane, a.data(), nullptr, 1, plane,
                                   fd.inv.data(), o),
                     plan_many_r2c_1d(nx, plane, a.data(), plane, 1, c.complex(), plane, 1, o),
                     plan_many_c2r_1d(nx, plane, c.complex(), plane, 1, a.data(), plane, 1, o)});
  }
  for (std::size_t i = 0; i < a.size(); ++i) a[i] = std::sin(0.37 * double(i));
  double best = 1e300;
  for (int r = 0; r < reps; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    for (const Plans& q : plans) {
      q.f.execute();  // forward: cross sections, then along x
      q.fx.execute();
      q.bx.execute();  // inverse: along x, then cross sections
      q.i.execute();
    }
    best = std::min(best, seconds_since(t0));
  }
  return best;
}

/// The physical floor of one coupled step on an nx x ny x nz grid of the duct's kind (the
/// cylinder lives inside the same duct grid): the 3 velocity components and the pressure on
/// the ny x nz cells, RODFT10/01 across for the velocities, REDFT10/01 for the pressure.
double fft_floor(int nx, int ny, int nz, int threads, int reps) {
  const FloorField vel{{nz, ny}, {FFTW_RODFT10, FFTW_RODFT10}, {FFTW_RODFT01, FFTW_RODFT01}};
  const FloorField pre{{nz, ny}, {FFTW_REDFT10, FFTW_REDFT10}, {FFTW_REDFT01, FFTW_REDFT01}};
  return time_floor(nx, {vel, vel, vel, pre}, threads, reps);
}

/// The same floor with the transforms the staggered grid itself needs: the face components
/// normal to a wall vanish on it, so across that direction v and w are DST-I (RODFT00) of the
/// n - 1 interior faces, u and p DCT-II/III (REDFT10/01) of the n cells, as in the
/// production solver. DST-I costs FFTW about twice a DCT-II of the same length per point.
double fft_floor_staggered(int nx, int ny, int nz, int threads, int reps) {
  const fftw_r2r_kind C10 = FFTW_REDFT10, C01 = FFTW_REDFT01, S00 = FFTW_RODFT00;
  const FloorField cells{{nz, ny}, {C10, C10}, {C01, C01}};        // u, p
  const FloorField vface{{nz, ny - 1}, {C10, S00}, {C01, S00}};    // v: interior y faces
  const FloorField wface{{nz - 1, ny}, {S00, C10}, {S00, C01}};    // w: interior z faces
  return time_floor(nx, {cells, vface, wface, cells}, threads, reps);
}

// ---- 1D tier ------------------------------------------------------------------------------

/// One force-driven cycle of the demo scene, best of `reps` solves.
struct CycleTiming {
  int cells = 0;
  std::string set;  ///< the variant's scene change ("" for the plain scene)
  std::string wall_law = "linear";
  double wall_s = 0, cycle_time_s = 0, displacement_per_cycle_m = 0;
  long steps = 0, switches = 0, newton_setups = 0, newton_iterations = 0, residual_evals = 0;
  long newton_factorisations = 0;  ///< set-ups that factored (not keeping the previous factorisation)
  bool ok = false;
};

/// The calibrated round-wall law shipped in docs/tube-law/ (absent in an installed tree).
const std::string kLawFile = SWIM_SOURCE_DIR "/docs/tube-law/calibration.json";

/// The scene changes that put the calibrated round-wall law (docs/tube-law.md) in place of the
/// linear one.
std::vector<std::string> calibrated_wall_sets() {
  return {"wall.spring_constant=null", "wall.calibration=\"" + kLawFile + "\"", "wall.law=\"calibrated_round\""};
}

CycleTiming time_cycle(int cells, const std::vector<std::string>& sets, const std::string& variant, int reps) {
  const auto p = demo_params(sets);
  reduced1d::Result r;
  CycleTiming c;
  c.cells = cells;
  c.set = variant;
  c.wall_s = best_solve_time(p, reps, r);
  const auto m = reduced1d::metrics(p, r);
  auto stat = [&](const char* k) { return r.stats.count(k) ? r.stats.at(k) : 0L; };
  c.steps = stat("steps");
  c.newton_setups = stat("lin_setups");
  c.newton_factorisations = c.newton_setups - stat("lin_setups_kept");
  c.newton_iterations = stat("nonlin_iters");
  c.residual_evals = stat("rhs_evals");
  c.switches = r.switches;
  c.cycle_time_s = m.mean_cycle_time_s;
  c.displacement_per_cycle_m = m.displacement_per_cycle_m;
  c.ok = !r.failure;
  return c;
}

void print_cycle(const CycleTiming& c) {
  std::printf("  %6d %12.3f %10ld %10ld %10ld %10ld %10ld %10.4g%s%s%s%s\n", c.cells, 1e3 * c.wall_s, c.steps, c.newton_setups,
              c.newton_factorisations, c.residual_evals, c.switches, c.cycle_time_s, c.set.empty() ? "" : "  ", c.set.c_str(),
              c.wall_law == "linear" ? "" : ("  " + c.wall_law + " wall").c_str(), c.ok ? "" : "  FAILED");
}

scene::json cycle_json(const CycleTiming& c) {
  return {{"cells", c.cells},
          {"wall_law", c.wall_law},
          {"wall_time_s", c.wall_s},
          {"steps", c.steps},
          {"newton_setups", c.newton_setups},
          {"newton_factorisations", c.newton_factorisations},
          {"newton_iterations", c.newton_iterations},
          {"residual_evals", c.residual_evals},
          {"switches", c.switches},
          {"cycle_time_s", c.cycle_time_s},
          {"displacement_per_cycle_m", c.displacement_per_cycle_m},
          {"ok", c.ok}};
}

scene::json variant_json(const CycleTiming& c) {
  return {{"cells", c.cells}, {"set", c.set}, {"wall_time_s", c.wall_s}, {"steps", c.steps},
          {"displacement_per_cycle_m", c.displacement_per_cycle_m}, {"ok", c.ok}};
}

/// A screening case: the design kind, its cells, the short-wave traction.
struct ScreeningCase {
  std::string kind;
  int cells;
  bool traction = true;
  bool calibrated_law = false;
  bool fine_rtol = false;  ///< numerics1d.rtol = 1e-6 instead of the screening grids' default 1e-4
  std::string label() const {
    return kind + (traction ? "" : " lubrication wall") + (calibrated_law ? " calibrated_round wall" : "") +
           " N=" + std::to_string(cells) + (fine_rtol ? " rtol=1e-6" : "");
  }
};

/// Screening throughput of one case, on all cores and on one thread.
struct ScreeningTiming {
  std::string label;
  int designs = 0, cells = 0;
  unsigned threads = 0;
  double wall_s[2] = {0, 0}, cpu_s[2] = {0, 0};  ///< all cores, one thread
  long failed = 0;
};

/// A 10 x 10 grid over lambda = R_f/R0 in [0.35, 0.85] and L in [0.2, 0.8] um. Force-driven
/// designs drive at 1.4x the static load so that every design is reachable and runs a whole
/// cycle (failing designs would cost nothing and inflate the figure).
ScreeningTiming time_screening(const ScreeningCase& c, bool quick, unsigned cores) {
  const int n = c.kind == "step" ? (quick ? 100 : 1000) : (quick ? 20 : 100);
  std::vector<reduced1d::Params> designs;
  for (int k = 0; k < n; ++k) {
    const double lambda = 0.35 + 0.5 * (k % 10) / 9.0;
    const double length_um = 0.2 + 0.6 * (k / 10 % 10) / 9.0;
    char l[64], s[64];
    std::snprintf(l, sizeof l, "wave.contracted_ratio=%.4f", lambda);
    std::snprintf(s, sizeof s, "swimmer.length=\"%.4f um\"", length_um);
    std::vector<std::string> sets = {l, s, "wave.kind=\"" + c.kind + "\"", "numerics1d.cells=" + std::to_string(c.cells)};
    if (!c.traction) sets.push_back("model1d.short_wave_traction=false");
    if (c.fine_rtol) sets.push_back("numerics1d.rtol=1e-6");
    if (c.calibrated_law) {
      const auto law = calibrated_wall_sets();
      sets.insert(sets.end(), law.begin(), law.end());
    }
    if (c.kind == "step")
      sets.push_back("protocol=null");
    else
      sets.insert(sets.end(), {"protocol.total_force=null", "protocol.load_factor=1.4"});
    designs.push_back(demo_params(sets));
  }
  ScreeningTiming t;
  t.label = c.label();
  t.designs = n;
  t.cells = c.cells;
  t.threads = cores;
  // On all cores, then on one thread. The process CPU time tells a CPU-starved run (other
  // jobs on the machine: fewer cores used than threads) from poor scaling (more CPU per
  // design on more threads).
  for (int pass = 0; pass < 2; ++pass) {
    const double c0 = process_cpu_seconds();
    const auto t0 = std::chrono::steady_clock::now();
    const auto res = reduced1d::run_designs(designs, pass == 0 ? 0 : 1);
    t.wall_s[pass] = seconds_since(t0);
    t.cpu_s[pass] = process_cpu_seconds() - c0;
    if (pass == 0) t.failed = std::count_if(res.begin(), res.end(), [](const auto& r) { return !r.ok; });
  }
  return t;
}

void print_screening(const ScreeningTiming& t) {
  const int n = t.designs;
  std::printf("  %-20s %6d designs in %8.3f s: %9.1f designs/s (%ld failed); CPU %.3g ms/design, %.2f cores used; "
              "1 thread: %.1f designs/s, CPU %.3g ms/design\n",
              t.label.c_str(), n, t.wall_s[0], n / t.wall_s[0], t.failed, 1e3 * t.cpu_s[0] / n, t.cpu_s[0] / t.wall_s[0],
              n / t.wall_s[1], 1e3 * t.cpu_s[1] / n);
}

scene::json screening_json(const ScreeningTiming& t) {
  const int n = t.designs;
  return {{"designs", n}, {"cells", t.cells}, {"threads", t.threads}, {"wall_time_s", t.wall_s[0]},
          {"designs_per_s", n / t.wall_s[0]}, {"cpu_time_s", t.cpu_s[0]}, {"cores_used", t.cpu_s[0] / t.wall_s[0]},
          {"designs_per_s_1_thread", n / t.wall_s[1]}, {"cpu_time_s_1_thread", t.cpu_s[1]}, {"failed", t.failed}};
}

/// The 1D part: one force-driven cycle at N = 50, 200, 800; at N = 200 the lubrication-only
/// wall (no short-wave traction), the other outer flow and the paper's reproduction mode; at
/// N = 50 the finer grids' tolerance and the continued open ends; screening throughput.
void bench_1d(scene::json& report, bool quick, int reps, unsigned cores) {
  std::printf("== 1D tier ==\n");
  // The 50-cell cycles (about 10 ms each) take four times the repetitions: on a shared machine
  // their best comes nearer the floor at a cost of a fraction of a second.
  const auto reps_at = [&](int cells) { return cells <= 50 ? 4 * reps : reps; };
  std::printf("one force-driven cycle (demo scene, best of %d; at N = 50 of %d):\n", reps, reps_at(50));
  std::printf("  %6s %12s %10s %10s %10s %10s %10s %10s\n", "N", "wall [ms]", "steps", "set-ups", "factored", "residuals",
              "switches", "cycle [s]");
  scene::json cycles = scene::json::array();
  // the default model at N = 50, 200, 800, and at N = 50 with the calibrated round-wall law
  const bool have_law = std::filesystem::exists(kLawFile);
  for (int n : {50, 200, 800, -50}) {
    if (n < 0 && !have_law) continue;
    std::vector<std::string> sets = {"numerics1d.cells=" + std::to_string(std::abs(n)), "protocol.cycles=1",
                                     "time.duration=\"auto\""};
    if (n < 0) {
      const auto law = calibrated_wall_sets();
      sets.insert(sets.end(), law.begin(), law.end());
    }
    CycleTiming c = time_cycle(std::abs(n), sets, "", reps_at(std::abs(n)));
    if (n < 0) c.wall_law = "calibrated_round";
    print_cycle(c);
    cycles.push_back(cycle_json(c));
  }
  report["force_driven_cycle"] = cycles;
  scene::json variants = scene::json::array();
  // the other models at N = 200, and the default model at N = 50 at the finer grids' tolerance
  // (the scene's default there is 1e-4: docs/performance-1d.md, "The tolerance against the
  // grid's error") and with the continued open ends (docs/reduced1d.md, "The open ends' half
  // cells")
  for (const auto& [cells, v] : {std::pair{200, std::string("model1d.short_wave_traction=false")},
                                 std::pair{200, std::string("model1d.outer_flow=\"unbounded\"")},
                                 std::pair{200, std::string("model1d.model=\"paper\"")},
                                 std::pair{50, std::string("numerics1d.rtol=1e-6")},
                                 std::pair{50, std::string("numerics1d.open_end=\"continued\"")},
                                 std::pair{50, std::string("numerics1d.threads=2")}}) {
    std::vector<std::string> sets = {"numerics1d.cells=" + std::to_string(cells), "protocol.cycles=1",
                                     "time.duration=\"auto\"", v};
    if (v.find("paper") != std::string::npos) sets.push_back("model1d.outer_flow=null");
    const CycleTiming c = time_cycle(cells, sets, v, reps_at(cells));
    print_cycle(c);
    variants.push_back(variant_json(c));
  }
  report["force_driven_cycle_variants"] = variants;

  // N = 200 (the shipped scenes' grid) and N = 50 (the default grid with the short-wave
  // traction), and the lubrication-only wall at N = 200
  std::printf("screening throughput (%u threads, 10 x 10 grid over lambda and L):\n", cores);
  scene::json screening = scene::json::object();
  for (const ScreeningCase& c : {ScreeningCase{"step", 200}, ScreeningCase{"force_driven", 200},
                                 ScreeningCase{"force_driven", 50}, ScreeningCase{"force_driven", 50, true, false, true},
                                 ScreeningCase{"force_driven", 50, true, true},
                                 ScreeningCase{"force_driven", 200, false}}) {
    if (c.calibrated_law && !have_law) continue;
    const ScreeningTiming t = time_screening(c, quick, cores);
    print_screening(t);
    screening[t.label] = screening_json(t);
  }
  report["screening"] = screening;
}

// ---- 3D tier ------------------------------------------------------------------------------

/// The time per coupled step of one scene, split into its parts, against the bare FFT Stokes
/// solve and the FFTW floors on the same grid and threads.
struct StepTiming {
  std::string grid, container;
  int nodes = 0, threads = 0;
  double step_s = 0, best_s = 0, fluid_s = 0, spread_s = 0, interp_s = 0, forces_s = 0;
  double bare_s = 0, floor_s = 0, mac_s = 0;
  /// the cylinder's fluid solve against the duct's on the same grid (cylinder scenes only)
  double cylinder_solve_s = 0, duct_solve_s = 0;
};

/// The demo swimmer in `container` at `across` cells, `thr` threads: `steps` timed steps after
/// a warm-up, the bare solve, the floors and (cylinder) the duct's solve on the same grid.
StepTiming time_steps(int across, const std::string& container, int thr, int steps) {
  scene::json sc = scene::load_file(data_dir() + "/scenes/demo.json");
  scene::apply_override(sc, "full3d.grid.cells_across=" + std::to_string(across));
  scene::apply_override(sc, "full3d.threads=" + std::to_string(thr));
  scene::apply_override(sc, "container.kind=\"" + container + "\"");
  scene::json resolved;
  const full3d::Params3d p = full3d::read_scene3d(sc, resolved);
  const full3d::World3d world(p);
  const full3d::MacGrid grid = world.grid();
  const std::unique_ptr<full3d::IbSolver> solver = world.solver();  // a massless wall
  full3d::IbSolver& ib = *solver;
  ib.stokes().compute_pressure(false);  // the step of a run that writes no fluid frames (the default)
  full3d::Protocol3d proto = world.protocol();
  proto.start(0.0, world.mesh.X0);
  ib.set_external_force([&](double, const Eigen::Matrix3Xd& X) { return proto.force(X); });
  full3d::IbState st = ib.initial_state();
  ib.step(st, p.dt);  // warm-up (plans, first PCG)
  StepTiming t;
  t.container = container;
  t.nodes = world.mesh.nodes();
  t.threads = thr;
  full3d::IbStepStats sum;
  const auto t0 = std::chrono::steady_clock::now();
  double best = 1e300;  // the fastest step: compared with the floor's best repetition
  for (int k = 0; k < steps; ++k) {
    const auto t1 = std::chrono::steady_clock::now();
    const auto s1 = ib.step(st, p.dt);
    best = std::min(best, seconds_since(t1));
    sum.time_fluid += s1.time_fluid;
    sum.time_spread += s1.time_spread;
    sum.time_interp += s1.time_interp;
    sum.time_forces += s1.time_forces;
  }
  t.step_s = seconds_since(t0) / steps;
  t.best_s = best;
  t.fluid_s = sum.time_fluid / steps;
  t.spread_s = sum.time_spread / steps;
  t.interp_s = sum.time_interp / steps;
  t.forces_s = sum.time_forces / steps;
  // bare FFT solve (reference::PressureCorrectionStep, full3d/reference/duct_fft.hpp) with the
  // same forcing size
  full3d::VectorField u(grid), f(grid);
  for (auto& c : f.c)
    for (size_t i = 0; i < c.size(); ++i) c[i] = std::sin(0.37 * double(i));
  // The bare solve runs its transforms through FFTW's own threads; for some sizes
  // (e.g. the cylinder's 34 cells across) FFTW's threaded plans are slower than its
  // serial ones, so the reference is the faster of FFTW with `thr` threads and with one.
  double bare_per = 1e300;
  for (int fft_threads : {thr, 1}) {
    if (fft_threads == 1 && thr == 1 && bare_per < 1e300) break;
    full3d::FftOptions fo = world.options.stokes.fft;
    fo.threads = fft_threads;
    full3d::reference::PressureCorrectionStep bare(grid, p.fluid, fo);
    bare.step(u, f, p.dt);
    const auto t1 = std::chrono::steady_clock::now();
    for (int k = 0; k < steps; ++k) bare.step(u, f, p.dt);
    bare_per = std::min(bare_per, seconds_since(t1) / steps);
  }
  t.bare_s = bare_per;
  t.floor_s = fft_floor(p.nx, p.ny, p.nz, thr, std::max(3, steps));
  t.mac_s = fft_floor_staggered(p.nx, p.ny, p.nz, thr, std::max(3, steps));
  char g[32];
  std::snprintf(g, sizeof g, "%dx%dx%d%s", p.nx, p.ny, p.nz, container == "cylinder" ? " cyl" : "");
  t.grid = g;
  if (container == "cylinder") {
    // the cylinder's fluid solve against the duct's on the same grid, same threads, same forcing
    full3d::StokesOptions so = world.options.stokes;
    so.cylinder.enabled = false;
    full3d::StokesSolver duct(grid, p.fluid, so);
    duct.compute_pressure(false);  // as the cylinder's solver in the step above
    full3d::StokesSolver& cyl = ib.stokes();
    double t_duct = 1e300, t_cyl = 1e300;
    duct.step(u, f, p.dt);
    for (int k = 0; k < steps; ++k) {
      std::fill(u.c[0].begin(), u.c[0].end(), 0.0);
      auto t1 = std::chrono::steady_clock::now();
      duct.step(u, f, p.dt);
      t_duct = std::min(t_duct, seconds_since(t1));
      t1 = std::chrono::steady_clock::now();
      cyl.step(u, f, p.dt);
      t_cyl = std::min(t_cyl, seconds_since(t1));
    }
    t.cylinder_solve_s = t_cyl;
    t.duct_solve_s = t_duct;
  }
  return t;
}

void print_step_header() {
  std::printf("  (per step, ms: mean over the timed steps, best: the fastest; bare: the project's pressure-correction\n"
              "   FFT solve; floor: 8 raw FFTW transforms of the duct's kind, sine/cosine-II across, best of the\n"
              "   repetitions; mac: the same with the staggered grid's own kinds, sine-I of the interior faces for v\n"
              "   and w; FFTW_MEASURE, same grid and threads; st/flr and st/mac: best step / floor)\n");
  std::printf("  %-14s %7s %3s %9s %9s %9s %9s %9s %9s %9s %9s %7s %7s %9s %7s\n", "grid", "nodes", "thr", "step[ms]",
              "best", "fluid", "spread", "interp", "forces", "bare[ms]", "floor[ms]", "st/bare", "st/flr", "mac[ms]",
              "st/mac");
}

void print_steps(const StepTiming& t) {
  std::printf("  %-14s %7d %3d %9.2f %9.2f %9.2f %9.2f %9.2f %9.2f %9.2f %9.2f %7.2f %7.2f %9.2f %7.2f\n",
              t.grid.c_str(), t.nodes, t.threads, 1e3 * t.step_s, 1e3 * t.best_s, 1e3 * t.fluid_s, 1e3 * t.spread_s,
              1e3 * t.interp_s, 1e3 * t.forces_s, 1e3 * t.bare_s, 1e3 * t.floor_s, t.step_s / t.bare_s,
              t.best_s / t.floor_s, 1e3 * t.mac_s, t.best_s / t.mac_s);
  if (t.container == "cylinder")
    std::printf("  %-14s fluid solve: cylinder %.2f ms, duct %.2f ms on the same grid: ratio %.2f\n", "",
                1e3 * t.cylinder_solve_s, 1e3 * t.duct_solve_s, t.cylinder_solve_s / t.duct_solve_s);
}

scene::json steps_json(const StepTiming& t) {
  scene::json row = {{"grid", t.grid},
                     {"container", t.container},
                     {"nodes", t.nodes},
                     {"threads", t.threads},
                     {"step_s", t.step_s},
                     {"step_best_s", t.best_s},
                     {"fluid_s", t.fluid_s},
                     {"spread_s", t.spread_s},
                     {"interp_s", t.interp_s},
                     {"forces_s", t.forces_s},
                     {"bare_fft_solve_s", t.bare_s},
                     {"step_over_bare", t.step_s / t.bare_s},
                     {"fft_floor_s", t.floor_s},
                     {"step_over_floor", t.best_s / t.floor_s},
                     {"fft_floor_staggered_s", t.mac_s},
                     {"step_over_floor_staggered", t.best_s / t.mac_s}};
  if (t.container == "cylinder") {
    row["cylinder_solve_s"] = t.cylinder_solve_s;
    row["duct_solve_same_grid_s"] = t.duct_solve_s;
    row["cylinder_over_duct"] = t.cylinder_solve_s / t.duct_solve_s;
  }
  return row;
}

/// One cycle of a paper scene run end to end.
struct PaperCycle {
  std::string scene;     ///< the scene file's stem
  full3d::Params3d p;
  unsigned threads = 0;
  full3d::RunOutcome run;
  double wall_s = 0;
  bool done = false;     ///< the cycle ended
  double t_cycle = 0;    ///< its end, or the run's end
  double target_s = 0;   ///< the cycle's wall-time target
  std::vector<std::pair<double, std::string>> split;  ///< wall time parts, largest first
  std::vector<std::string> sets;  ///< scene overrides beyond the cycle's own (--fine-cycle-set)
};

/// One cycle of data/scenes/SCENE.json with `sets`, as shipped otherwise (adaptive step,
/// recovery included; without VTK frames), on all cores, into out/DIR.
PaperCycle run_cycle(const std::string& out, unsigned cores, const std::string& scene_stem,
                     const std::vector<std::string>& sets, const std::string& dir_name, double target_s) {
  scene::json sc = scene::load_file(data_dir() + "/scenes/" + scene_stem + ".json");
  for (const auto& s : sets) scene::apply_override(sc, s);
  scene::apply_override(sc, "full3d.threads=" + std::to_string(cores));
  scene::apply_override(sc, "full3d.output.vtk=false");
  scene::json resolved;
  PaperCycle c;
  c.scene = scene_stem;
  c.target_s = target_s;
  c.p = full3d::read_scene3d(sc, resolved);
  c.threads = cores;
  const std::string dir = out + "/" + dir_name;
  output::make_dir(dir);
  full3d::RunControl ctl;
  ctl.progress = 1;
  ctl.quiet_vtk = true;
  std::printf("%s, one cycle (%dx%dx%d, %s, %u threads) ...\n", scene_stem.c_str(), c.p.nx, c.p.ny, c.p.nz,
              c.p.adaptive.enabled ? "adaptive step" : ("dt = " + std::to_string(c.p.dt) + " s").c_str(), cores);
  std::fflush(stdout);
  const auto t0 = std::chrono::steady_clock::now();
  c.run = full3d::run3d(c.p, resolved, dir, ctl);
  c.wall_s = seconds_since(t0);
  const auto& sm = c.run.summary;
  const auto& ends = sm.value("cycle_end_times_s", scene::json::array());
  c.done = !c.run.failed && !ends.empty();
  c.t_cycle = c.done ? ends[0].get<double>() : sm.value("t_end_s", 0.0);
  // where the run's wall time went (solver_stats.json "wall_time_split_s"), largest parts first
  const scene::json split = c.run.record.stats.value("wall_time_split_s", scene::json::object());
  for (const auto& [k, v] : split.items()) c.split.emplace_back(v.get<double>(), k);
  std::sort(c.split.rbegin(), c.split.rend());
  return c;
}

/// The paper's single-cycle scene (L = 0.4 um, R_f = 0.55 R0) at the default resolution, into
/// out/paper_cycle (a 3D cycle lasts several times the 1D tier's because the recovery is slow).
PaperCycle run_paper_cycle(const std::string& out, unsigned cores) {
  return run_cycle(out, cores, "paper_amplitude_0.55", {}, "paper_cycle", 60.0);
}

/// The paper's buckling wall on a fine grid: paper_aspect_L0.2 at `cells` across, seeded with the
/// mode its buckling estimate grows fastest (seed_mode = "auto": m = 8 lobes of 1e-2 R0, as the
/// buckling suite's paper_aspect_L0.2_seeded), into out/fine_cycle_N. Targets: 4 min at 96
/// cells, 12 min at 128 (none on other grids).
PaperCycle run_fine_cycle(const std::string& out, unsigned cores, int cells, const std::vector<std::string>& sets) {
  const double target = cells == 96 ? 240.0 : cells == 128 ? 720.0 : 0.0;
  std::vector<std::string> all = {"full3d.grid.cells_across=" + std::to_string(cells), "full3d.membrane.seed_mode=auto"};
  all.insert(all.end(), sets.begin(), sets.end());
  PaperCycle c = run_cycle(out, cores, "paper_aspect_L0.2", all, "fine_cycle_" + std::to_string(cells), target);
  c.sets = sets;
  return c;
}

void print_paper_cycle(const PaperCycle& c) {
  const full3d::RunOutcome& r = c.run;
  char target[64] = "";
  if (c.target_s > 0) std::snprintf(target, sizeof target, "; target: cycle in <= %.0f s", c.target_s);
  std::printf("  %s at t = %.3g s after %ld steps, displacement %.4g m, wall %.0f s (%.3g s/step%s)%s\n",
              c.done ? "cycle ended" : "cycle NOT ended", c.t_cycle, r.steps, r.summary.value("displacement_m", 0.0),
              c.wall_s, r.steps > 0 ? c.wall_s / double(r.steps) : 0.0, target,
              r.failed ? ("  FAILED: " + r.message).c_str() : "");
  const scene::json& ts = r.record.stats.value("time_step", scene::json::object());
  if (ts.contains("steps_by_bound"))
    std::printf("  steps by bound: %s; largest explicit rate %.0f /s\n", ts["steps_by_bound"].dump().c_str(),
                ts.value("explicit_rate_max_per_s", 0.0));
  std::string line;
  for (std::size_t i = 0; i < c.split.size() && i < 6; ++i) {
    char b[96];
    std::snprintf(b, sizeof b, "%s%s %.1f s", i ? ", " : "", c.split[i].second.c_str(), c.split[i].first);
    line += b;
  }
  if (!line.empty()) std::printf("  wall time: %s\n", line.c_str());
}

scene::json paper_cycle_json(const PaperCycle& c) {
  const full3d::Params3d& p = c.p;
  const auto& sm = c.run.summary;
  scene::json j = {{"scene", c.scene}, {"threads", c.threads},
                   {"grid", std::to_string(p.nx) + "x" + std::to_string(p.ny) + "x" + std::to_string(p.nz)},
                   {"adaptive_step", p.adaptive.enabled}, {"dt_s", p.dt},
                   {"steps_per_cycle", sm.value("steps_per_cycle", scene::json::array())},
                   {"cycle_completed", c.done}, {"cycle_end_s", c.t_cycle},
                   {"steps", c.run.steps}, {"wall_time_s", c.wall_s},
                   {"displacement_m", sm.value("displacement_m", 0.0)}, {"failed", c.run.failed},
                   {"time_step", c.run.record.stats.value("time_step", scene::json::object())},
                   {"wall_time_split_s", c.run.record.stats.value("wall_time_split_s", scene::json::object())}};
  if (c.target_s > 0) j["target_wall_time_s"] = c.target_s;
  if (!c.sets.empty()) j["scene_overrides"] = c.sets;
  return j;
}

/// The 3D part: time per coupled step on the demo scene (duct, paper's container size) at three
/// resolutions, split into its parts, against a bare FFT Stokes solve on the same grid, and
/// with 1 and 2 threads; then the paper's single cycle (minutes: full bench or --paper-cycle).
void bench_3d(scene::json& report, const std::string& out, bool quick, bool paper_cycle, unsigned cores,
              const std::vector<int>& fine_cycles, const std::vector<std::string>& fine_sets) {
  std::printf("== 3D tier ==\n");
  print_step_header();
  scene::json grids = scene::json::array();
  const int steps = quick ? 3 : 10;
  // the demo swimmer in the square duct at three resolutions, then in the paper's
  // cylinder at the default resolution
  const std::vector<std::pair<int, std::string>> configs = {{12, "duct"}, {20, "duct"}, {32, "duct"}, {32, "cylinder"}};
  for (const auto& [across, container] : configs) {
    double per_step_thr[3] = {0, 0, 0};
    for (int thr : {1, 2}) {
      const StepTiming t = time_steps(across, container, thr, steps);
      per_step_thr[thr] = t.step_s;
      print_steps(t);
      grids.push_back(steps_json(t));
    }
    std::printf("  %-14s 2-thread speedup %.2f\n", "", per_step_thr[1] / per_step_thr[2]);
  }
  report["full3d_step"] = grids;
  if (paper_cycle) {
    const PaperCycle c = run_paper_cycle(out, cores);
    print_paper_cycle(c);
    report["full3d_paper_cycle"] = paper_cycle_json(c);
  } else {
    std::printf("paper single-cycle scene: not run with --quick (swim bench, or --paper-cycle)\n");
  }
  for (int cells : fine_cycles) {
    const PaperCycle c = run_fine_cycle(out, cores, cells, fine_sets);
    print_paper_cycle(c);
    report["full3d_fine_cycle"].push_back(paper_cycle_json(c));
  }
}

// ---- axisymmetric tier ------------------------------------------------------------------------

/// One cycle of the axi tier's fitted method against one numeric factorisation of its system.
struct AxiCycle {
  int cells = 0, threads = 1;
  double h = 0;
  long unknowns = 0;
  double factor_cpu_s = 1e300;  ///< one factorisation, best of 3, CPU time
  axi::RunOutcomeAxi run;
  double wall_s = 0, cpu_s = 0;
  scene::json split;  ///< the run's wall_time_split_s
  double fact_s = 0, solves_s = 0;
  long factorisations = 0, gmres_iterations = 0, stokes_solves = 0;
};

/// One cycle of the round-wall amplitude scene (R_f = 0.82 R0, D fixed, the geometric recovery
/// end) with the fitted method at `cells` across on `threads` threads (axi.threads), at the
/// settings of the converged suite's reference of that case (the rings at half the default
/// spacing, axi.tolerance 1.25e-4: what its 32-cell grid needs to reach 1 % with the wall's and
/// the time integration's errors in its bars), into out/axi_cycle_<threads>t, against the
/// CPU time of one numeric factorisation of its fitted system (the unit of this method's cost:
/// a step factors or reuses, and solves three times; both in CPU time, so that the ratio holds
/// on a busy machine).
/// A shipped scene (data/scenes/<file>) with its wall held round as the converged suite holds it
/// (axisymmetric, the geometric recovery end, its bending rigidity fixed), then `sets`.
scene::json converged_round_wall(const std::string& file, const std::vector<std::string>& sets) {
  scene::json sc = scene::load_file(data_dir() + "/scenes/" + file);
  for (const char* set : {"full3d.membrane.axisymmetric=true", "full3d.recovery_end=\"shape\"",
                          "full3d.membrane.bending_rigidity=\"2.1184615504e-24 J\""})
    scene::apply_override(sc, set);
  for (const auto& set : sets) scene::apply_override(sc, set);
  return sc;
}

AxiCycle run_axi_cycle(const std::string& out, int cells, int threads) {
  const scene::json sc = converged_round_wall(
      "paper_amplitude_0.82.json", {"axi.spacing_factor=0.5", "axi.tolerance=1.25e-4",
                                    "axi.grid.cells_across=" + std::to_string(cells),
                                    "axi.threads=" + std::to_string(threads)});
  scene::json resolved;
  const axi::ParamsAxi p = axi::read_scene_axi(sc, resolved);
  AxiCycle c;
  c.cells = cells;
  c.threads = threads;
  c.h = p.h;
  // one factorisation of the system on the reference shape, best of 3
  {
    axi::FittedStokes fs(axi::fitted_mesh_params(p), p.base.fluid.mu, p.wall_nodes);
    const axi::AxiWall wall(axi::AxiWallParams{p.base.R0, p.base.L, p.ks, p.D, p.wall_nodes, p.ring_s0});
    Eigen::Matrix3Xd X = wall.reference();  // the reference shape, as the run starts
    X.row(0).array() += p.x_start();
    for (int rep = 0; rep < 3; ++rep) {  // CPU time: the ratio below is then immune to other jobs
      const double c0 = process_cpu_seconds();
      fs.factor(X, nullptr, 0.0, /*force=*/true);
      c.factor_cpu_s = std::min(c.factor_cpu_s, process_cpu_seconds() - c0);
    }
    c.unknowns = fs.unknowns();
  }
  const std::string dir = out + "/axi_cycle_" + std::to_string(threads) + "t";
  output::make_dir(dir);
  axi::RunControlAxi ctl;
  ctl.progress = 1;
  std::printf("one cycle of paper_amplitude_0.82, round wall, %d cells across (h = %.3g nm, %ld unknowns), %d thread%s ...\n",
              cells, 1e9 * p.h, c.unknowns, threads, threads > 1 ? "s" : "");
  std::fflush(stdout);
  const double c0 = process_cpu_seconds();
  const auto t0 = std::chrono::steady_clock::now();
  c.run = axi::run_axi(p, resolved, dir, ctl);
  c.wall_s = seconds_since(t0);
  c.cpu_s = process_cpu_seconds() - c0;
  c.split = c.run.record.stats.value("wall_time_split_s", scene::json::object());
  c.fact_s = c.split.value("factorisation", 0.0);
  c.solves_s = c.split.value("solves", 0.0);
  c.factorisations = c.split.value("factorisations", 0L);
  c.gmres_iterations = c.split.value("gmres_iterations", 0L);
  c.stokes_solves = c.run.record.stats.value("stokes_solves", 0L);
  return c;
}

void print_axi_cycle(const AxiCycle& c) {
  const axi::RunOutcomeAxi& r = c.run;
  std::printf("  %s: %ld steps, %ld solves, %ld factorisations, %ld GMRES iterations; wall %.0f s (CPU %.0f s), "
              "= %.0f factorisations of %.3g s (CPU); factorising %.0f %% of the wall time (%s), solving %.0f %% "
              "(target: <= 300 s per cycle on 2 cores)%s\n",
              r.failed ? "FAILED" : "cycle ended", r.steps, c.stokes_solves, c.factorisations, c.gmres_iterations,
              c.wall_s, c.cpu_s, c.cpu_s / c.factor_cpu_s, c.factor_cpu_s, 100 * c.fact_s / c.wall_s,
              c.threads > 1 ? "waiting for the second thread" : "on the stepping thread", 100 * c.solves_s / c.wall_s,
              r.failed ? ("  " + r.message).c_str() : "");
  std::printf("  preconditioner: %s; BLAS (UMFPACK's): %s\n",
              c.run.record.stats.value("preconditioner", std::string("?")).c_str(), axi::blas_provider().c_str());
}

scene::json axi_cycle_json(const AxiCycle& c) {
  const scene::json& sm = c.run.summary;
  return {{"scene", "paper_amplitude_0.82 (round wall, D fixed, recovery_end shape)"},
          {"cells_across", c.cells}, {"threads", c.threads}, {"h_m", c.h}, {"unknowns", c.unknowns}, {"steps", c.run.steps},
          {"stokes_solves", c.stokes_solves}, {"factorisations", c.factorisations},
          {"gmres_iterations", c.gmres_iterations}, {"wall_time_s", c.wall_s}, {"cpu_time_s", c.cpu_s},
          {"one_factorisation_cpu_s", c.factor_cpu_s}, {"cpu_over_factorisation", c.cpu_s / c.factor_cpu_s},
          {"wall_time_split_s", c.split}, {"blas", axi::blas_provider()},
          {"preconditioner", c.run.record.stats.value("preconditioner", scene::json())},
          {"factorisation_fallbacks", c.run.record.stats.value("factorisation_fallbacks", scene::json())},
          {"displacement_per_cycle_m", sm.value("displacement_per_cycle_m", scene::json())},
          {"cycle_times_s", sm.value("cycle_times_s", scene::json::array())}, {"failed", c.run.failed}};
}

/// One cycle of the round L = 0.8 um tube whose front rim hooks over the lumen, on the moved
/// triangulation (axi.mesh = triangles) at the converged suite's settings of its reference (rims
/// refined four times further, rings at half the default spacing, axi.tolerance 5e-4), two
/// threads, with its gap's triangles up to `gap_size` h (axi.gap_size), into
/// out/axi_hooked_gap<gap_size>.
struct AxiHooked {
  double gap_size = 1, wall_s = 0;
  long unknowns = 0, steps = 0;
  double displacement_m = 0, cycle_s = 0;
  bool failed = false;
};
AxiHooked run_axi_hooked(const std::string& out, int cells, double gap_size) {
  const scene::json sc = converged_round_wall(
      "paper_aspect_L0.8.json",
      {"protocol.pressure=\"0.5 Pa\"", "axi.mesh=\"triangles\"", "axi.spacing_factor=0.5", "axi.rim_refinement=0.25",
       "axi.tolerance=5e-4", "axi.time_limit=\"8 s\"", "axi.threads=2",
       "axi.grid.cells_across=" + std::to_string(cells), "axi.gap_size=" + std::to_string(gap_size)});
  scene::json resolved;
  const axi::ParamsAxi p = axi::read_scene_axi(sc, resolved);
  const std::string dir = out + "/axi_hooked_gap" + std::to_string(int(gap_size));
  output::make_dir(dir);
  axi::RunControlAxi ctl;
  ctl.progress = 1;
  std::printf("one cycle of paper_aspect_L0.8, round wall under 0.5 Pa, triangles, %d cells across (h = %.3g nm), "
              "axi.gap_size = %g, 2 threads ...\n",
              cells, 1e9 * p.h, gap_size);
  std::fflush(stdout);
  const auto t0 = std::chrono::steady_clock::now();
  const axi::RunOutcomeAxi r = axi::run_axi(p, resolved, dir, ctl);
  AxiHooked c;
  c.gap_size = gap_size;
  c.wall_s = seconds_since(t0);
  c.unknowns = r.record.stats.value("fitted_unknowns", 0L);
  c.steps = r.steps;
  c.displacement_m = r.summary.value("displacement_per_cycle_m", 0.0);
  c.cycle_s = r.summary.value("cycle_time_s", 0.0);
  c.failed = r.failed;
  std::printf("  %s: %ld steps, %ld unknowns (at the last mesh); wall %.0f s (target: <= 300 s per cycle on 2 cores); "
              "%.5g nm per cycle in %.6g s%s\n",
              r.failed ? "FAILED" : "cycle ended", c.steps, c.unknowns, c.wall_s, 1e9 * c.displacement_m, c.cycle_s,
              r.failed ? ("  " + r.message).c_str() : "");
  return c;
}

scene::json axi_hooked_json(const AxiHooked& c, int cells) {
  return {{"scene", "paper_aspect_L0.8 (round wall, 0.5 Pa, triangles, the converged suite's reference settings)"},
          {"cells_across", cells}, {"threads", 2}, {"gap_size", c.gap_size}, {"unknowns", c.unknowns},
          {"steps", c.steps}, {"wall_time_s", c.wall_s}, {"displacement_per_cycle_m", c.displacement_m},
          {"cycle_time_s", c.cycle_s}, {"failed", c.failed}};
}

/// The cycle on one thread and on two (axi.threads; the second factors the systems the first
/// solves), in one run: the ratio of their wall times is the measured gain of the second core.
/// Then the hooked tube on triangles with the gap's triangles at h and at the default
/// axi.gap_size: the ratio of their wall times is the gain of the larger triangles, the
/// differences of their figures what it costs.
void bench_axi(scene::json& report, const std::string& out, int cells) {
  std::printf("== axisymmetric tier (fitted) ==\n");
  const AxiCycle one = run_axi_cycle(out, cells, 1);
  print_axi_cycle(one);
  const AxiCycle two = run_axi_cycle(out, cells, 2);
  print_axi_cycle(two);
  const double d1 = one.run.summary.value("displacement_per_cycle_m", 0.0),
               d2 = two.run.summary.value("displacement_per_cycle_m", 0.0);
  std::printf("  2 threads against 1: %.2f times faster in wall time, %.2f times the CPU time; displacement per "
              "cycle %.7g nm against %.7g nm\n",
              one.wall_s / two.wall_s, two.cpu_s / one.cpu_s, 1e9 * d2, 1e9 * d1);
  report["axi_cycle"] = axi_cycle_json(two);
  report["axi_cycle"]["one_thread"] = axi_cycle_json(one);
  report["axi_cycle"]["wall_time_one_over_two_threads"] = one.wall_s / two.wall_s;
  const int hooked_cells = cells <= 16 ? 16 : 24;
  const AxiHooked uniform = run_axi_hooked(out, hooked_cells, 1.0);
  const AxiHooked graded = run_axi_hooked(out, hooked_cells, axi::kGapSize);
  const double dd = graded.displacement_m / uniform.displacement_m - 1, dt = graded.cycle_s / uniform.cycle_s - 1;
  std::printf("  axi.gap_size %g against 1: %.2f times faster, %.2f times the unknowns; displacement per cycle %+.3f %%, "
              "cycle time %+.3f %%\n",
              axi::kGapSize, uniform.wall_s / graded.wall_s, double(graded.unknowns) / double(uniform.unknowns), 100 * dd,
              100 * dt);
  report["axi_hooked"] = axi_hooked_json(graded, hooked_cells);
  report["axi_hooked"]["gap_size_1"] = axi_hooked_json(uniform, hooked_cells);
  report["axi_hooked"]["wall_time_uniform_over_graded"] = uniform.wall_s / graded.wall_s;
}

}  // namespace

int bench(const std::string& out_opt, bool quick, bool paper_cycle_opt, const std::string& tier,
          const std::vector<int>& fine_cycles, const std::vector<std::string>& fine_sets) {
  for (int n : fine_cycles)
    if (n < 8 || n > 512 || n % 2)
      throw InputError("--fine-cycle", std::to_string(n), "an even number of cells across from 8 to 512");
  if (!fine_sets.empty() && fine_cycles.empty())
    throw InputError("--fine-cycle-set", fine_sets.front(), "overrides of the --fine-cycle runs: give --fine-cycle N too");
  if (!fine_sets.empty()) {  // the overrides must make a valid scene before anything runs or is written
    scene::json sc = scene::load_file(data_dir() + "/scenes/paper_aspect_L0.2.json");
    for (const auto& s : fine_sets) scene::apply_override(sc, s);
    scene::apply_override(sc, "full3d.grid.cells_across=" + std::to_string(fine_cycles.front()));
    scene::json resolved;
    (void)full3d::read_scene3d(sc, resolved);
  }
  if (!fine_cycles.empty() && tier != "3d" && tier != "all")
    throw InputError("--fine-cycle", std::to_string(fine_cycles.front()), "a 3D figure: with --tier 3d or all");
  const bool do1d = tier == "1d" || tier == "all", do3d = tier == "3d" || tier == "all";
  const bool do_axi = tier == "axi" || tier == "all";
  const bool paper_cycle = do3d && (paper_cycle_opt || !quick);
  const std::string out = out_opt.empty() ? "out/bench" : out_opt;
  output::make_dir(out);
  scene::json report = scene::json::object();
  const int reps = quick ? 1 : 5;
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  report["hardware_threads"] = cores;
  if (do1d) bench_1d(report, quick, reps, cores);
  if (do3d) bench_3d(report, out, quick, paper_cycle, cores, fine_cycles, fine_sets);
  if (do_axi) bench_axi(report, out, quick ? 16 : 32);
  output::write_json(out + "/bench.json", report);
  std::printf("  -> %s/bench.json\n", out.c_str());
  return 0;
}

}  // namespace swim::app
