#include "reduced1d/sundials.hpp"

#include <cvode/cvode.h>
#include <ida/ida.h>
#include <sunlinsol/sunlinsol_band.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_band.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include <cstdlib>
#include <cstring>
#include <string>

#include "reduced1d/serial_kernels.hpp"

namespace swim::reduced1d::sun {

namespace {
std::string compose(const std::string& where, int flag, const std::string& name,
                    const std::string& detail) {
  std::string m = where + " returned " + name + " (" + std::to_string(flag) + ")";
  if (!detail.empty()) m += ": " + detail;
  return m;
}
}  // namespace

SundialsError::SundialsError(std::string where, int flag, std::string flag_name, std::string detail)
    : std::runtime_error(compose(where, flag, flag_name, detail)),
      where_(std::move(where)),
      flag_(flag),
      flag_name_(std::move(flag_name)),
      detail_(std::move(detail)) {}

int check(int flag, const char* where, const std::string& detail) {
  if (flag >= 0) return flag;
  std::string name;
  if (std::strncmp(where, "IDA", 3) == 0) {
    char* n = IDAGetReturnFlagName(flag);
    if (n) {
      name = n;
      free(n);
    }
  } else {
    char* n = CVodeGetReturnFlagName(flag);
    if (n) {
      name = n;
      free(n);
    }
  }
  if (name.empty()) name = "flag";
  throw SundialsError(where, flag, name, detail);
}

void ContextDeleter::operator()(SUNContext c) const {
  if (c) SUNContext_Free(&c);
}
void VectorDeleter::operator()(N_Vector v) const {
  if (v) N_VDestroy(v);
}
void MatrixDeleter::operator()(SUNMatrix m) const {
  if (m) SUNMatDestroy(m);
}
void LinSolDeleter::operator()(SUNLinearSolver s) const {
  if (s) SUNLinSolFree(s);
}
void NonlinSolDeleter::operator()(SUNNonlinearSolver s) const {
  if (s) SUNNonlinSolFree(s);
}
void CvodeDeleter::operator()(void* mem) const {
  if (mem) CVodeFree(&mem);
}
void IdaDeleter::operator()(void* mem) const {
  if (mem) IDAFree(&mem);
}

Context make_context() {
  SUNContext c = nullptr;
  check(SUNContext_Create(nullptr, &c), "SUNContext_Create");
  return Context(check_ptr(c, "SUNContext_Create"));
}

Vector make_vector(long n, SUNContext ctx) {
  Vector v(check_ptr(N_VNew_Serial(n, ctx), "N_VNew_Serial"));
  install_vector_kernels(v.get());
  N_VConst(0.0, v.get());
  return v;
}

Matrix make_band_matrix(long n, long mu, long ml, SUNContext ctx) {
  Matrix A(check_ptr(SUNBandMatrixStorage(n, mu, ml, mu, ctx), "SUNBandMatrixStorage"));
  install_band_kernels(A.get());
  return A;
}

Matrix make_dense_matrix(long n, SUNContext ctx) {
  return Matrix(check_ptr(SUNDenseMatrix(n, n, ctx), "SUNDenseMatrix"));
}

LinearSolver make_band_solver(N_Vector y, SUNMatrix A, SUNContext ctx) {
  return LinearSolver(check_ptr(SUNLinSol_Band(y, A, ctx), "SUNLinSol_Band"));
}

LinearSolver make_dense_solver(N_Vector y, SUNMatrix A, SUNContext ctx) {
  return LinearSolver(check_ptr(SUNLinSol_Dense(y, A, ctx), "SUNLinSol_Dense"));
}

NonlinearSolver make_fixed_point_solver(N_Vector y, int m_accel, SUNContext ctx) {
  return NonlinearSolver(check_ptr(SUNNonlinSol_FixedPoint(y, m_accel, ctx), "SUNNonlinSol_FixedPoint"));
}

CvodeMem make_cvode(int lmm, SUNContext ctx) {
  return CvodeMem(check_ptr(CVodeCreate(lmm, ctx), "CVodeCreate"));
}

IdaMem make_ida(SUNContext ctx) { return IdaMem(check_ptr(IDACreate(ctx), "IDACreate")); }

void capture_error(int error_code, const char* module, const char* function, char* msg,
                   void* user_data) {
  if (!user_data) return;
  auto* s = static_cast<std::string*>(user_data);
  *s = std::string(function ? function : "") + ": " + (msg ? msg : "");
}

}  // namespace swim::reduced1d::sun
