#include "reduced1d/screen.hpp"

#include <atomic>
#include <cmath>
#include <limits>
#include <chrono>
#include <mutex>
#include <stdexcept>
#include <thread>

namespace swim::reduced1d {

DesignOutcome run_design(const Params& design) {
  const auto t0 = std::chrono::steady_clock::now();
  DesignOutcome o;
  try {
    SolveOptions so;
    so.keep_samples = false;  // the metrics come from the record's running figures
    // A screen runs its designs one per thread: none takes a second for its samples.
    Params one = design;
    one.numerics.threads = 1;
    const Result r = solve(one, so);
    o.metrics = metrics(design, r);
    o.ok = !r.failure;
    if (r.failure) o.message = r.failure->what();
  } catch (const std::exception& e) {
    o.ok = false;
    o.message = e.what();
  }
  o.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return o;
}

namespace {
// non-finite numbers have no JSON form: they travel as strings
scene::json num(double v) {
  if (std::isfinite(v)) return v;
  return std::isnan(v) ? "nan" : (v > 0 ? "inf" : "-inf");
}
double num(const scene::json& j) {
  if (j.is_number()) return j.get<double>();
  const std::string s = j.get<std::string>();
  return s == "nan" ? std::numeric_limits<double>::quiet_NaN()
                    : (s == "inf" ? std::numeric_limits<double>::infinity() : -std::numeric_limits<double>::infinity());
}
scene::json nums(const std::vector<double>& v) {
  scene::json a = scene::json::array();
  for (double x : v) a.push_back(num(x));
  return a;
}
std::vector<double> nums(const scene::json& a) {
  std::vector<double> v;
  for (const auto& x : a) v.push_back(num(x));
  return v;
}
}  // namespace

scene::json outcome_to_json(const DesignOutcome& o) {
  const Metrics& m = o.metrics;
  return {{"ok", o.ok},
          {"message", o.message},
          {"wall_time_s", o.wall_time_s},
          {"metrics",
           {{"t_end_s", num(m.t_end_s)},
            {"displacement_m", num(m.displacement_m)},
            {"max_displacement_m", num(m.max_displacement_m)},
            {"mean_velocity_m_per_s", num(m.mean_velocity_m_per_s)},
            {"body_lengths_per_s", num(m.body_lengths_per_s)},
            {"final_velocity_m_per_s", num(m.final_velocity_m_per_s)},
            {"max_velocity_m_per_s", num(m.max_velocity_m_per_s)},
            {"pumped_volume_m3", num(m.pumped_volume_m3)},
            {"cycles_completed", m.cycles_completed},
            {"cycle_times_s", nums(m.cycle_times_s)},
            {"mean_cycle_time_s", num(m.mean_cycle_time_s)},
            {"min_radius_m", num(m.min_radius_m)},
            {"switches", m.switches},
            {"cycle_displacements_m", nums(m.cycle_displacements_m)},
            {"displacement_per_cycle_m", num(m.displacement_per_cycle_m)},
            {"mean_velocity_per_cycle_m_per_s", num(m.mean_velocity_per_cycle_m_per_s)},
            {"has_cycle", m.has_cycle},
            {"no_cycle_reason", m.no_cycle_reason},
            {"pumped_volume_lab_m3", num(m.pumped_volume_lab_m3)},
            {"drag_coefficient_N_s_per_m", num(m.drag_coefficient_N_s_per_m)},
            {"thermal_rms_displacement_m", num(m.thermal_rms_displacement_m)},
            {"directed_to_diffusive", num(m.directed_to_diffusive)},
            {"implausible", m.implausible}}}};
}

DesignOutcome outcome_from_json(const scene::json& j) {
  DesignOutcome o;
  o.ok = j.at("ok").get<bool>();
  o.message = j.at("message").get<std::string>();
  o.wall_time_s = j.at("wall_time_s").get<double>();
  const scene::json& x = j.at("metrics");
  Metrics& m = o.metrics;
  m.t_end_s = num(x.at("t_end_s"));
  m.displacement_m = num(x.at("displacement_m"));
  m.max_displacement_m = num(x.at("max_displacement_m"));
  m.mean_velocity_m_per_s = num(x.at("mean_velocity_m_per_s"));
  m.body_lengths_per_s = num(x.at("body_lengths_per_s"));
  m.final_velocity_m_per_s = num(x.at("final_velocity_m_per_s"));
  m.max_velocity_m_per_s = num(x.at("max_velocity_m_per_s"));
  m.pumped_volume_m3 = num(x.at("pumped_volume_m3"));
  m.cycles_completed = x.at("cycles_completed").get<int>();
  m.cycle_times_s = nums(x.at("cycle_times_s"));
  m.mean_cycle_time_s = num(x.at("mean_cycle_time_s"));
  m.min_radius_m = num(x.at("min_radius_m"));
  m.switches = x.at("switches").get<long>();
  m.cycle_displacements_m = nums(x.at("cycle_displacements_m"));
  m.displacement_per_cycle_m = num(x.at("displacement_per_cycle_m"));
  m.mean_velocity_per_cycle_m_per_s = num(x.at("mean_velocity_per_cycle_m_per_s"));
  m.has_cycle = x.at("has_cycle").get<bool>();
  m.no_cycle_reason = x.at("no_cycle_reason").get<std::string>();
  m.pumped_volume_lab_m3 = num(x.at("pumped_volume_lab_m3"));
  m.drag_coefficient_N_s_per_m = num(x.at("drag_coefficient_N_s_per_m"));
  m.thermal_rms_displacement_m = num(x.at("thermal_rms_displacement_m"));
  m.directed_to_diffusive = num(x.at("directed_to_diffusive"));
  m.implausible = x.at("implausible").get<std::vector<std::string>>();
  return o;
}

std::vector<DesignOutcome> run_designs(const std::vector<Params>& designs, int jobs,
                                       const std::function<void(size_t)>& on_done) {
  std::vector<DesignOutcome> out(designs.size());
  if (jobs <= 0) jobs = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  jobs = static_cast<int>(std::min<size_t>(static_cast<size_t>(jobs), std::max<size_t>(1, designs.size())));
  std::atomic<size_t> next{0};
  std::mutex done_mutex;
  auto worker = [&] {
    for (size_t k = next++; k < designs.size(); k = next++) {
      out[k] = run_design(designs[k]);
      if (on_done) {
        std::lock_guard lock(done_mutex);
        on_done(k);
      }
    }
  };
  std::vector<std::thread> pool;
  for (int j = 1; j < jobs; ++j) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  return out;
}

const std::vector<std::string>& metric_names() {
  static const std::vector<std::string> names = {
      "displacement_m",      "mean_velocity_m_per_s", "body_lengths_per_s", "pumped_volume_m3",
      "max_velocity_m_per_s", "final_velocity_m_per_s", "mean_cycle_time_s", "displacement_per_cycle_m",
      "mean_velocity_per_cycle_m_per_s", "directed_to_diffusive_ratio"};
  return names;
}

std::string metric_unit(const std::string& name) {
  auto ends = [&](const std::string& suffix) {
    return name.size() >= suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0;
  };
  if (name == "body_lengths_per_s") return "body lengths/s";
  if (ends("_m_per_s")) return "m/s";
  if (ends("_m3")) return "m^3";
  if (ends("_m")) return "m";
  if (ends("_s")) return "s";
  return "";
}

double metric_value(const Metrics& m, const std::string& name) {
  if (name == "displacement_m") return m.displacement_m;
  if (name == "mean_velocity_m_per_s") return m.mean_velocity_m_per_s;
  if (name == "body_lengths_per_s") return m.body_lengths_per_s;
  if (name == "pumped_volume_m3") return m.pumped_volume_m3;
  if (name == "max_velocity_m_per_s") return m.max_velocity_m_per_s;
  if (name == "final_velocity_m_per_s") return m.final_velocity_m_per_s;
  if (name == "mean_cycle_time_s") return m.mean_cycle_time_s;
  if (name == "displacement_per_cycle_m") return m.displacement_per_cycle_m;
  if (name == "mean_velocity_per_cycle_m_per_s") return m.mean_velocity_per_cycle_m_per_s;
  if (name == "directed_to_diffusive_ratio") return m.directed_to_diffusive;
  throw std::logic_error("unknown metric " + name);
}

}  // namespace swim::reduced1d
