// The scene sections every tier reads the same way: name and description, swimmer, fluid,
// container, wall, wave, protocol and time. SharedScene reads and validates each of their keys
// here and only here; a tier's reader (reduced1d/scene1d.cpp, full3d/scene3d.cpp, and through
// the 3D reader axi/scene_axi.cpp) maps them onto its own parameters, applies its own rules
// and reads its own sections (model1d/numerics1d, full3d, axi).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "common/scene.hpp"

namespace swim::scene {

/// Exactly one of `keys` may be present in `r`; returns it, or `fallback` when none is.
/// Two present keys are an InputError naming the second.
std::string one_of(const Reader& r, const std::vector<std::string>& keys, const std::string& fallback);

/// "1.25e-07 m": a value and its unit for messages and defaults.
std::string format_quantity(double v, const char* unit);

/// True when a is a whole number n >= 1 of cells h (to 1e-9 relative): grid rules of the
/// 3D and axisymmetric tiers.
bool multiple_of(double a, double h);

/// The swimmer and fluid sections.
struct Body {
  double R0 = 0, L = 0;     ///< swimmer.radius, swimmer.length [m]
  double mu = 0, rho = 0;   ///< fluid.viscosity [Pa s], fluid.density [kg/m^3]
  double temperature = 0;   ///< fluid.temperature [K]
};

/// The rigid periodic container both tiers run in (scene section `container`).
struct ContainerSpec {
  std::string kind;       ///< "duct" (square, default), "cylinder" (the paper's) or "box" (periodic, 3D only)
  double radius = 0;      ///< cylinder radius or duct half-width [m]
  double period = 0;      ///< axial period [m]
};

/// The wall section.
struct WallSpec {
  std::string stiffness;    ///< the key given: "C1", "spring_constant", "stretching_modulus" or "calibration"
  /// C1 [Pa/m], or the spring constant k_s [N/m] of the network (wall.spring_constant, or
  /// wall.stretching_modulus Y converted with k_s = sqrt(3) Y / 2); 0 for a calibration file
  double value = 0;
  /// The wall is given as a spring network (k_s in value): spring_constant or stretching_modulus.
  bool network() const { return stiffness == "spring_constant" || stiffness == "stretching_modulus"; }
  std::string calibration;  ///< path, for "calibration"
  double mass_per_area = 0; ///< [kg/m^2] (mass_per_length converted with 2 pi R0, source-equations.md §1)
  /// wall.law: "linear" (the default, and when the key is absent: not echoed, so scenes without
  /// it resolve as before), "calibrated_round" or "calibrated_buckled" (the 1D tier's static
  /// tube law from the calibration file's tube_law section, docs/tube-law.md; the 3D tier's
  /// wall is the membrane itself and ignores it)
  std::string law = "linear";
};

/// The spring network's small-strain wall stiffness C1 = 2 k_s / (sqrt(3) R0^2) [Pa/m] of a
/// tube of radius R0 [m] with spring constant k_s [N/m] (plane stress of the triangulated
/// network; docs/source-equations.md). The one formula of both tiers and the calibration.
double c1_from_spring_constant(double k_s, double R0);

/// The wave section (docs/scenes.md "wave.*"): its kind, the contracted radius and the
/// prescribed waves' kinematics (reduced1d/params.hpp StepWave, SineWave; a recorded wave's
/// file, which the 1D tier reads: reduced1d/recorded_wave.hpp).
struct WaveSpec {
  std::string kind;         ///< "step", "sine", "force_driven" or "recorded"
  double R_f = 0;           ///< contracted radius [m]: the step's R_min, the sine's R0 - amplitude
  double speed = 0;         ///< step, sine: wave speed s > 0, the wave travels towards -z [m/s]
  double width = 0;         ///< step: smoothing width w [m]
  double wavelength = 0;    ///< sine: lambda [m]
  std::string radius_file;  ///< recorded: the radius.csv to replay (read by the 1D tier)
  double period = 0;        ///< recorded: the record's span [s], set by the tier that reads the file
  bool prescribed() const { return kind != "force_driven"; }
  /// The default end time of a prescribed wave: L/s (step), lambda/s (sine), the record's span
  /// (recorded, once the tier has read it); 0 (force_driven).
  double transit(double L) const;
};

/// The protocol section of a force-driven wave.
struct ProtocolSpec {
  double q = 0;             ///< actuation pressure [Pa], inward positive
  int segments = 0;
  double first_ratio = 0;   ///< first (rightmost) segment length / other segments
  double delta = 0;         ///< radius tolerance [m]
  double energy_tol = 0;
  int cycles = 0;
  /// Copies these values into a tier's protocol parameters (the fields of the same names).
  template <class Params>
  void assign_to(Params& out) const {
    out.q = q;
    out.segments = segments;
    out.first_ratio = first_ratio;
    out.delta = delta;
    out.energy_tol = energy_tol;
    out.cycles = cycles;
  }
};

/// The time section.
struct TimeSpec {
  /// time.duration [s]; 0 for "auto" (the default): a prescribed wave's transit time, or until
  /// protocol.cycles cycles are complete
  double duration = 0;
  /// time.output_interval [s]; default 1/200 of the run (the duration, else the transit), else 0.5 ms
  double output_interval = 0;
};

/// The shared sections of one scene, each key read and validated once, for whichever tier
/// runs it. A tier's reader calls the three phases in its own order, which is the order of
/// the resolved scene's keys, and reads its own sections between them:
///   SharedScene s = SharedScene::read(top, wall_rule);  // name, description, swimmer, fluid,
///                                                       // container, wall, wave
///   s.read_protocol(top, C1);                           // protocol, or its refusal
///   s.read_time(top);                                   // time
struct SharedScene {
  std::string name;
  Body body;
  ContainerSpec container;
  WallSpec wall;
  WaveSpec wave;
  ProtocolSpec protocol;  ///< a force_driven wave's; zero for a prescribed wave
  TimeSpec time;

  bool force_driven() const { return !wave.prescribed(); }

  /// A tier's own rule on the wall (its stiffness model), applied as soon as the wall section
  /// is read, before the wave section; it throws InputError for a wall the tier cannot model.
  using WallRule = std::function<void(const Body&, const WallSpec&)>;
  /// Reads (and finishes) name, description, swimmer, fluid, container, wall and wave of the
  /// top-level reader.
  static SharedScene read(Reader& top, const WallRule& wall_rule = {});
  /// A force_driven wave: reads (and finishes) the protocol section. C1 [Pa/m] is the wall
  /// stiffness used to check that the actuation can reach R_f (static load C1 (R0 - R_f));
  /// `static_load` > 0: the static load that holds R_f under a nonlinear wall law, in place of
  /// C1 (R0 - R_f). A prescribed wave: a protocol section is an InputError.
  void read_protocol(Reader& top, double C1, double static_load = 0.0);
  /// Reads (and finishes) the time section.
  void read_time(Reader& top);
};

}  // namespace swim::scene
