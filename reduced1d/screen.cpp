#include "reduced1d/screen.hpp"

#include <atomic>
#include <chrono>
#include <mutex>
#include <stdexcept>
#include <thread>

namespace swim::reduced1d {

std::vector<DesignOutcome> run_designs(const std::vector<Params>& designs, int jobs,
                                       const std::function<void(size_t)>& on_done) {
  std::vector<DesignOutcome> out(designs.size());
  if (jobs <= 0) jobs = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  jobs = static_cast<int>(std::min<size_t>(static_cast<size_t>(jobs), std::max<size_t>(1, designs.size())));
  std::atomic<size_t> next{0};
  std::mutex done_mutex;
  auto worker = [&] {
    for (size_t k = next++; k < designs.size(); k = next++) {
      const auto t0 = std::chrono::steady_clock::now();
      DesignOutcome& o = out[k];
      try {
        SolveOptions so;
        so.keep_samples = false;  // the metrics come from the record's running figures
        const Result r = solve(designs[k], so);
        o.metrics = metrics(designs[k], r);
        o.ok = !r.failure;
        if (r.failure) o.message = r.failure->what();
      } catch (const std::exception& e) {
        o.ok = false;
        o.message = e.what();
      }
      o.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
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
