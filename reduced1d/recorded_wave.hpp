// A prescribed wave replayed from a recorded radius profile (wave.kind = "recorded",
// wave.radius_file): the radius.csv of a run of any tier (long format t_s, z_m, radius_m;
// docs/outputs.md), interpolated onto the 1D tier's points.
//
// Interpolation (docs/scenes.md "wave.radius_file"): piecewise linear in time per ring, and
// linear in z between the rings (linear extrapolation from the two end rings over the gap of at
// most half a ring spacing plus 2 % of L between the last ring and an end of the tube: a 1D
// record holds the cell centres, half a cell in from the ends). The wall velocity is the exact time derivative of that
// interpolant: per ring the slope of the record's interval, interpolated in z with the same
// weights, so R and dR/dt are consistent (the swept volume is the integral of the flux) and the
// displacement of a time-reversed record is exactly minus the forward one. The record's times
// are shifted to start at 0; its span is the wave's period (one cycle), and a longer
// time.duration repeats it.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

namespace swim::reduced1d {

struct RecordedRadius {
  std::vector<double> t;  ///< record times from 0, strictly increasing (>= 2) [s]
  std::vector<double> z;  ///< ring positions, strictly increasing (>= 2) [m]
  std::vector<double> R;  ///< R[k * z.size() + j]: radius of ring j at t[k] [m]

  double period() const { return t.back() - t.front(); }
  double min_radius() const;
  double max_radius() const;
  /// The record's time interval k (t[k] <= t' < t[k + 1]) and its weight theta at time t
  /// (t' = t mod period for t beyond the record).
  void locate(double time, std::size_t& k, double& theta) const;
  /// R and dR/dt at (zq, time).
  void eval(double zq, double time, double& Rq, double& Rt) const;
  /// R and dR/dt at the n points zq[i] = z0 + i dz at one time.
  void eval_uniform(double z0, double dz, int n, double time, double* Rq, double* Rt) const;

 private:
  /// R and dR/dt between rings j and j + 1 (weight w of the upper one) in the record's interval
  /// from the rows a to b (weight th of b, length dt).
  static void blend(const double* a, const double* b, std::size_t j, double w, double th, double dt, double& Rq,
                    double& Rt) {
    const double ra = (1 - th) * a[j] + th * b[j], rb = (1 - th) * a[j + 1] + th * b[j + 1];
    Rq = (1 - w) * ra + w * rb;
    Rt = ((1 - w) * (b[j] - a[j]) + w * (b[j + 1] - a[j + 1])) / dt;
  }
};

// The evaluation is header-only, as the rest of disc::PrescribedShape (reduced1d/discretisation.hpp,
// which the axisymmetric tier's prescribed waves include without the 1D library).

inline void RecordedRadius::locate(double time, std::size_t& k, double& theta) const {
  const double T = period();
  double tt = time - t.front();
  if (tt > T) {  // a longer run repeats the record
    tt = std::fmod(tt, T);
    if (tt == 0.0) tt = T;  // the end of a repetition is the end of the record
  }
  if (tt < 0) tt = 0;
  tt += t.front();
  const std::size_t n = t.size();
  // the interval with t[k] <= tt < t[k + 1]; the last time belongs to the last interval
  k = std::size_t(std::upper_bound(t.begin(), t.end(), tt) - t.begin());
  k = k == 0 ? 0 : k - 1;
  if (k > n - 2) k = n - 2;
  theta = (tt - t[k]) / (t[k + 1] - t[k]);
}

inline void RecordedRadius::eval(double zq, double time, double& Rq, double& Rt) const {
  std::size_t k;
  double th;
  locate(time, k, th);
  // the bracketing rings and the upper one's weight (linear continuation outside their span)
  const std::size_t m = z.size();
  std::size_t j = std::size_t(std::upper_bound(z.begin(), z.end(), zq) - z.begin());
  j = j == 0 ? 0 : j - 1;
  if (j > m - 2) j = m - 2;
  const double w = (zq - z[j]) / (z[j + 1] - z[j]);
  const double dt = t[k + 1] - t[k];
  const double* a = R.data() + k * m;
  blend(a, a + m, j, w, th, dt, Rq, Rt);
}

inline void RecordedRadius::eval_uniform(double z0, double dz, int n, double time, double* Rq, double* Rt) const {
  std::size_t k;
  double th;
  locate(time, k, th);
  const std::size_t m = z.size();
  const double dt = t[k + 1] - t[k];
  const double* a = R.data() + k * m;
  const double* b = a + m;
  std::size_t j = 0;
  for (int i = 0; i < n; ++i) {
    const double zq = z0 + i * dz;
    while (j + 2 < m && z[j + 1] <= zq) ++j;  // the points increase: walk the rings once
    blend(a, b, j, (zq - z[j]) / (z[j + 1] - z[j]), th, dt, Rq[i], Rt[i]);
  }
}

/// Reads and checks a radius.csv for a tube of length L [m] (InputError naming `key`, the path
/// and what is allowed, for a missing or unreadable file, a header other than
/// `t_s,z_m,radius_m`, a row that is not three finite numbers, a radius that is not positive,
/// times that do not increase, fewer than 2 times or 2 rings, a time whose rings differ from the
/// first time's, and rings whose z span does not cover [0, L] to within half a ring spacing
/// plus 2 % of L at each end). A relative path is tried from the working directory, then from scene_dir.
std::shared_ptr<const RecordedRadius> read_radius_file(const std::string& key, const std::string& path,
                                                       const std::string& scene_dir, double L);

}  // namespace swim::reduced1d
