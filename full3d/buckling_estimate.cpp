#include "full3d/buckling_estimate.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "common/errors.hpp"

namespace swim::full3d {

namespace {
constexpr double kPi = 3.14159265358979323846;

struct Wavenumbers {
  double kx, ky, k2;
};
Wavenumbers wavenumbers(int m, double R, double ell) {
  const double kx = std::isinf(ell) ? 0.0 : kPi / ell, ky = m / R;
  return {kx, ky, kx * kx + ky * ky};
}
// K_m + N k_y^2: the wall's own stiffness of the mode (bending and the lobes' membrane strain)
double wall_stiffness(const Wavenumbers& k, double D, double Y, double R) {
  const double kx2 = k.kx * k.kx;
  return D * k.k2 * k.k2 + Y / (R * R) * kx2 * kx2 / (k.k2 * k.k2);
}
}  // namespace

double segment_buckling_compression(int m, double D, double Y, double R, double ell) {
  if (m < 2) return std::numeric_limits<double>::infinity();
  const Wavenumbers k = wavenumbers(m, R, ell);
  return wall_stiffness(k, D, Y, R) / (k.ky * k.ky);
}

double segment_mode_growth_rate(int m, double N, double D, double Y, double R, double ell, WallDrag drag,
                                double coefficient) {
  if (m < 2) return -std::numeric_limits<double>::infinity();
  const Wavenumbers k = wavenumbers(m, R, ell);
  const double K = wall_stiffness(k, D, Y, R) - N * k.ky * k.ky;
  const double c = drag == WallDrag::Dry ? coefficient : 4.0 * coefficient * std::sqrt(k.k2);
  return -K / c;
}

int fastest_segment_mode(double N, double D, double Y, double R, double ell, WallDrag drag, double coefficient,
                         int m_max) {
  int best = 0;
  double rate = 0.0;
  for (int m = 2; m <= m_max; ++m) {
    const double s = segment_mode_growth_rate(m, N, D, Y, R, ell, drag, coefficient);
    if (s > rate) rate = s, best = m;
  }
  return best;
}

std::vector<ContractionStage> contraction_buckling(double L, int segments, double first_ratio, double R_f, double N,
                                                   double D, double Y, double mu) {
  if (segments < 1 || !(L > 0.0) || !(first_ratio > 0.0) || !(R_f > 0.0))
    throw std::invalid_argument("contraction_buckling: a positive length, radius and segment count");
  const double other = L / (first_ratio + segments - 1);
  std::vector<ContractionStage> stages;
  for (int j = 0; j < segments; ++j) {
    ContractionStage s;
    s.loaded_length = j + 1 == segments ? L : other * (first_ratio + j);
    s.ell = j + 1 == segments ? std::numeric_limits<double>::infinity() : s.loaded_length;
    s.mode = fastest_segment_mode(N, D, Y, R_f, s.ell, WallDrag::Stokes, mu);
    s.growth_rate = s.mode ? segment_mode_growth_rate(s.mode, N, D, Y, R_f, s.ell, WallDrag::Stokes, mu) : 0.0;
    s.critical_compression = std::numeric_limits<double>::infinity();
    for (int m = 2; m <= 64; ++m) {
      const double n = segment_buckling_compression(m, D, Y, R_f, s.ell);
      if (n < s.critical_compression) s.critical_compression = n, s.critical_mode = m;
    }
    stages.push_back(s);
  }
  return stages;
}

}  // namespace swim::full3d
