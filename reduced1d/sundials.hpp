// Thin RAII layer over the SUNDIALS 6 C API used by the reduced 1D tier.
// (The tier's own solvers behind SUNDIALS' interfaces are in linear_solvers.hpp and
// serial_kernels.hpp.)
//
// Every SUNDIALS object is owned by a unique_ptr with the matching destroy call, so an
// exception thrown anywhere in the solver releases everything. `check` is the one place
// where a SUNDIALS return flag becomes an exception (SundialsError); the solver turns that
// exception into Result::failure (swim::NumericalError) with a cause and a remedy.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>

#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sundials/sundials_linearsolver.h>
#include <sundials/sundials_matrix.h>
#include <sundials/sundials_nonlinearsolver.h>

namespace swim::reduced1d::sun {

/// A SUNDIALS call returned a negative flag.
class SundialsError : public std::runtime_error {
 public:
  SundialsError(std::string where, int flag, std::string flag_name, std::string detail);
  const std::string& where() const { return where_; }
  int flag() const { return flag_; }
  const std::string& flag_name() const { return flag_name_; }
  const std::string& detail() const { return detail_; }

 private:
  std::string where_;
  int flag_;
  std::string flag_name_;
  std::string detail_;
};

/// Throw SundialsError when flag < 0. `where` names the call ("CVode", "IDASolve",
/// "CVodeInit", "SUNLinSol_Band", ...); calls whose name starts with "IDA" use IDA's flag
/// names, all others CVODE's. `detail` is the last message of the integrator's error
/// handler, if the caller captured one. Returns the flag (>= 0) otherwise.
int check(int flag, const char* where, const std::string& detail = {});

/// Throw SundialsError (flag -999) when a constructor returned nullptr.
template <class P>
P* check_ptr(P* p, const char* where) {
  if (p == nullptr) throw SundialsError(where, -999, "NULL", "allocation or creation failed");
  return p;
}

// ---- owners -------------------------------------------------------------------------

struct ContextDeleter {
  void operator()(SUNContext c) const;
};
struct VectorDeleter {
  void operator()(N_Vector v) const;
};
struct MatrixDeleter {
  void operator()(SUNMatrix m) const;
};
struct LinSolDeleter {
  void operator()(SUNLinearSolver s) const;
};
struct NonlinSolDeleter {
  void operator()(SUNNonlinearSolver s) const;
};
struct CvodeDeleter {
  void operator()(void* mem) const;
};
struct IdaDeleter {
  void operator()(void* mem) const;
};

using Context = std::unique_ptr<std::remove_pointer_t<SUNContext>, ContextDeleter>;
using Vector = std::unique_ptr<std::remove_pointer_t<N_Vector>, VectorDeleter>;
using Matrix = std::unique_ptr<std::remove_pointer_t<SUNMatrix>, MatrixDeleter>;
using LinearSolver = std::unique_ptr<std::remove_pointer_t<SUNLinearSolver>, LinSolDeleter>;
using NonlinearSolver = std::unique_ptr<std::remove_pointer_t<SUNNonlinearSolver>, NonlinSolDeleter>;
using CvodeMem = std::unique_ptr<void, CvodeDeleter>;
using IdaMem = std::unique_ptr<void, IdaDeleter>;

Context make_context();
Vector make_vector(long n, SUNContext ctx);  ///< serial vector, zero-filled, kernels of serial_kernels.hpp
/// Band matrix n x n with upper/lower half-bandwidths mu, ml, zeroed by the kernel of
/// serial_kernels.hpp. Without storage for LU fill-in: the tier's solvers
/// (linear_solvers.hpp) factor into their own storage, and the integrators zero the matrix
/// before every Jacobian (IDA's band at N = 50 is 21 instead of 32 rows of 406 columns). A
/// factorisation in place (SUNLinSol_Band, make_band_solver) needs SUNBandMatrix's storage.
Matrix make_band_matrix(long n, long mu, long ml, SUNContext ctx);
Matrix make_dense_matrix(long n, SUNContext ctx);
LinearSolver make_band_solver(N_Vector y, SUNMatrix A, SUNContext ctx);
LinearSolver make_dense_solver(N_Vector y, SUNMatrix A, SUNContext ctx);
NonlinearSolver make_fixed_point_solver(N_Vector y, int m_accel, SUNContext ctx);
CvodeMem make_cvode(int lmm, SUNContext ctx);
IdaMem make_ida(SUNContext ctx);

/// Raw data pointer of a serial vector.
inline double* data(N_Vector v) { return N_VGetArrayPointer(v); }

/// Error handler for CVODE/IDA that stores the last message into a std::string (passed as
/// user data) instead of printing it to stderr.
void capture_error(int error_code, const char* module, const char* function, char* msg,
                   void* user_data);

}  // namespace swim::reduced1d::sun
