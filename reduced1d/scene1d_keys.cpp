#include "reduced1d/scene1d_keys.hpp"

namespace swim::reduced1d {

const scene::json& section_keys() {
  static const scene::json keys = {
      {"model1d",
       {{"model", "choice:force_free|paper"},
        {"outer_flow", "choice:confined|unbounded"},
        {"hydraulic_offsets", {{"source", "choice:scene|calibration"}, {"inner", "quantity:m"}, {"outer", "quantity:m"}}},
        {"paper",
         {{"closure", "choice:tube_law|flow"},
          {"balance", "choice:per_area|per_length"},
          {"thrust", "boolean"},
          {"external_drag", "choice:none|resistive_force"}}},
        {"wall_inertia", "boolean"},
        {"short_wave_traction", "boolean"},
        {"short_wave_traction_end", "number"},
        {"end_effects", "choice:none|open_ends|junction"},
        {"recovery_end", "choice:energy|dead_band|shape"},
        {"axial_bending", {{"source", "choice:none|scene|calibration"}, {"rigidity", "quantity:J@positive"}}}}},
      {"numerics1d", {{"cells", "integer"}, {"rtol", "number"}, {"atol_scale", "number"}, {"max_steps", "integer"}, {"threads", "integer"}, {"open_end", "choice:drainage|linear|continued"}}}};
  return keys;
}

}  // namespace swim::reduced1d
