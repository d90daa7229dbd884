#include "app/scene_checks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "axi/scene_axi.hpp"
#include "common/errors.hpp"
#include "common/scene_shared.hpp"
#include "full3d/scene3d_keys.hpp"
#include "reduced1d/scene1d.hpp"
#include "reduced1d/scene1d_keys.hpp"
#include "reduced1d/solver.hpp"

namespace swim::app {

namespace {
// Bytes per value of a CSV file ("%.10g" and a separator).
constexpr double kCsvValue = 17.0;
// Bytes per value of a VTK frame: a Float32 or Int32, base64-encoded (4/3), before zlib; the
// compression only lowers it (by about 3.5 on membrane frames, depending on the data), and
// zlib's worst-case expansion on incompressible blocks (0.03 % and a few bytes) is in the 1 %.
constexpr double kVtkValue = 4.0 * 4.0 / 3.0 * 1.01;

std::string human(double bytes) {
  char b[48];
  if (bytes >= 1e9) std::snprintf(b, sizeof b, "%.3g GB", bytes / 1e9);
  else if (bytes >= 1e6) std::snprintf(b, sizeof b, "%.3g MB", bytes / 1e6);
  else std::snprintf(b, sizeof b, "%.3g kB", bytes / 1e3);
  return b;
}
}  // namespace

void check_other_tier(const scene::json& sc, const std::string& tier) {
  if (!sc.is_object()) return;
  if (tier != "axi" && sc.contains("axi")) scene::check_section(sc.at("axi"), "axi", axi::section_keys().at("axi"));
  if (tier == "1d") {
    if (sc.contains("full3d")) scene::check_section(sc.at("full3d"), "full3d", full3d::section_keys());
    return;
  }
  const scene::json& keys = reduced1d::section_keys();
  for (auto it = keys.begin(); it != keys.end(); ++it)
    if (sc.contains(it.key())) scene::check_section(sc.at(it.key()), it.key(), it.value());
  // one scene, one validation: the values of the 1D tier's own sections are read by its reader
  // (cheap) as in a 1D run; a refusal of one of them refuses the scene here too
  try {
    scene::json resolved;
    reduced1d::read_scene(sc, resolved);
  } catch (const InputError& e) {
    for (auto it = keys.begin(); it != keys.end(); ++it)
      if (e.key() == it.key() || e.key().rfind(it.key() + ".", 0) == 0) throw;
  }
}

void check_sweep_scenes(const sweep::Sweep& sw) {
  check_other_tier(sw.base, "1d");
  for (const auto& a : sw.axes) {
    // only an axis into those sections can change them
    const std::string section = a.key.substr(0, a.key.find('.'));
    if (section != "full3d" && section != "axi") continue;
    for (const auto& v : a.values) {
      scene::json sc = sw.base;
      try {
        scene::apply_override(sc, a.key + "=" + v.dump());
        check_other_tier(sc, "1d");
      } catch (const InputError& e) {
        throw InputError("vary." + a.key, scene::show(v), std::string("a value swim run --set accepts: ") + e.what());
      }
    }
  }
}

namespace {
// Bytes of one 1D output sample: a row of series.csv (19 columns) and a radius snapshot (three
// values per cell).
double bytes_per_sample(const reduced1d::Params& p) { return (19.0 + 3.0 * p.numerics.cells) * kCsvValue; }
// Bytes of the samples of a 1D run over `span` seconds.
double sample_bytes(const reduced1d::Params& p, double span) {
  return (std::floor(span / p.numerics.output_interval) + 2.0) * bytes_per_sample(p);
}
}  // namespace

OutputEstimate estimate_output(const reduced1d::Params& p) {
  // The span is known for a given duration and for a prescribed wave (its transit time);
  // a force-driven run with duration "auto" lasts until its cycles complete, which is only
  // known when it ends (end_time() is a loose upper bound): no estimate.
  if (!(p.duration > 0) && p.wave == reduced1d::WaveKind::ForceDriven) return {0.0, "time.duration"};
  return {sample_bytes(p, reduced1d::end_time(p)), "time.output_interval"};
}

void check_auto_run_output(const reduced1d::Params& p, const scene::json& sc) {
  if (p.duration > 0 || p.wave != reduced1d::WaveKind::ForceDriven) return;
  const auto limit = static_cast<double>(scene::output_limits(sc).max_bytes);
  const double dt = p.numerics.output_interval;
  const double per_sample = bytes_per_sample(p);
  // the end-time bound (5 relaxation times and more per cycle, far above a cycle as a rule):
  // when even its output fits, no run is needed to know
  if (sample_bytes(p, reduced1d::end_time(p)) <= limit) return;
  const double samples = std::floor(limit / per_sample) - 2.0;
  const double t_budget = std::max(0.0, samples) * dt;
  struct BudgetReached {
    double t;
  };
  reduced1d::Params q = p;
  q.numerics.threads = 1;  // the progress callback throws: on the integrating thread
  // samples only as often as the check needs them (the integration does not depend on them),
  // on the default model's converged grid (its cycle within 0.5 % of N = 400's) when the
  // scene's is finer: the check costs about one cycle of the screening's
  q.numerics.output_interval = std::max(dt, t_budget / 256.0);
  q.numerics.cells = std::min(q.numerics.cells, 50);
  reduced1d::SolveOptions so;
  so.keep_samples = false;
  so.progress = [&](double t, double) {
    if (t > t_budget) throw BudgetReached{t};
  };
  try {
    (void)reduced1d::solve(q, so);  // a numerical failure is the run's own: it runs and reports it
  } catch (const BudgetReached& b) {
    throw InputError("time.output_interval", scene::format_quantity(dt, "s"),
                     "an interval at which the run's output fits output.max_bytes = " +
                         std::to_string(static_cast<long long>(limit)) +
                         " bytes: this force-driven run lasts until its cycles complete, and integrated without "
                         "output it had not completed them by t = " + scene::format_quantity(b.t, "s") +
                         ", where its series and radius samples (about " + human(per_sample) +
                         " each) reach the limit; raise time.output_interval, set time.duration, or raise "
                         "output.max_bytes");
  }
}

OutputEstimate estimate_output(const full3d::Params3d& p) {
  // duration "auto": the run ends with its cycles, far below the full3d.time_limit cap as a
  // rule; the span is unknown before the run, so there is no estimate
  if (!(p.duration > 0)) return {0.0, "time.duration"};
  const double span = p.duration;
  const auto frames = [&](double interval) { return std::floor(span / std::max(interval, p.dt)) + 2; };
  // mesh size as the reference mesh (make_mesh): rings of n_theta nodes, edges below factor h/2
  const double edge = p.spacing_factor * 0.5 * p.h;
  const double n_theta = std::max(3.0, std::ceil(2.0 * M_PI * p.R0 / edge));
  const double rings = std::max(2.0, std::ceil(p.L / edge) + 1);
  const double nodes = n_theta * rings;
  const double samples = frames(p.output_interval) * (21 + 3 * rings) * kCsvValue;
  // membrane frames: 13 values per node (points and point data), about two triangles per node
  // of four Int32 each (connectivity and offsets); fluid frames: four values per cell
  const double vtk = p.vtk ? frames(p.vtk_interval) * nodes * (13 + 2 * 4) * kVtkValue : 0.0;
  const double cells = double(p.nx) * p.ny * p.nz;
  const double fluid = p.fluid_fields ? frames(p.fluid_interval) * cells * 4 * kVtkValue : 0.0;
  OutputEstimate e{samples + vtk + fluid, "time.output_interval"};
  if (vtk > samples && vtk >= fluid) e.key = "full3d.output.vtk_interval";
  if (fluid > samples && fluid > vtk) e.key = "full3d.output.fluid_interval";
  return e;
}

void check_output_size(const OutputEstimate& e, const scene::json& sc) {
  const scene::OutputLimits lim = scene::output_limits(sc);
  if (e.bytes > static_cast<double>(lim.max_bytes))
    throw InputError(e.key, "",
                     "the run would write about " + human(e.bytes) + ", above output.max_bytes = " +
                         std::to_string(lim.max_bytes) + " bytes; raise the interval, shorten time.duration, or raise "
                         "output.max_bytes");
}

}  // namespace swim::app
