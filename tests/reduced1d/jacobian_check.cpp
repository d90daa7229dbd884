#include "jacobian_check.hpp"

#include <sunmatrix/sunmatrix_band.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "reduced1d/force_model.hpp"
#include "reduced1d/internal.hpp"
#include "reduced1d/protocol.hpp"
#include "reduced1d/sundials.hpp"

namespace swim::reduced1d::test {

using namespace detail;

JacobianCheck check_jacobian(const Params& P, int phase, int active, unsigned seed) {
  validate(P);
  ForceModel M(P);
  ModelState state = M.make_state();
  ProtocolMachine machine(P);
  machine.set_state(phase, active);
  std::vector<ProtocolMachine::CellLaw> laws;
  std::vector<const ActuationLaw*> seg;
  machine.laws(laws, seg);
  M.set_actuation(machine, laws, seg);
  const int n = M.n, N = M.N;
  std::uint64_t st = 0x9E3779B97F4A7C15ull * (seed + 1);
  auto uni = [&]() {  // splitmix64 -> [0, 1)
    st += 0x9E3779B97F4A7C15ull;
    std::uint64_t z = st;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return double((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
  };
  const double R0 = P.geometry.R0, Rf = P.protocol.R_f, d = P.protocol.delta;
  std::vector<double> y(n, 0.0), yp(n, 0.0);
  for (int i = 0; i < N; ++i) {
    const bool held = seg[M.seg_a[i]] != nullptr;
    const double Ri = held ? Rf + d * (4.0 * uni() - 2.0) : R0 * (0.45 + 0.6 * uni());
    y[1 + M.stride * i] = (Ri / R0) * (Ri / R0);
    if (M.dae)
      for (int k = 1; k < M.stride; ++k) y[1 + M.stride * i + k] = uni() - 0.5;
  }
  // Shift each held segment so that its mean radius sits on a ramp of the held law (a few
  // passes: cells straddling two segments couple neighbouring means).
  std::vector<double> target(seg.size());
  for (auto& v : target) v = (uni() < 0.5 ? Rf + d : Rf - d) + 0.1 * d * (uni() - 0.5);
  for (int pass = 0; pass < 20; ++pass)
    for (int k = 0; k < int(seg.size()); ++k) {
      if (!seg[k]) continue;
      M.unpack(y.data(), state);
      const double shift = target[k] - state.Rbar[k];
      for (int i = M.seg_first[k]; i <= M.seg_last[k]; ++i) {
        const double Ri = R0 * std::sqrt(y[1 + M.stride * i]) + shift;
        y[1 + M.stride * i] = (Ri / R0) * (Ri / R0);
      }
    }
  for (int k = 0; k < n; ++k) yp[k] = uni() - 0.5;
  y[M.iD] = uni();
  y[M.iX] = uni();

  // analytic (band + low rank), dense
  std::vector<double> J(std::size_t(n) * n, 0.0);  // row-major
  std::vector<double> U, Vt;
  int rank = 0;
  const double cj = 1e3;
  if (!M.dae) {
    const Linearisation lin = M.linearise(y.data(), state, true);
    const BandSink band = [&](int i, int j, double v) { J[std::size_t(i) * n + j] = v; };
    rank = M.jacobian(lin, band, U, Vt);
  } else {
    const Linearisation lin = M.linearise(y.data(), state, false);
    rank = M.residual_low_rank(lin, U, Vt);
    // band part: the integrator's analytic band on a band matrix (an entry outside the band
    // the matrix was sized for is an error)
    auto ctx = sun::make_context();
    auto A = sun::make_band_matrix(n, M.band_mu, M.band_ml, ctx.get());
    SUNMatZero(A.get());
    const BandSink band = [&](int i, int j, double v) {
      if (j - i > M.band_mu || i - j > M.band_ml)
        throw std::logic_error("IDA band entry (" + std::to_string(i) + ", " + std::to_string(j) + ") outside the band");
      SM_ELEMENT_B(A.get(), i, j) += v;
    };
    M.ida_band(lin, y.data(), cj, band);
    for (int i = 0; i < n; ++i)
      for (int j = std::max(0, i - M.band_ml); j <= std::min(n - 1, i + M.band_mu); ++j)
        J[std::size_t(i) * n + j] = SM_ELEMENT_B(A.get(), i, j);
  }
  for (int k = 0; k < rank; ++k)
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) J[std::size_t(i) * n + j] += U[std::size_t(k) * n + i] * Vt[std::size_t(k) * n + j];

  // central differences of the full model
  std::vector<double> Jfd(std::size_t(n) * n, 0.0), fp(n), fm(n), yy = y, yyp = yp;
  for (int j = 0; j < n; ++j) {
    const double inc = 1e-6 * std::max(std::abs(y[j]), 1e-2);
    yy[j] = y[j] + inc;
    yyp[j] = yp[j] + cj * inc;
    if (M.dae) M.res(yy.data(), yyp.data(), fp.data(), state); else M.rhs(yy.data(), fp.data(), state);
    yy[j] = y[j] - inc;
    yyp[j] = yp[j] - cj * inc;
    if (M.dae) M.res(yy.data(), yyp.data(), fm.data(), state); else M.rhs(yy.data(), fm.data(), state);
    yy[j] = y[j];
    yyp[j] = yp[j];
    for (int i = 0; i < n; ++i) Jfd[std::size_t(i) * n + j] = (fp[i] - fm[i]) / (2.0 * inc);
  }
  JacobianCheck out;
  out.rank = rank;
  for (int i = 0; i < n; ++i) {
    // D, X and lab-volume rows: radii couplings left out by design (no feedback)
    if (i == M.iD || i == M.iX || i == M.iVrl || i == M.iVfl) continue;
    double rowmax = 0;
    for (int j = 0; j < n; ++j) rowmax = std::max(rowmax, std::abs(Jfd[std::size_t(i) * n + j]));
    if (rowmax == 0) continue;
    for (int j = 0; j < n; ++j) {
      const double a = J[std::size_t(i) * n + j], b = Jfd[std::size_t(i) * n + j];
      if (a != 0 || b != 0) ++out.entries;
      out.max_rel_error = std::max(out.max_rel_error, std::abs(a - b) / rowmax);
    }
  }
  // D-X block (inside the band)
  for (int i : {M.iD, M.iX})
    for (int j : {M.iD, M.iX}) {
      const double a = J[std::size_t(i) * n + j], b = Jfd[std::size_t(i) * n + j];
      const double sc = std::max({std::abs(b), std::abs(Jfd[std::size_t(M.iX) * n + M.iD]), 1e-300});
      if (a != 0 || b != 0) ++out.entries;
      out.max_rel_error = std::max(out.max_rel_error, std::abs(a - b) / sc);
    }
  return out;
}

}  // namespace swim::reduced1d::test
