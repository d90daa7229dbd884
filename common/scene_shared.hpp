// The scene sections both tiers read the same way: swimmer, fluid, wall, the contracted
// radius of the wave, and the force-driven protocol. Each tier reads its own sections
// (model1d/numerics1d, full3d) and the tier-specific keys of `wave` around these.
#pragma once

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

struct Body {
  double R0 = 0, L = 0;     ///< swimmer.radius, swimmer.length [m]
  double mu = 0, rho = 0;   ///< fluid.viscosity [Pa s], fluid.density [kg/m^3]
  double temperature = 0;   ///< fluid.temperature [K]
};
/// Reads (and finishes) the swimmer and fluid sections.
Body read_body(Reader& top);

/// The rigid periodic container both tiers run in (scene section `container`).
struct ContainerSpec {
  std::string kind;       ///< "duct" (square, default), "cylinder" (the paper's) or "box" (periodic, 3D only)
  double radius = 0;      ///< cylinder radius or duct half-width [m]
  double period = 0;      ///< axial period [m]
};
/// Reads (and finishes) the container section; the swimmer must fit (R0 < radius, L < period).
ContainerSpec read_container(Reader& top, double R0, double L);

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
/// Reads (and finishes) the wall section.
WallSpec read_wall(Reader& top, double R0);

/// The spring network's small-strain wall stiffness C1 = 2 k_s / (sqrt(3) R0^2) [Pa/m] of a
/// tube of radius R0 [m] with spring constant k_s [N/m] (plane stress of the triangulated
/// network; docs/source-equations.md). The one formula of both tiers and the calibration.
double c1_from_spring_constant(double k_s, double R0);

/// wave.contracted_ratio | wave.contracted_radius -> R_f [m]; the caller reads the other
/// wave keys and finishes `wave`.
double read_contracted_radius(Reader& wave, double R0);

/// The wave section (docs/scenes.md "wave.*"): its kind, the contracted radius and the
/// prescribed waves' kinematics (reduced1d/params.hpp StepWave, SineWave).
struct WaveSpec {
  std::string kind;         ///< "step", "sine" or "force_driven"
  double R_f = 0;           ///< contracted radius [m]: the step's R_min, the sine's R0 - amplitude
  double speed = 0;         ///< step, sine: wave speed s > 0, the wave travels towards -z [m/s]
  double width = 0;         ///< step: smoothing width w [m]
  double wavelength = 0;    ///< sine: lambda [m]
  bool prescribed() const { return kind != "force_driven"; }
  /// The default end time of a prescribed wave: L/s (step), lambda/s (sine); 0 (force_driven).
  double transit(double L) const;
};
/// Reads (and finishes) the wave section of a swimmer of radius R0 and length L [m].
WaveSpec read_wave(Reader& top, double R0, double L);

struct ProtocolSpec {
  double q = 0;             ///< actuation pressure [Pa], inward positive
  int segments = 0;
  double first_ratio = 0;   ///< first (rightmost) segment length / other segments
  double delta = 0;         ///< radius tolerance [m]
  double energy_tol = 0;
  int cycles = 0;
};
/// Reads (and finishes) the protocol section of a force-driven wave. C1 [Pa/m] is the wall
/// stiffness used to check that the actuation can reach R_f (static load C1 (R0 - R_f)).
/// `static_load` > 0: the static load that holds R_f under a nonlinear wall law, in place of
/// C1 (R0 - R_f).
ProtocolSpec read_protocol(Reader& top, double R0, double L, double R_f, double C1, double static_load = 0.0);

}  // namespace swim::scene
