// swim: command line of the peristaltic micro-swimmer suite (product contract in README.md).
//
//   swim run SCENE.json [--tier 1d|3d|axi] [--out DIR] [--set key.path=value ...] [--plot] [--resume DIR] [--overwrite] [--threads N]
//                       [--error-estimate]
//   swim screen SWEEP.json [--out DIR] [--jobs N] [--overwrite] [--confirm K] [--threads N] [--grid-check TOL]
//   swim optimize SPEC.json [--out DIR] [--overwrite] [--no-confirm] [--threads N]
//   swim bench [--out DIR] [--quick] [--paper-cycle] [--fine-cycle N ...] [--fine-cycle-set K=V ...]
//              [--tier 1d|3d|axi|all]
//   swim scenes
//   swim demo [--out DIR]
//   swim calibrate SCENE.json [--out DIR] [--set key.path=value ...] [--wet] [--tube-law] [--overwrite] [--threads N] [--progress|--quiet]
//   swim validate [SUITE.json] [--out DIR] [--quick] [--threads N] [--case NAME ...]
//   swim --version
//
// Exit codes: 0 success, 2 bad input (nothing written), 3 numerical failure or a result
// file that could not be written (partial results kept, marked failed), 1 anything
// unexpected.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <functional>

#include "app/app.hpp"
#include "app/ranks.hpp"
#include "common/errors.hpp"
#include "common/version.hpp"

int main(int argc, char** argv) {
  using namespace swim;
  // mpirun -n N swim …: rank 0 runs the command, the other ranks serve its runs (docs/mpi.md)
  app::ranks::Session mpi(&argc, &argv);
  if (const std::string why = app::ranks::unsupported_launch(); !why.empty()) {
    std::fprintf(stderr, "swim: %s\n", why.c_str());
    return 2;
  }
  if (app::ranks::rank() > 0) return app::ranks::serve(app::run_task);
  // named "swim" in the help, whatever path started it (a symlink, build/bin/swim)
  CLI::App cli{"swim: design and check peristaltic elastic micro-swimmers (1D lubrication and 3D immersed-boundary tiers)",
               "swim"};
  cli.require_subcommand(1);
  cli.set_help_all_flag("--help-all", "Help for every subcommand");
  cli.set_version_flag("--version", std::string("swim ") + version(), "Print the version and exit");

  app::RunOptions ro;
  bool progress_on = false, progress_off = false;
  auto add_progress = [&](CLI::App* c) {
    c->add_flag("--progress", progress_on, "Show progress on stderr even when it is not a terminal");
    c->add_flag("--quiet", progress_off, "Never show progress");
  };

  CLI::App* run = cli.add_subcommand("run", "Run one scene on one tier");
  run->add_option("scene", ro.scene, "Scene file (JSON with unit strings)")->required();
  run->add_option("--tier", ro.tier, "Model tier: 1d (default; the force-free lubrication model, milliseconds to a second), 3d (immersed boundary, minutes) or axi (the axisymmetric reference of round-wall scenes)")->check(CLI::IsMember({"1d", "3d", "axi"}));
  run->add_option("--out", ro.out, "Output directory (default out/<scene name>-<tier>)");
  run->add_option("--set", ro.sets, "Override a scene value: key.path=value (same unit syntax as the file)");
  run->add_flag("--plot", ro.plot, "Also write plots (PNG) of the run");
  run->add_option("--resume", ro.resume, "3D and axi: continue an interrupted run from the checkpoint in this output folder");
  run->add_flag("--overwrite", ro.overwrite,
                "Replace the results of another run in the output folder (its files are removed first)");
  run->add_option("--threads", ro.threads, "Threads of the run: 3D sets full3d.threads (default the scene's, 1); axi sets axi.threads (1 or 2, default 2); 1D sets numerics1d.threads (1 or 2, default 1: the second evaluates the output samples)")
      ->check(CLI::Range(1, 256));
  run->add_flag("--error-estimate", ro.error_estimate,
                "3D: also run the scene on a coarser grid (3/4 of the cells across, in OUT/error_estimate/coarse) and "
                "report the run's discretisation error in summary.json (error_estimate)");
  add_progress(run);

  std::string out;
  CLI::App* demo = cli.add_subcommand("demo", "Run the default scene and plot it");
  demo->add_option("--out", out, "Output directory (default out/demo)");
  add_progress(demo);

  std::string sweep;
  int jobs = 0;
  CLI::App* scr = cli.add_subcommand("screen", "Run a 1D design sweep in parallel and rank the designs");
  scr->add_option("sweep", sweep, "Sweep file (JSON)")->required();
  scr->add_option("--out", out, "Output directory (default out/screen-<sweep name>)");
  scr->add_option("--jobs", jobs, "Worker threads (default: all cores; under mpirun each rank runs one design at a time)")->check(CLI::Range(0, 1024));
  int scr_confirm = 0, threads3d = 1;
  scr->add_option("--confirm", scr_confirm,
                  "Also run K designs in 3D (the K/2 best and K/2 spread over the rest) and report the rank agreement")
      ->check(CLI::Range(0, 100000));
  scr->add_option("--threads", threads3d, "Threads of each 3D run (default 1)")->check(CLI::Range(1, 1024));
  double scr_grid_check = 0;
  scr->add_option("--grid-check", scr_grid_check,
                  "Also run every design on twice its cells (numerics1d.cells) and report the metric's relative change "
                  "per design, the designs whose change exceeds this tolerance (e.g. 0.05) and whether the ranking holds")
      ->check(CLI::Range(0.0, 1.0));
  bool scr_overwrite = false;
  scr->add_flag("--overwrite", scr_overwrite, "Replace another run's results in the output folder (its files are removed first)");
  add_progress(scr);

  CLI::App* opt = cli.add_subcommand("optimize", "Search the best design on the 1D tier (NLopt COBYLA) and confirm it in 3D");
  std::string opt_spec;
  bool opt_overwrite = false, opt_no_confirm = false;
  opt->add_option("spec", opt_spec, "Optimisation spec (JSON: base scene, parameters with bounds, objective, constraints)")
      ->required();
  opt->add_option("--out", out, "Output directory (default out/optimize-<spec name>)");
  opt->add_option("--threads", threads3d, "Threads of the 3D confirmation run (default 1)")->check(CLI::Range(1, 1024));
  opt->add_flag("--no-confirm", opt_no_confirm, "Do not run the best design in 3D");
  opt->add_flag("--overwrite", opt_overwrite, "Replace another run's results in the output folder (its files are removed first)");
  add_progress(opt);

  bool quick = false;
  CLI::App* ben = cli.add_subcommand("bench", "Measure performance figures");
  ben->add_option("--out", out, "Output directory (default out/bench)");
  ben->add_flag("--quick", quick, "Fewer repetitions (a smoke run); skips the paper-cycle run");
  bool paper_cycle = false;
  std::string bench_tier = "all";
  ben->add_option("--tier", bench_tier, "Measure only one tier: 1d, 3d, axi or all (default)")
      ->check(CLI::IsMember({"1d", "3d", "axi", "all"}));
  ben->add_flag("--paper-cycle", paper_cycle,
                "Also run the paper's single-cycle 3D scene end to end with --quick (minutes)");
  std::vector<int> fine_cycles;
  ben->add_option("--fine-cycle", fine_cycles,
                  "Also run one cycle of the paper's buckling wall (paper_aspect_L0.2, seeded) at N cells across "
                  "(targets: 4 min at 96, 12 min at 128); repeatable");
  std::vector<std::string> fine_sets;
  ben->add_option("--fine-cycle-set", fine_sets,
                  "Override a scene value of the --fine-cycle runs: key.path=value (e.g. "
                  "full3d.wall_stabilization=bending); repeatable");

  CLI::App* sc = cli.add_subcommand("scenes", "List the shipped scenes");

  CLI::App* cal = cli.add_subcommand("calibrate", "Fit the 1D wall stiffness C1 from 3D uniform-load runs");
  std::string cal_scene, cal_out;
  std::vector<std::string> cal_sets;
  cal->add_option("scene", cal_scene, "Scene file (JSON)")->required();
  cal->add_option("--out", cal_out, "Output directory (default out/<name>-calibration)");
  cal->add_option("--set", cal_sets, "Override a scene value: key.path=value");
  bool cal_wet = false;
  bool cal_overwrite = false;
  cal->add_flag("--overwrite", cal_overwrite,
                "Replace another run's results in the output folder (its files are removed first)");
  int cal_threads = 0;
  cal->add_option("--threads", cal_threads, "Threads of the 3D runs (sets full3d.threads; default: the scene's, 1)")
      ->check(CLI::Range(1, 256));
  cal->add_flag("--wet", cal_wet, "Also confirm the largest fitted load with a fluid-coupled 3D run, the wall held axisymmetric as in the static path (up to 4 000 steps: minutes)");
  bool cal_law = false;
  cal->add_flag("--tube-law", cal_law,
                "Also measure the whole static tube law P(R) down to 0.3 R0 on the round and the buckled branch "
                "(docs/tube-law.md; minutes at the default grid)");
  add_progress(cal);
  CLI::App* val = cli.add_subcommand("validate", "Run the 1D-vs-3D validation suite and write its report");
  std::string val_suite, val_out;
  bool val_quick = false;
  int val_threads = 2;
  val->add_option("suite", val_suite, "Suite file (default: data/validation/default.json, or quick.json with --quick)");
  val->add_flag("--quick", val_quick, "The reduced suite (small grids, minutes)");
  val->add_option("--out", val_out, "Output directory (default out/validation-<suite name>); completed runs in it are reused");
  val->add_option("--threads", val_threads, "Threads of the 3D runs and calibrations (default 2)");
  std::vector<std::string> val_cases;
  val->add_option("--case", val_cases, "Run only this case (its scene file name, or the case's own name); repeatable");
  add_progress(val);

  // a mistyped subcommand is named as such (CLI11 alone would say "arguments were not expected")
  if (argc > 1 && argv[1][0] != '-') {
    std::string names;
    bool known = false;
    for (const CLI::App* c : cli.get_subcommands(std::function<bool(CLI::App*)>())) {
      known = known || c->get_name() == argv[1];
      names += (names.empty() ? "" : ", ") + c->get_name();
    }
    if (!known) {
      std::fprintf(stderr, "swim: invalid input: unknown subcommand %s; one of %s (run 'swim --help' for usage)\n",
                   argv[1], names.c_str());
      return 2;
    }
  }
  try {
    cli.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return cli.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return cli.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return cli.exit(e);
  } catch (const CLI::ParseError& e) {
    // one message, one line, as every other refusal
    std::string m = e.what();
    for (char& ch : m)
      if (ch == '\n' || ch == '\r') ch = ' ';
    while (!m.empty() && m.back() == ' ') m.pop_back();
    std::fprintf(stderr, "swim: invalid input: %s (run 'swim --help' for usage)\n", m.c_str());
    return 2;
  }
  // a folder flag given an empty value is a mistake, not "the default folder"
  for (CLI::App* c : {run, demo, scr, ben, cal, val})
    for (const char* flag : {"--out", "--resume"})
      if (*c && c->get_option_no_throw(flag) && c->get_option(flag)->count() > 0 &&
          c->get_option(flag)->as<std::string>().empty()) {
        std::fprintf(stderr, "swim: invalid input: key '%s' = \"\": a folder name (leave the flag out for the default)\n", flag);
        return 2;
      }
  const int progress = progress_off ? 0 : progress_on ? 1 : -1;
  try {
    if (*run) {
      ro.progress = progress;
      return app::run(ro);
    }
    if (*demo) return app::demo(out, progress);
    if (*scr) return app::screen(sweep, out, jobs, progress, scr_overwrite, scr_confirm, threads3d, scr_grid_check);
    if (*opt) return app::optimize(opt_spec, out, progress, opt_overwrite, !opt_no_confirm, threads3d);
    if (*ben) return app::bench(out, quick, paper_cycle, bench_tier, fine_cycles, fine_sets);
    if (*sc) return app::scenes();
    if (*cal) return app::calibrate(cal_scene, cal_sets, cal_out, cal_wet, cal_overwrite, cal_threads, cal_law, progress);
    if (*val) return app::validate(val_suite, val_quick, val_out, val_threads, progress, val_cases);
  } catch (const app::Interrupted& e) {
    std::fprintf(stderr, "swim: %s; the child process was stopped and nothing runs on\n", e.what());
    return 128 + e.signal();
  } catch (const InputError& e) {
    std::fprintf(stderr, "swim: %s\n", e.what());
    return 2;
  } catch (const NumericalError& e) {
    std::fprintf(stderr, "swim: %s\n", e.what());
    return 3;
  } catch (const OutputError& e) {
    std::fprintf(stderr, "swim: %s\n", e.what());
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "swim: internal error: %s\n", e.what());
    return 1;
  }
  return 0;
}
