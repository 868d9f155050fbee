#include "integrators/ida_solver.hpp"

#include <ida/ida.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunlinsol/sunlinsol_klu.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <sstream>
#include <utility>

#include "core/errors.hpp"
#include "integrators/klu_ordering.hpp"

namespace flexmbd {

namespace {

std::string flagName(long flag) {
  char* name = IDAGetReturnFlagName(flag);
  std::string s = name ? name : "unknown flag";
  std::free(name);
  return s;
}

}  // namespace

struct IdaSolver::Impl {
  const DaeProblem* dae = nullptr;
  std::unique_ptr<DaeScratch> scratch;
  SUNContext ctx = nullptr;
  void* mem = nullptr;
  N_Vector yy = nullptr, yp = nullptr, atol = nullptr, id = nullptr;
  SUNMatrix A = nullptr;
  SUNLinearSolver LS = nullptr;
  bool sparse = false;
  KluOrdering kluOrdering;  // holds the CAMD constraint set KLU's ordering callback reads
  // An exception thrown by the model inside a callback: IDA is told to stop (an
  // unrecoverable failure of the callback) and advance() rethrows it with its type.
  std::exception_ptr pending;
  std::string lastIdaMessage;  // last message of IDA's error handler

  ~Impl() {
    if (mem) IDAFree(&mem);
    if (LS) SUNLinSolFree(LS);
    if (A) SUNMatDestroy(A);
    for (N_Vector v : {yy, yp, atol, id}) {
      if (v) N_VDestroy(v);
    }
    if (ctx) SUNContext_Free(&ctx);
  }

  void check(int flag, const char* call) const {
    if (flag < 0) {
      throw SolverError(std::string("IDA set-up failed in ") + call + ": " + flagName(flag), 0.0, 0.0);
    }
  }

  static int residual(realtype t, N_Vector y, N_Vector yp, N_Vector r, void* user) {
    auto* self = static_cast<Impl*>(user);
    try {
      self->dae->residual(t, N_VGetArrayPointer(y), N_VGetArrayPointer(yp), N_VGetArrayPointer(r), *self->scratch);
      const double* F = N_VGetArrayPointer(r);
      const auto n = N_VGetLength(r);
      for (sunindextype k = 0; k < n; ++k) {
        if (!std::isfinite(F[k])) return 1;  // recoverable: IDA retries with a smaller step
      }
      return 0;
    } catch (...) {
      self->pending = std::current_exception();
      return -1;
    }
  }

  static int jacobian(realtype t, realtype cj, N_Vector y, N_Vector yp, N_Vector, SUNMatrix J,
                      void* user, N_Vector, N_Vector, N_Vector) {
    auto* self = static_cast<Impl*>(user);
    try {
      const SparsePattern& p = self->dae->pattern();
      if (self->sparse) {
        // SUNMatZero clears the index arrays too: restore the fixed pattern.
        std::memcpy(SUNSparseMatrix_IndexPointers(J), p.colStart().data(),
                    p.colStart().size() * sizeof(sunindextype));
        std::memcpy(SUNSparseMatrix_IndexValues(J), p.rowIndex().data(),
                    p.rowIndex().size() * sizeof(sunindextype));
        double* values = SUNSparseMatrix_Data(J);
        std::fill(values, values + p.nonZeros(), 0.0);
        JacobianSink sink = JacobianSink::sparse(values, p);
        self->dae->jacobian(t, N_VGetArrayPointer(y), N_VGetArrayPointer(yp), cj, sink, *self->scratch);
      } else {
        SUNMatZero(J);
        JacobianSink sink = JacobianSink::dense(SUNDenseMatrix_Data(J), p.size());
        self->dae->jacobian(t, N_VGetArrayPointer(y), N_VGetArrayPointer(yp), cj, sink, *self->scratch);
      }
      return 0;
    } catch (...) {
      self->pending = std::current_exception();
      return -1;
    }
  }

  static void errorHandler(int, const char* module, const char* function, char* msg, void* user) {
    auto* self = static_cast<Impl*>(user);
    self->lastIdaMessage = std::string(module) + "/" + function + ": " + msg;
  }
};

static_assert(sizeof(sunindextype) == sizeof(int64_t), "SUNDIALS built with 64-bit indices expected");

IdaSolver::IdaSolver(const DaeProblem& dae, double t0, const VecX& y0, const VecX& yp0,
                     const IntegratorOptions& o)
    : impl_(std::make_unique<Impl>()) {
  Impl& d = *impl_;
  d.dae = &dae;
  d.scratch = dae.makeScratch();
  const int n = dae.size();
  if (y0.size() != n || yp0.size() != n) {
    throw InputError("IdaSolver: y0 and yp0 must have the DAE size " + std::to_string(n));
  }
  if (o.atol.size() != n) throw InputError("IdaSolver: atol must have the DAE size " + std::to_string(n));
  if (!(o.rtol > 0.0) || !(o.atol.minCoeff() > 0.0)) throw InputError("solver: tolerances must be positive");
  d.check(SUNContext_Create(nullptr, &d.ctx), "SUNContext_Create");
  d.yy = N_VNew_Serial(n, d.ctx);
  d.yp = N_VNew_Serial(n, d.ctx);
  d.atol = N_VNew_Serial(n, d.ctx);
  d.id = N_VNew_Serial(n, d.ctx);
  if (!d.yy || !d.yp || !d.atol || !d.id) throw SolverError("IDA set-up: out of memory", t0, 0.0);
  Eigen::Map<VecX>(N_VGetArrayPointer(d.yy), n) = y0;
  Eigen::Map<VecX>(N_VGetArrayPointer(d.yp), n) = yp0;
  Eigen::Map<VecX>(N_VGetArrayPointer(d.atol), n) = o.atol;
  Eigen::Map<VecX>(N_VGetArrayPointer(d.id), n) = dae.differentialIds();

  d.mem = IDACreate(d.ctx);
  if (!d.mem) throw SolverError("IDACreate failed", t0, 0.0);
  d.check(IDASetErrHandlerFn(d.mem, &Impl::errorHandler, &d), "IDASetErrHandlerFn");
  d.check(IDAInit(d.mem, &Impl::residual, t0, d.yy, d.yp), "IDAInit");
  d.check(IDASVtolerances(d.mem, o.rtol, d.atol), "IDASVtolerances");
  d.check(IDASetUserData(d.mem, &d), "IDASetUserData");
  d.check(IDASetId(d.mem, d.id), "IDASetId");
  d.check(IDASetSuppressAlg(d.mem, SUNTRUE), "IDASetSuppressAlg");
  d.check(IDASetMaxNumSteps(d.mem, o.maxSteps), "IDASetMaxNumSteps");
  if (o.maxStepSize > 0.0) d.check(IDASetMaxStep(d.mem, o.maxStepSize), "IDASetMaxStep");
  if (o.minStepSize > 0.0) d.check(IDASetMinStep(d.mem, o.minStepSize), "IDASetMinStep");
  if (o.maxOrder != 5) d.check(IDASetMaxOrd(d.mem, o.maxOrder), "IDASetMaxOrd");
  if (o.initialStepSize > 0.0) d.check(IDASetInitStep(d.mem, o.initialStepSize), "IDASetInitStep");

  LinearSolverKind kind = o.linearSolver;
  if (kind == LinearSolverKind::Automatic) {
    kind = (n <= kDenseSizeLimit || o.finiteDifferenceJacobian) ? LinearSolverKind::Dense : LinearSolverKind::Klu;
  }
  if (kind == LinearSolverKind::Klu && o.finiteDifferenceJacobian) {
    throw InputError("solver: fd_jacobian needs the dense linear solver (IDA's difference quotients are dense)");
  }
  d.sparse = kind == LinearSolverKind::Klu;
  usesKlu_ = d.sparse;
  if (d.sparse) {
    d.A = SUNSparseMatrix(n, n, dae.pattern().nonZeros(), CSC_MAT, d.ctx);
    if (!d.A) throw SolverError("SUNSparseMatrix failed", t0, 0.0);
    d.LS = SUNLinSol_KLU(d.yy, d.A, d.ctx);
    if (!d.LS) throw SolverError("creating the linear solver failed", t0, 0.0);
    d.kluOrdering = KluOrdering::choose(dae, t0, y0, yp0, kOrderingTrialCj);
    d.kluOrdering.configure(*SUNLinSol_KLUGetCommon(d.LS));
  } else {
    d.A = SUNDenseMatrix(n, n, d.ctx);
    if (!d.A) throw SolverError("SUNDenseMatrix failed", t0, 0.0);
    d.LS = SUNLinSol_Dense(d.yy, d.A, d.ctx);
  }
  if (!d.LS) throw SolverError("creating the linear solver failed", t0, 0.0);
  d.check(IDASetLinearSolver(d.mem, d.LS, d.A), "IDASetLinearSolver");
  if (!o.finiteDifferenceJacobian) d.check(IDASetJacFn(d.mem, &Impl::jacobian), "IDASetJacFn");
  y_ = y0;
  yp_ = yp0;
}

IdaSolver::~IdaSolver() = default;

double IdaSolver::advance(double tout, double tStop) {
  Impl& d = *impl_;
  d.check(IDASetStopTime(d.mem, tStop), "IDASetStopTime");
  realtype tret = 0.0;
  d.pending = nullptr;
  const int flag = IDASolve(d.mem, tout, &tret, d.yy, d.yp, IDA_NORMAL);
  const int n = static_cast<int>(y_.size());
  // Not a solver failure (an InputError, a ModelError, an assembly bug): it leaves as it was thrown.
  if (d.pending) std::rethrow_exception(std::exchange(d.pending, nullptr));
  if (flag < 0) {
    realtype h = 0.0, tcur = 0.0;
    IDAGetLastStep(d.mem, &h);
    IDAGetCurrentTime(d.mem, &tcur);
    std::ostringstream os;
    os << "IDA failed at t = " << tcur << " with step size " << h << ": " << flagName(flag);
    if (!d.lastIdaMessage.empty()) {
      os << " (" << d.lastIdaMessage << ")";
    }
    // IDASolve returns the solution at its last successful step (tret = tn) on failures
    failureState_ = Eigen::Map<const VecX>(N_VGetArrayPointer(d.yy), n);
    throw SolverError(os.str(), tcur, h);
  }
  y_ = Eigen::Map<const VecX>(N_VGetArrayPointer(d.yy), n);
  yp_ = Eigen::Map<const VecX>(N_VGetArrayPointer(d.yp), n);
  return tret;
}

IntegratorStats IdaSolver::stats() const {
  const Impl& d = *impl_;
  IntegratorStats s;
  long v = 0;
  if (IDAGetNumSteps(d.mem, &v) == IDA_SUCCESS) s.steps = v;
  if (IDAGetNumResEvals(d.mem, &v) == IDA_SUCCESS) s.residualEvals = v;
  if (IDAGetNumJacEvals(d.mem, &v) == IDA_SUCCESS) s.jacobianEvals = v;
  if (IDAGetNumNonlinSolvIters(d.mem, &v) == IDA_SUCCESS) s.nonlinearIterations = v;
  if (IDAGetNumNonlinSolvConvFails(d.mem, &v) == IDA_SUCCESS) s.nonlinearConvFailures = v;
  if (IDAGetNumErrTestFails(d.mem, &v) == IDA_SUCCESS) s.errorTestFailures = v;
  if (IDAGetNumLinSolvSetups(d.mem, &v) == IDA_SUCCESS) s.linearSetups = v;
  realtype h = 0.0, t = 0.0;
  if (IDAGetLastStep(d.mem, &h) == IDA_SUCCESS) s.lastStepSize = h;
  if (IDAGetCurrentTime(d.mem, &t) == IDA_SUCCESS) s.currentTime = t;
  return s;
}

}  // namespace flexmbd
