#include "integrators/cvode_solver.hpp"


#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <exception>
#include <sstream>
#include <string>
#include <utility>

#include "core/stop_request.hpp"
#include "core/errors.hpp"

namespace flexmbd {

namespace {

std::string flagName(int flag) {
  char* name = CVodeGetReturnFlagName(flag);
  std::string s = name ? name : "unknown flag";
  std::free(name);
  return s;
}

}  // namespace

struct CvodeSolver::Impl {
  const OdeSystem* ode = nullptr;
  SUNContext ctx = nullptr;
  void* mem = nullptr;
  N_Vector y = nullptr;
  SUNMatrix A = nullptr;
  SUNLinearSolver LS = nullptr;
  // An exception thrown by the model inside a callback: CVODE is told to stop (an
  // unrecoverable failure of the callback) and advance() rethrows it with its type.
  std::exception_ptr pending;
  std::string lastMessage;

  ~Impl() {
    if (mem) CVodeFree(&mem);
    if (LS) SUNLinSolFree(LS);
    if (A) SUNMatDestroy(A);
    if (y) N_VDestroy(y);
    if (ctx) SUNContext_Free(&ctx);
  }

  void check(int flag, const char* call) const {
    if (flag < 0) {
      throw SolverError(std::string("CVODE set-up failed in ") + call + ": " + flagName(flag), 0.0, 0.0);
    }
  }

  static int rhs(realtype t, N_Vector y, N_Vector ydot, void* user) {
    auto* self = static_cast<Impl*>(user);
    try {
      pollStop(t);  // core/stop_request.hpp: thrown, kept pending and rethrown by advance()
      self->ode->rhs(t, N_VGetArrayPointer(y), N_VGetArrayPointer(ydot));
      const double* f = N_VGetArrayPointer(ydot);
      for (sunindextype k = 0; k < N_VGetLength(ydot); ++k) {
        if (!std::isfinite(f[k])) return 1;  // recoverable: CVODE retries with a smaller step
      }
      return 0;
    } catch (...) {
      self->pending = std::current_exception();
      return -1;
    }
  }

  static int roots(realtype t, N_Vector y, realtype* g, void* user) {
    auto* self = static_cast<Impl*>(user);
    try {
      self->ode->roots(t, N_VGetArrayPointer(y), g);
      return 0;
    } catch (...) {
      self->pending = std::current_exception();
      return -1;
    }
  }

  static void errorHandler(int, const char* module, const char* function, char* msg, void* user) {
    static_cast<Impl*>(user)->lastMessage = std::string(module) + "/" + function + ": " + msg;
  }
};

CvodeSolver::CvodeSolver(const OdeSystem& ode, double t0, const VecX& y0, const CvodeOptions& o)
    : impl_(std::make_unique<Impl>()) {
  Impl& d = *impl_;
  d.ode = &ode;
  const int n = ode.size();
  if (y0.size() != n || n < 1) throw InputError("CvodeSolver: y0 must have the ODE size " + std::to_string(n));
  if (!(o.rtol > 0.0) || !(o.atol > 0.0)) throw InputError("solver: tolerances must be positive");
  d.check(SUNContext_Create(nullptr, &d.ctx), "SUNContext_Create");
  d.y = N_VNew_Serial(n, d.ctx);
  if (!d.y) throw SolverError("CVODE set-up: out of memory", t0, 0.0);
  Eigen::Map<VecX>(N_VGetArrayPointer(d.y), n) = y0;
  d.mem = CVodeCreate(CV_BDF, d.ctx);
  if (!d.mem) throw SolverError("CVodeCreate failed", t0, 0.0);
  d.check(CVodeSetErrHandlerFn(d.mem, &Impl::errorHandler, &d), "CVodeSetErrHandlerFn");
  d.check(CVodeInit(d.mem, &Impl::rhs, t0, d.y), "CVodeInit");
  d.check(CVodeSStolerances(d.mem, o.rtol, o.atol), "CVodeSStolerances");
  d.check(CVodeSetUserData(d.mem, &d), "CVodeSetUserData");
  d.check(CVodeSetMaxNumSteps(d.mem, o.maxSteps), "CVodeSetMaxNumSteps");
  if (o.maxStepSize > 0.0) d.check(CVodeSetMaxStep(d.mem, o.maxStepSize), "CVodeSetMaxStep");
  d.A = SUNDenseMatrix(n, n, d.ctx);
  if (!d.A) throw SolverError("SUNDenseMatrix failed", t0, 0.0);
  d.LS = SUNLinSol_Dense(d.y, d.A, d.ctx);
  if (!d.LS) throw SolverError("SUNLinSol_Dense failed", t0, 0.0);
  d.check(CVodeSetLinearSolver(d.mem, d.LS, d.A), "CVodeSetLinearSolver");
  if (ode.numRoots() > 0) {
    d.check(CVodeRootInit(d.mem, ode.numRoots(), &Impl::roots), "CVodeRootInit");
    roots_.assign(ode.numRoots(), 0);
  }
  y_ = y0;
}

CvodeSolver::~CvodeSolver() = default;

double CvodeSolver::advance(double tout) {
  Impl& d = *impl_;
  d.check(CVodeSetStopTime(d.mem, tout), "CVodeSetStopTime");
  d.pending = nullptr;
  realtype tret = 0.0;
  const int flag = CVode(d.mem, tout, d.y, &tret, CV_NORMAL);
  // Not a solver failure (an InputError, a ModelError, an assembly bug): it leaves as it was thrown.
  if (d.pending) std::rethrow_exception(std::exchange(d.pending, nullptr));
  if (flag < 0) {
    realtype h = 0.0, tcur = 0.0;
    CVodeGetLastStep(d.mem, &h);
    CVodeGetCurrentTime(d.mem, &tcur);
    std::ostringstream os;
    os << "CVODE failed at t = " << tcur << " with step size " << h << ": " << flagName(flag);
    if (!d.lastMessage.empty()) {
      os << " (" << d.lastMessage << ")";
    }
    throw SolverError(os.str(), tcur, h);
  }
  y_ = Eigen::Map<const VecX>(N_VGetArrayPointer(d.y), y_.size());
  rootFound_ = flag == CV_ROOT_RETURN;
  if (rootFound_) {
    d.check(CVodeGetRootInfo(d.mem, roots_.data()), "CVodeGetRootInfo");
  } else {
    std::fill(roots_.begin(), roots_.end(), 0);
  }
  return tret;
}

void CvodeSolver::reinit(double t, const VecX& y) {
  Impl& d = *impl_;
  if (y.size() != y_.size()) throw InputError("CvodeSolver::reinit: wrong state size");
  Eigen::Map<VecX>(N_VGetArrayPointer(d.y), y.size()) = y;
  const CvodeStats before = stats();
  d.check(CVodeReInit(d.mem, t, d.y), "CVodeReInit");  // resets CVODE's counters
  accumulated_ = before;
  y_ = y;
}

CvodeStats CvodeSolver::stats() const {
  const Impl& d = *impl_;
  CvodeStats s = accumulated_;
  long v = 0;
  if (CVodeGetNumSteps(d.mem, &v) == CV_SUCCESS) s.steps += v;
  if (CVodeGetNumRhsEvals(d.mem, &v) == CV_SUCCESS) s.rhsEvals += v;
  if (CVodeGetNumGEvals(d.mem, &v) == CV_SUCCESS) s.rootEvals += v;
  if (CVodeGetNumErrTestFails(d.mem, &v) == CV_SUCCESS) s.errorTestFailures += v;
  if (CVodeGetNumNonlinSolvConvFails(d.mem, &v) == CV_SUCCESS) s.nonlinearConvFailures += v;
  realtype h = 0.0;
  if (CVodeGetLastStep(d.mem, &h) == CV_SUCCESS) s.lastStepSize = h;
  return s;
}

}  // namespace flexmbd
