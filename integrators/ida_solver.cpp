#include "integrators/ida_solver.hpp"

#include <idas/idas.h>
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

  // forward sensitivities (docs/sensitivities.md); ns = 0 without
  ParameterDerivatives* derivatives = nullptr;
  int ns = 0;
  N_Vector* yS = nullptr;
  N_Vector* ypS = nullptr;
  // dF/dy and dF/dy' (CSC values on the DAE's pattern) and dF/dp (n x ns) at the state
  // (cacheT, cacheY, cacheYp): the staggered corrector calls the sensitivity residual
  // several times at one converged state, the matrices are made once per state.
  std::vector<double> jy, jyp;
  bool rateProduct = false;  ///< dF/dy' s' from DaeProblem::addRateJacobianProduct (jyp unused)
  MatX dFdp;
  VecX cacheY, cacheYp;
  double cacheT = 0.0;
  bool cacheValid = false;
  double rtol = 0.0;  ///< the state's relative tolerance (the sensitivities' too)

  ~Impl() {
    if (yS) N_VDestroyVectorArray(yS, ns);
    if (ypS) N_VDestroyVectorArray(ypS, ns);
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

  /// dF/dy = J(cj = 0) (DaeProblem::jacobian) and dF/dp at (t, y, y'), unless they are those
  /// of the last call; dF/dy' = J(1) - J(0) too where the problem has no product of its own.
  void updateSensitivityMatrices(double t, const double* y, const double* yp) {
    const auto n = static_cast<Eigen::Index>(cacheY.size());
    const Eigen::Map<const VecX> Y(y, n), Yp(yp, n);
    if (cacheValid && t == cacheT && Y == cacheY && Yp == cacheYp) return;
    const SparsePattern& p = dae->pattern();
    std::fill(jy.begin(), jy.end(), 0.0);
    JacobianSink sy = JacobianSink::sparse(jy.data(), p);
    dae->jacobian(t, y, yp, 0.0, sy, *scratch);
    if (!rateProduct) {
      std::fill(jyp.begin(), jyp.end(), 0.0);
      JacobianSink syp = JacobianSink::sparse(jyp.data(), p);
      dae->jacobian(t, y, yp, 1.0, syp, *scratch);
      for (std::size_t k = 0; k < jyp.size(); ++k) jyp[k] -= jy[k];
    }
    for (int i = 0; i < ns; ++i) derivatives->residualDerivative(i, t, y, yp, dFdp.col(i).data());
    cacheT = t;
    cacheY = Y;
    cacheYp = Yp;
    cacheValid = true;
  }

  /// r += A x for A in CSC values on the DAE's pattern.
  void addProduct(const std::vector<double>& A, const double* x, double* r) const {
    addPatternProduct(dae->pattern(), A.data(), x, r);
  }

  /// The sensitivity residuals F_y s_i + F_y' s_i' + F_p_i: the forward sensitivity system
  /// of F(t, y, y', p) = 0 (Hindmarsh et al. 2005, ACM TOMS 31(3); docs/sensitivities.md).
  static int sensitivityResidual(int ns, realtype t, N_Vector y, N_Vector yp, N_Vector, N_Vector* yS,
                                 N_Vector* ypS, N_Vector* resS, void* user, N_Vector, N_Vector, N_Vector) {
    auto* self = static_cast<Impl*>(user);
    try {
      self->updateSensitivityMatrices(t, N_VGetArrayPointer(y), N_VGetArrayPointer(yp));
      const auto n = static_cast<Eigen::Index>(self->cacheY.size());
      for (int i = 0; i < ns; ++i) {
        double* r = N_VGetArrayPointer(resS[i]);
        Eigen::Map<VecX>(r, n) = self->dFdp.col(i);
        self->addProduct(self->jy, N_VGetArrayPointer(yS[i]), r);
        if (self->rateProduct) {
          self->dae->addRateJacobianProduct(t, N_VGetArrayPointer(y), N_VGetArrayPointer(yp),
                                            N_VGetArrayPointer(ypS[i]), r, *self->scratch);
        } else {
          self->addProduct(self->jyp, N_VGetArrayPointer(ypS[i]), r);
        }
        for (Eigen::Index k = 0; k < n; ++k) {
          if (!std::isfinite(r[k])) return 1;  // recoverable: a smaller step
        }
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
  d.rtol = o.rtol;
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

IdaSolver::IdaSolver(const DaeProblem& dae, double t0, const VecX& y0, const VecX& yp0, const IntegratorOptions& o,
                     const SensitivityProblem& sensitivity)
    : IdaSolver(dae, t0, y0, yp0, o) {
  startSensitivities(sensitivity);
}

void IdaSolver::startSensitivities(const SensitivityProblem& sp) {
  Impl& d = *impl_;
  const int n = d.dae->size();
  if (!sp.derivatives) throw InputError("IdaSolver: sensitivities without their parameter derivatives");
  const int ns = sp.derivatives->count();
  if (ns < 1 || sp.s0.rows() != n || sp.sp0.rows() != n || sp.s0.cols() != ns || sp.sp0.cols() != ns ||
      sp.scales.size() != ns || sp.atolS.rows() != n || sp.atolS.cols() != ns) {
    throw InputError("IdaSolver: initial sensitivities and their tolerances must be n x count, scales of size count");
  }
  if (!(sp.scales.cwiseAbs().minCoeff() > 0.0)) throw InputError("IdaSolver: parameter scales must be non-zero");
  d.derivatives = sp.derivatives;
  d.yS = N_VCloneVectorArray(ns, d.yy);
  d.ypS = N_VCloneVectorArray(ns, d.yy);
  if (!d.yS || !d.ypS) throw SolverError("IDAS sensitivities: out of memory", 0.0, 0.0);
  d.ns = ns;
  for (int i = 0; i < ns; ++i) {
    Eigen::Map<VecX>(N_VGetArrayPointer(d.yS[i]), n) = sp.s0.col(i);
    Eigen::Map<VecX>(N_VGetArrayPointer(d.ypS[i]), n) = sp.sp0.col(i);
  }
  d.jy.assign(static_cast<std::size_t>(d.dae->pattern().nonZeros()), 0.0);
  d.rateProduct = d.dae->providesRateJacobianProduct();
  if (!d.rateProduct) d.jyp = d.jy;
  d.dFdp = MatX::Zero(n, ns);
  d.cacheY = VecX::Zero(n);
  d.cacheYp = VecX::Zero(n);
  d.check(IDASensInit(d.mem, ns, IDA_STAGGERED, &Impl::sensitivityResidual, d.yS, d.ypS), "IDASensInit");
  // p = NULL: the parameters enter through the user's sensitivity residual; pbar scales
  // the error weights of the sensitivities (IDAS guide, IDASetSensParams).
  std::vector<realtype> pbar(sp.scales.data(), sp.scales.data() + ns);
  d.check(IDASetSensParams(d.mem, nullptr, pbar.data(), nullptr), "IDASetSensParams");
  N_Vector* atolS = N_VCloneVectorArray(ns, d.yy);
  if (!atolS) throw SolverError("IDAS sensitivities: out of memory", 0.0, 0.0);
  for (int i = 0; i < ns; ++i) Eigen::Map<VecX>(N_VGetArrayPointer(atolS[i]), n) = sp.atolS.col(i);
  const int flag = IDASensSVtolerances(d.mem, d.rtol, atolS);  // IDAS copies them
  N_VDestroyVectorArray(atolS, ns);
  d.check(flag, "IDASensSVtolerances");
  d.check(IDASetSensErrCon(d.mem, sp.errorControl ? SUNTRUE : SUNFALSE), "IDASetSensErrCon");
  s_ = sp.s0;
  sp_ = sp.sp0;
}

long IdaSolver::sensitivityResidualEvals() const {
  long v = 0;
  if (impl_->ns > 0) IDAGetSensNumResEvals(impl_->mem, &v);
  return v;
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
  if (d.ns > 0) {
    realtype ts = 0.0;
    d.check(IDAGetSens(d.mem, &ts, d.yS), "IDAGetSens");
    d.check(IDAGetSensDky(d.mem, tret, 1, d.ypS), "IDAGetSensDky");
    for (int i = 0; i < d.ns; ++i) {
      s_.col(i) = Eigen::Map<const VecX>(N_VGetArrayPointer(d.yS[i]), n);
      sp_.col(i) = Eigen::Map<const VecX>(N_VGetArrayPointer(d.ypS[i]), n);
    }
  }
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
