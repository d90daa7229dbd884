// Serial kernels for the SUNDIALS objects of the reduced 1D tier.
//
// The distribution's SUNDIALS libraries are built without optimisation (measured: ~20
// instructions per element in N_VLinearSum_Serial), and CVODE/IDA spend most of a step in
// their vector kernels for the small systems of the 1D tier. These replacements are compiled
// with the project's flags and have the same semantics as the serial implementations.
#pragma once

#include <nvector/nvector_serial.h>
#include <sundials/sundials_matrix.h>

namespace swim::reduced1d::sun {

/// Replace the operations of a serial vector (and of its clones) by the optimised kernels.
void install_vector_kernels(N_Vector v);

/// Replace SUNMatZero of a band matrix by one memset of its storage (the integrators zero it
/// before every Jacobian fill).
void install_band_kernels(SUNMatrix A);

}  // namespace swim::reduced1d::sun
