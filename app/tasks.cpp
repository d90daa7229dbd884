// The independent runs that the ranks of an MPI command carry out (app/ranks.hpp): one JSON
// payload in, one JSON result out, each exactly what the single-process command computes.
#include <filesystem>
#include <stdexcept>

#include "app/app.hpp"
#include "app/ranks.hpp"
#include "common/progress.hpp"
#include "design/confirm.hpp"
#include "full3d/scene3d.hpp"
#include "reduced1d/scene1d.hpp"
#include "reduced1d/screen.hpp"
#include "validation/suite.hpp"

namespace swim::app {

scene::json run_task(const scene::json& t) {
  const std::string kind = t.at("kind").get<std::string>();
  if (kind == "1d") {
    scene::json resolved;
    const reduced1d::Params p = reduced1d::read_scene(t.at("scene"), resolved, t.at("base_dir").get<std::string>());
    return reduced1d::outcome_to_json(reduced1d::run_design(p));
  }
  if (kind == "confirm3d")
    return design::confirmed_to_json(design::run_confirmed(t.at("scene"), t.at("runs_dir").get<std::string>(),
                                                           t.at("label").get<std::string>(), 0,
                                                           t.at("error_estimate").get<bool>(),
                                                           t.at("metric").get<std::string>(),
                                                           t.value("tier", std::string("3d"))));
  if (kind == "validate") {
    // the run's progress lines name it and the rank it runs on (the ranks share one terminal)
    const Progress::Context named(t.value("tag", std::string("a run")) + " on rank " + std::to_string(ranks::rank()) + ": ",
                                  true);
    return validation::run_planned(t.at("job"));
  }
  throw std::logic_error("unknown task kind " + kind);
}

double cost_1d(const reduced1d::Params& p) {
  // cells times simulated time: a proxy (a force-driven design without a duration runs its cycles)
  return double(p.numerics.cells) * (p.duration > 0 ? p.duration : 1.0);
}

double cost_3d(const scene::json& scene) {
  scene::json resolved;
  const full3d::Params3d p = full3d::read_scene3d(scene, resolved);
  const double t = p.duration > 0 ? p.duration : p.time_limit;
  return double(p.nx) * p.ny * p.nz * (t / p.dt);
}

}  // namespace swim::app
