#include "full3d/scene3d_keys.hpp"

namespace swim::full3d {

const scene::json& section_keys() {
  static const scene::json keys = {
      {"grid", {{"cells_across", "integer@[4,4096]"}, {"cell_size", "quantity:m@positive"}}},
      {"dt", "quantity:s@positive"},
      {"adaptive",
       {{"enabled", "boolean"},
        {"cfl", "number@(0,2)"},
        {"tolerance", "number@(0,1)"},
        {"dt_max", "quantity:s@positive"},
        {"dt_min", "quantity:s@positive"},
        {"event_dt", "quantity:s@positive"},
        {"stability_fraction", "number@(0,1)"},
        {"max_stages", "integer@[1,32]"}}},
      {"scheme", "choice:forward_euler|midpoint|chebyshev"},
      {"wall_stabilization", "choice:none|bending"},
      {"stabilization_factor", "number@[0.1,100]"},
      {"memory_limit_gib", "number@[0.125,1024]"},
      {"membrane",
       {{"bending_constant", "quantity:N@non_negative"},
        {"bending_rigidity", "quantity:J@positive"},
        {"bending_model", "choice:rigidity|fixed_kb"},
        {"reference_edge", "quantity:m@positive"},
        {"seed_mode", "integer_or_auto@[0,64]"},
        {"seed_amplitude", "number@[0,0.1]"},
        {"secondary_seed_mode", "integer@[0,64]"},
        {"secondary_seed_amplitude", "number@[0,0.1]"},
        {"bending_form", "choice:reference_angle|printed"},
        {"spacing_factor", "number@(0,1)"},
        {"ring_nodes_multiple", "integer@[1,64]"},
        {"axisymmetric", "boolean"}}},
      {"wall_inertia", "boolean"},
      {"navier_stokes", "boolean"},
      {"recovery_end", "choice:energy|dead_band|shape"},
      {"dry", "boolean"},
      {"dry_damping", "quantity:kg/(m^2*s)@non_negative"},
      {"max_cfl", "number@(0,2)"},
      {"energy_growth_limit", "number@(1,1e12)"},
      {"time_limit", "quantity:s@positive"},
      {"output",
       {{"vtk", "boolean"},
        {"vtk_interval", "quantity:s@positive"},
        {"fluid_fields", "boolean"},
        {"fluid_interval", "quantity:s@positive"}}},
      {"checkpoint_interval", "quantity:s@positive"},
      {"threads", "integer@[1,256]"}};
  return keys;
}

}  // namespace swim::full3d
