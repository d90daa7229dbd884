// Design screening with the 1D tier: many independent runs spread over worker threads.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "reduced1d/params.hpp"
#include "reduced1d/report.hpp"

namespace swim::reduced1d {

struct DesignOutcome {
  bool ok = false;
  std::string message;  ///< failure message when !ok
  Metrics metrics;
  double wall_time_s = 0;
};

/// Run one design (the unit of run_designs).
DesignOutcome run_design(const Params& design);

/// A design's outcome as JSON and back, exactly (every double round-trips): how the ranks of
/// an MPI screen send it to rank 0 (app/ranks.hpp).
scene::json outcome_to_json(const DesignOutcome& o);
DesignOutcome outcome_from_json(const scene::json& j);

/// Run every design, `jobs` at a time (jobs <= 0: one per hardware thread).
/// `on_done(k)` is called (from a worker, serialised) after design k finishes.
std::vector<DesignOutcome> run_designs(const std::vector<Params>& designs, int jobs,
                                       const std::function<void(size_t)>& on_done = {});

/// Metric names a sweep may rank designs by.
const std::vector<std::string>& metric_names();
/// Unit of a metric for printouts ("m/s", "m", "m^3", "s", "body lengths/s"; "" if none).
std::string metric_unit(const std::string& name);
double metric_value(const Metrics& m, const std::string& name);

}  // namespace swim::reduced1d
