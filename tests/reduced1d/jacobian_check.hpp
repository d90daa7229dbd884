// Test oracle of the force-driven model's Newton-matrix Jacobians.
#pragma once

#include "reduced1d/params.hpp"

namespace swim::reduced1d::test {

/// The analytic Newton-matrix Jacobians (band part and low-rank terms) against central
/// finite differences of the right-hand side (CVODE) or residual (IDA) at a random state:
/// radii drawn in [R_f - 2 delta, R_f + 2 delta] (held segments, shifted so that the segment
/// means fall on the ramps) or in [0.45, 1.05] R0, protocol in `phase` with `active` as the
/// active segment. max_rel_error: the largest entry error relative to the largest entry of
/// its row; rank: the number of low-rank terms.
struct JacobianCheck {
  double max_rel_error = 0;
  int rank = 0;
  int entries = 0;  ///< non-zero entries compared
};
JacobianCheck check_jacobian(const Params& p, int phase, int active, unsigned seed);

}  // namespace swim::reduced1d::test
