#include "full3d/run3d_setup.hpp"

#include <algorithm>
#include <cmath>

#include "common/si_format.hpp"

namespace swim::full3d {

namespace {
long steps_for(double interval, double dt) { return std::max(1L, std::lround(interval / dt)); }
}  // namespace

RunSetup::RunSetup(const Params3d& params)
    : World3d(params), mass(node_masses(mesh, params.mass_per_area)),
      adaptive(params.adaptive.enabled && !params.dry), dt_key(adaptive ? "full3d.adaptive.dt_max" : "full3d.dt"),
      n_end(params.duration > 0 ? std::max(1L, std::lround(params.duration / params.dt)) : -1),
      n_limit(std::max(1L, std::lround(params.time_limit / params.dt))),
      out_every(steps_for(params.output_interval, params.dt)), vtk_every(steps_for(params.vtk_interval, params.dt)),
      // a whole multiple of vtk_every (read_scene3d makes fluid_interval a multiple of
      // vtk_interval): every fluid frame is written at a step that also writes the membrane
      fluid_every(vtk_every * std::max(1L, std::lround(params.fluid_interval / params.vtk_interval))),
      ckpt_every(steps_for(params.checkpoint_interval, params.dt)) {}

std::string short_number(double v) { return significant(v, 4); }

}  // namespace swim::full3d
