// Linear buckling estimate of a loaded segment of the tube's wall (Donnell's shallow-shell
// equation), the growth rates of its modes with a dry or a viscous (Stokes) drag, and the
// estimate for a force-driven scene's contraction. docs/full3d.md, "Ring buckling and the
// seed imperfection", derives it and compares it with the runs.
//
// A wall of stretching modulus Y (N/m) and bending rigidity D (J), radius R, under a hoop
// compression N (N/m), loaded over an axial length ell between parts that stay round, deforms
// in modes w = a sin(pi x / ell) cos(m theta): axial wavenumber k_x = pi / ell, azimuthal
// k_y = m / R, k^2 = k_x^2 + k_y^2. Donnell's equation,
//
//     D k^8 w + (Y / R^2) k_x^4 w - N k_y^2 k^4 w = 0,
//
// gives the mode's stiffness per unit area and amplitude
//
//     K_m = D k^4 + (Y / R^2) k_x^4 / k^4 - N k_y^2        (K_m < 0: the mode grows)
//
// (bending, the membrane strain the axial variation of the lobes costs, the compression's
// work). ell = infinity is the free tube's axially uniform mode (k_x = 0: the ring, with m^2
// where the exact ring has m^2 - 1; a relative O(1/m^2)).
#pragma once

#include <vector>

namespace swim::full3d {

/// Hoop compression (N/m) at which mode m of a segment of length ell (m; infinity: the free
/// tube) buckles: N_m = [D k^4 + (Y / R^2) k_x^4 / k^4] / k_y^2. m < 2: infinity.
double segment_buckling_compression(int m, double D, double Y, double R, double ell);

/// How the wall's motion is resisted when a mode grows.
enum class WallDrag {
  Dry,    ///< c dw/dt per area with a constant c (kg/(m^2 s)), the dry swimmer's damping
  Stokes  ///< creeping fluid on both sides of a thin sheet: 4 mu k dw/dt per area (mu in Pa s)
};

/// Linear growth rate (1/s; negative: decay) of mode m of the segment under the hoop
/// compression N: sigma_m = -K_m / c_m, c_m = coefficient (Dry) or 4 coefficient k (Stokes,
/// coefficient = mu; the plane sheet's drag, good to O(1/m) on a ring of m lobes).
double segment_mode_growth_rate(int m, double N, double D, double Y, double R, double ell, WallDrag drag,
                                double coefficient);

/// The mode m in [2, m_max] that grows fastest (largest positive rate), or 0 when none grows.
int fastest_segment_mode(double N, double D, double Y, double R, double ell, WallDrag drag, double coefficient,
                         int m_max = 64);

/// The estimate for one stage of a force-driven contraction: the segments loaded so far form one
/// contracted part of length `loaded_length`, held at R_f by the hoop compression N = q / (2 pi),
/// q the actuation force per unit axial length (the scene's pressure times 2 pi R0: the nodes'
/// centrally directed forces, balanced by the compressed hoop). The part's ends stay round unless
/// it spans the whole tube, whose free ends let the axially uniform (ring) modes grow.
struct ContractionStage {
  double loaded_length = 0.0;  ///< m
  double ell = 0.0;            ///< the buckling length used: loaded_length, or infinity for the whole tube
  int mode = 0;                ///< fastest-growing mode in the fluid (0: stable)
  double growth_rate = 0.0;    ///< 1/s, of that mode (0 when stable)
  int critical_mode = 0;       ///< the mode with the lowest buckling compression
  double critical_compression = 0.0;  ///< N/m, that lowest N_m
};

/// Stages of a contraction of a tube of length L whose k segments (the first of length
/// first_ratio times the others) load one after the other: stage j has the first j + 1 segments
/// contracted to R_f under the hoop compression N. Wall moduli Y, D; fluid viscosity mu.
std::vector<ContractionStage> contraction_buckling(double L, int segments, double first_ratio, double R_f, double N,
                                                   double D, double Y, double mu);

}  // namespace swim::full3d
