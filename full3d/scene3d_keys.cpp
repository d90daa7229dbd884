#include "full3d/scene3d_keys.hpp"

namespace swim::full3d {

const scene::json& section_keys() {
  static const scene::json keys = {
      {"grid", {{"cells_across", "integer"}, {"cell_size", "quantity:m"}}},
      {"dt", "quantity:s"},
      {"adaptive",
       {{"enabled", "boolean"},
        {"cfl", "number"},
        {"tolerance", "number"},
        {"dt_max", "quantity:s"},
        {"dt_min", "quantity:s"},
        {"event_dt", "quantity:s"},
        {"stability_fraction", "number"}}},
      {"scheme", "choice:forward_euler|midpoint"},
      {"membrane",
       {{"bending_constant", "quantity:N"},
        {"bending_rigidity", "quantity:J"},
        {"bending_form", "choice:reference_angle|printed"},
        {"spacing_factor", "number"},
        {"axisymmetric", "boolean"}}},
      {"wall_inertia", "boolean"},
      {"navier_stokes", "boolean"},
      {"recovery_end", "choice:energy|dead_band|shape"},
      {"dry", "boolean"},
      {"dry_damping", "quantity:kg/(m^2*s)"},
      {"max_cfl", "number"},
      {"energy_growth_limit", "number"},
      {"time_limit", "quantity:s"},
      {"output",
       {{"vtk", "boolean"}, {"vtk_interval", "quantity:s"}, {"fluid_fields", "boolean"}, {"fluid_interval", "quantity:s"}}},
      {"checkpoint_interval", "quantity:s"},
      {"threads", "integer"}};
  return keys;
}

}  // namespace swim::full3d
