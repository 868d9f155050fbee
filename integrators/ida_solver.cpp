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
  /// During integrateAdjoint: the time each backward residual is evaluated at (progress).
  std::function<void(double)> backwardTime;
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

  // adjoint sensitivities (docs/sensitivities.md): recording with checkpoints, the
  // outputs' integrals as forward quadratures, one backward problem per output
  IntegralOutputs* outputs = nullptr;
  N_Vector quad = nullptr;
  bool recording = false;
  /// One backward problem: its matrix, linear solver and vectors.
  struct Backward {
    Impl* self = nullptr;
    int k = 0;  ///< the output
    int which = -1;
    SUNMatrix A = nullptr;
    SUNLinearSolver LS = nullptr;
    N_Vector y = nullptr, yp = nullptr, q = nullptr, atol = nullptr, atolQ = nullptr, id = nullptr;
    ~Backward() {
      if (LS) SUNLinSolFree(LS);
      if (A) SUNMatDestroy(A);
      for (N_Vector v : {y, yp, q, atol, atolQ, id}) {
        if (v) N_VDestroy(v);
      }
    }
  };
  std::vector<std::unique_ptr<Backward>> backward;
  SparsePattern transposed;       ///< pattern of J^T
  std::vector<int64_t> toTransposed;  ///< position in J^T's values of each of J's
  std::vector<double> jB;         ///< J(-cj_B) on the DAE's pattern
  MatX jDenseB;                   ///< the same, dense (dense linear solver)
  VecX shiftedY, rateShift, adjointTerm;  ///< scratch of the backward residual (n)

  ~Impl() {
    if (yS) N_VDestroyVectorArray(yS, ns);
    if (ypS) N_VDestroyVectorArray(ypS, ns);
    if (mem) IDAFree(&mem);
    backward.clear();
    if (quad) N_VDestroy(quad);
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
  /// of F(t, y, y', p) = 0 (HindmarshEtAl2005; docs/sensitivities.md).
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

  /// The forward quadratures: the outputs' integrands.
  static int quadratureRhs(realtype t, N_Vector y, N_Vector, N_Vector rhs, void* user) {
    auto* self = static_cast<Impl*>(user);
    try {
      self->outputs->integrands(t, N_VGetArrayPointer(y), N_VGetArrayPointer(rhs));
      return 0;
    } catch (...) {
      self->pending = std::current_exception();
      return -1;
    }
  }

  /// (dE/dt) lambda = (E(q + e q') - E(q - e q')) lambda / (2 e) into `out` (central
  /// difference along the motion, NocedalWright2006, sec. 8.1; E = dF/dy' depends on q
  /// only, through M(q)): zero where q' = 0 or M is constant. Allocates nothing.
  void rateJacobianDerivativeProduct(double t, const double* y, const double* yp, const double* lambda,
                                     VecX& out) {
    const auto n = static_cast<Eigen::Index>(shiftedY.size());
    const Eigen::Map<const VecX> Y(y, n), Yp(yp, n);
    out.setZero();
    // E depends on the positions, the first `positions` entries of y (AdjointProblem::positions)
    const double speed = Yp.head(positions).cwiseAbs().maxCoeff();
    if (!(speed > 0.0)) return;
    const double e = kCentralDifferenceFraction * std::max(1.0, Y.head(positions).cwiseAbs().maxCoeff()) / speed;
    for (const double sign : {1.0, -1.0}) {
      shiftedY = Y;
      shiftedY.head(positions) += sign * e * Yp.head(positions);
      rateShift.setZero();
      dae->addRateJacobianProduct(t, shiftedY.data(), yp, lambda, rateShift.data(), *scratch);
      out += (sign / (2.0 * e)) * rateShift;
    }
  }
  long maxSteps = 500;  ///< IntegratorOptions::maxSteps (the backward problems' too)
  int positions = 0;  ///< number of positions (the first entries of y)

  /// The adjoint residual E^T lambda' + (dE/dt)^T lambda - F_y^T lambda + g_y^T (IdasGuide,
  /// "Adjoint sensitivity analysis"; CaoLiPetzoldSerban2003; E = dF/dy' symmetric for GGL:
  /// diag(I, M, 0, 0)).
  static int backwardResidual(realtype t, N_Vector y, N_Vector yp, N_Vector yB, N_Vector ypB, N_Vector rB,
                              void* user) {
    auto* b = static_cast<Backward*>(user);
    Impl* self = b->self;
    try {
      if (self->backwardTime) self->backwardTime(t);
      const double* Y = N_VGetArrayPointer(y);
      const double* Yp = N_VGetArrayPointer(yp);
      const double* L = N_VGetArrayPointer(yB);
      double* r = N_VGetArrayPointer(rB);
      const auto n = static_cast<Eigen::Index>(self->cacheY.size());
      self->updateSensitivityMatrices(t, Y, Yp);
      self->outputs->integrandGradient(b->k, t, Y, r);  // r = g_y^T
      self->dae->addRateJacobianProduct(t, Y, Yp, N_VGetArrayPointer(ypB), r, *self->scratch);
      self->rateJacobianDerivativeProduct(t, Y, Yp, L, self->adjointTerm);
      Eigen::Map<VecX>(r, n) += self->adjointTerm;
      self->adjointTerm.setZero();
      addPatternTransposeProduct(self->dae->pattern(), self->jy.data(), L, self->adjointTerm.data());
      Eigen::Map<VecX>(r, n) -= self->adjointTerm;
      for (Eigen::Index k = 0; k < n; ++k) {
        if (!std::isfinite(r[k])) return 1;
      }
      return 0;
    } catch (...) {
      self->pending = std::current_exception();
      return -1;
    }
  }

  /// The backward Newton matrix dF_B/dlambda + cj_B dF_B/dlambda' = -(F_y - cj_B E)^T =
  /// -J(-cj_B)^T (the (dE/dt) term, O(h) against cj_B E, left out; IdasGuide).
  static int backwardJacobian(realtype t, realtype cjB, N_Vector y, N_Vector yp, N_Vector, N_Vector, N_Vector,
                              SUNMatrix JB, void* user, N_Vector, N_Vector, N_Vector) {
    auto* b = static_cast<Backward*>(user);
    Impl* self = b->self;
    try {
      const SparsePattern& p = self->dae->pattern();
      if (self->sparse) {
        std::fill(self->jB.begin(), self->jB.end(), 0.0);
        JacobianSink sink = JacobianSink::sparse(self->jB.data(), p);
        self->dae->jacobian(t, N_VGetArrayPointer(y), N_VGetArrayPointer(yp), -cjB, sink, *self->scratch);
        const SparsePattern& tp = self->transposed;
        std::memcpy(SUNSparseMatrix_IndexPointers(JB), tp.colStart().data(), tp.colStart().size() * sizeof(sunindextype));
        std::memcpy(SUNSparseMatrix_IndexValues(JB), tp.rowIndex().data(), tp.rowIndex().size() * sizeof(sunindextype));
        double* values = SUNSparseMatrix_Data(JB);
        for (std::size_t k = 0; k < self->jB.size(); ++k) values[self->toTransposed[k]] = -self->jB[k];
        // a fresh factorisation (pivots chosen anew) at every new matrix: KLU's refactorisation
        // keeps the pivots of the first one, taken at T, and SUNDIALS does not factor afresh
        // when it fails; near a start at rest (velocities zero) a pivot vanished and every
        // retry failed (a chain of links: IDA_CONV_FAIL at t = 2e-3)
        if (SUNLinSol_KLUReInit(b->LS, JB, static_cast<sunindextype>(self->jB.size()), SUNKLU_REINIT_PARTIAL) != 0) {
          return -1;
        }
      } else {
        self->jDenseB.setZero();
        JacobianSink sink = JacobianSink::dense(self->jDenseB.data(), p.size());
        self->dae->jacobian(t, N_VGetArrayPointer(y), N_VGetArrayPointer(yp), -cjB, sink, *self->scratch);
        Eigen::Map<MatX>(SUNDenseMatrix_Data(JB), p.size(), p.size()) = -self->jDenseB.transpose();
      }
      return 0;
    } catch (...) {
      self->pending = std::current_exception();
      return -1;
    }
  }

  /// The quadratures of the gradients: g_p - lambda^T F_p per parameter.
  static int backwardQuadrature(realtype t, N_Vector y, N_Vector yp, N_Vector yB, N_Vector, N_Vector rhs,
                                void* user) {
    auto* b = static_cast<Backward*>(user);
    try {
      b->self->outputs->gradientIntegrand(b->k, t, N_VGetArrayPointer(y), N_VGetArrayPointer(yp),
                                          N_VGetArrayPointer(yB), N_VGetArrayPointer(rhs));
      return 0;
    } catch (...) {
      b->self->pending = std::current_exception();
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
  d.maxSteps = o.maxSteps;
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
  t_ = t0;
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
  // the error weights of the sensitivities (IdasGuide, IDASetSensParams).
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

IdaSolver::IdaSolver(const DaeProblem& dae, double t0, const VecX& y0, const VecX& yp0, const IntegratorOptions& o,
                     IntegralOutputs& outputs, long stepsPerCheckpoint)
    : IdaSolver(dae, t0, y0, yp0, o) {
  startQuadratures(outputs, stepsPerCheckpoint);
}

void IdaSolver::startQuadratures(IntegralOutputs& outputs, long stepsPerCheckpoint) {
  Impl& d = *impl_;
  if (stepsPerCheckpoint > 0 && !d.dae->providesRateJacobianProduct()) {
    throw InputError("IdaSolver: adjoint sensitivities need the DAE's rate Jacobian product (GGL or index-3 form)");
  }
  if (outputs.count() < 1) throw InputError("IdaSolver: quadratures without outputs");
  const int n = d.dae->size();
  d.outputs = &outputs;
  d.quad = N_VNew_Serial(outputs.count(), d.ctx);
  if (!d.quad) throw SolverError("IDAS quadratures: out of memory", 0.0, 0.0);
  N_VConst(0.0, d.quad);
  d.check(IDAQuadInit(d.mem, &Impl::quadratureRhs, d.quad), "IDAQuadInit");
  d.check(IDASetQuadErrCon(d.mem, SUNFALSE), "IDASetQuadErrCon");
  if (stepsPerCheckpoint <= 0) return;
  // the BDF's interpolating polynomials (of the step's order; cubic Hermite would cap the
  // forward solution's accuracy between steps at h^4)
  d.check(IDAAdjInit(d.mem, stepsPerCheckpoint, IDA_POLYNOMIAL), "IDAAdjInit");
  d.recording = true;
  // the backward residual's matrices and scratch (J(0) as the forward sensitivities' cache)
  d.jy.assign(static_cast<std::size_t>(d.dae->pattern().nonZeros()), 0.0);
  d.rateProduct = true;
  d.cacheY = VecX::Zero(n);
  d.cacheYp = VecX::Zero(n);
  d.shiftedY = VecX::Zero(n);
  d.rateShift = VecX::Zero(n);
  d.adjointTerm = VecX::Zero(n);
}

VecX IdaSolver::integrals() const {
  const Impl& d = *impl_;
  if (!d.outputs) return VecX();
  realtype t = 0.0;
  const int flag = IDAGetQuad(d.mem, &t, d.quad);
  if (flag < 0) throw SolverError("IDAGetQuad failed: " + flagName(flag), t, 0.0);
  return Eigen::Map<const VecX>(N_VGetArrayPointer(d.quad), d.outputs->count());
}

AdjointSolution IdaSolver::integrateAdjoint(const AdjointProblem& problem, double t0,
                                            const std::function<void(double t, long steps)>& progress) {
  Impl& d = *impl_;
  if (!d.recording || problem.outputs != d.outputs) throw std::logic_error("IdaSolver: adjoint without its recording");
  const int n = d.dae->size();
  const int count = d.outputs->count(), np = d.outputs->parameterCount();
  if (problem.lambdaT.rows() != n || problem.lambdaT.cols() != count || problem.lambdaTp.rows() != n ||
      problem.lambdaTp.cols() != count || problem.atolB.rows() != n || problem.atolB.cols() != count ||
      problem.atolQ.rows() != np || problem.atolQ.cols() != count) {
    throw InputError("IdaSolver: adjoint terminal values and tolerances must be n x count, np x count");
  }
  const double tEnd = t_;
  constexpr double kBackwardInitialStepFraction = 1e-3;
  realtype lastForwardStep = 0.0;
  IDAGetLastStep(d.mem, &lastForwardStep);
  const SparsePattern& p = d.dae->pattern();
  if (d.sparse && d.toTransposed.empty()) {
    std::vector<std::pair<int, int>> entries;
    for (int c = 0; c < p.size(); ++c) {
      for (int64_t k = p.colStart()[c]; k < p.colStart()[c + 1]; ++k) entries.emplace_back(c, static_cast<int>(p.rowIndex()[k]));
    }
    d.transposed = SparsePattern(n, std::move(entries));
    for (int c = 0; c < p.size(); ++c) {
      for (int64_t k = p.colStart()[c]; k < p.colStart()[c + 1]; ++k) {
        d.toTransposed.push_back(d.transposed.find(c, static_cast<int>(p.rowIndex()[k])));
      }
    }
    d.jB.assign(static_cast<std::size_t>(p.nonZeros()), 0.0);
  } else if (!d.sparse) {
    d.jDenseB = MatX::Zero(n, n);
  }
  const VecX ids = d.dae->differentialIds();
  if (problem.positions < 0 || problem.positions > n) throw InputError("IdaSolver: adjoint positions out of range");
  d.positions = problem.positions;
  d.backward.clear();
  for (int k = 0; k < count; ++k) {
    auto b = std::make_unique<Impl::Backward>();
    b->self = &d;
    b->k = k;
    b->y = N_VNew_Serial(n, d.ctx);
    b->yp = N_VNew_Serial(n, d.ctx);
    b->atol = N_VNew_Serial(n, d.ctx);
    b->id = N_VNew_Serial(n, d.ctx);
    b->q = N_VNew_Serial(np, d.ctx);
    b->atolQ = N_VNew_Serial(np, d.ctx);
    if (!b->y || !b->yp || !b->atol || !b->id || !b->q || !b->atolQ) throw SolverError("IDAS adjoint: out of memory", tEnd, 0.0);
    Eigen::Map<VecX>(N_VGetArrayPointer(b->y), n) = problem.lambdaT.col(k);
    Eigen::Map<VecX>(N_VGetArrayPointer(b->yp), n) = problem.lambdaTp.col(k);
    Eigen::Map<VecX>(N_VGetArrayPointer(b->atol), n) = problem.atolB.col(k);
    Eigen::Map<VecX>(N_VGetArrayPointer(b->id), n) = ids;
    Eigen::Map<VecX>(N_VGetArrayPointer(b->atolQ), np) = problem.atolQ.col(k);
    N_VConst(0.0, b->q);
    d.check(IDACreateB(d.mem, &b->which), "IDACreateB");
    d.check(IDAInitB(d.mem, b->which, &Impl::backwardResidual, tEnd, b->y, b->yp), "IDAInitB");
    d.check(IDASVtolerancesB(d.mem, b->which, d.rtol, b->atol), "IDASVtolerancesB");
    d.check(IDASetUserDataB(d.mem, b->which, b.get()), "IDASetUserDataB");
    d.check(IDASetIdB(d.mem, b->which, b->id), "IDASetIdB");
    d.check(IDASetSuppressAlgB(d.mem, b->which, SUNTRUE), "IDASetSuppressAlgB");
    d.check(IDASetMaxNumStepsB(d.mem, b->which, d.maxSteps), "IDASetMaxNumStepsB");
    // the first backward step of an adjoint that starts away from zero (a terminal output,
    // lambda_q or lambda_v(T) != 0): a fraction of the forward run's last one. IDA's own
    // estimate from lambda'(T), weighed by the adjoint's absolute tolerances, gave 4e-11 s for
    // a velocity output of a pendulum, where the corrector failed on the round-off of the
    // adjoint multipliers (cj M against G^T); the whole last step as the first order-1 step
    // cost the spring-mass-damper's gradient 3e-6 of its accuracy. An adjoint that starts
    // from lambda_D = 0 (an integral output) keeps IDA's estimate: the given step doubled
    // the elastic crank's backward steps (78835 against 38911).
    const bool startsAwayFromZero = (problem.lambdaT.col(k).array() * ids.array()).abs().maxCoeff() > 0.0;
    if (lastForwardStep != 0.0 && startsAwayFromZero) {
      d.check(IDASetInitStepB(d.mem, b->which, -kBackwardInitialStepFraction * std::fabs(lastForwardStep)),
              "IDASetInitStepB");
    }
    if (d.sparse) {
      b->A = SUNSparseMatrix(n, n, p.nonZeros(), CSC_MAT, d.ctx);
      if (b->A) b->LS = SUNLinSol_KLU(b->y, b->A, d.ctx);
      // the same fill-reducing ordering: P J^T P^T has the diagonal and the constraint set of P J P^T
      if (b->LS) d.kluOrdering.configure(*SUNLinSol_KLUGetCommon(b->LS));
    } else {
      b->A = SUNDenseMatrix(n, n, d.ctx);
      if (b->A) b->LS = SUNLinSol_Dense(b->y, b->A, d.ctx);
    }
    if (!b->A || !b->LS) throw SolverError("IDAS adjoint: creating the linear solver failed", tEnd, 0.0);
    d.check(IDASetLinearSolverB(d.mem, b->which, b->LS, b->A), "IDASetLinearSolverB");
    d.check(IDASetJacFnB(d.mem, b->which, &Impl::backwardJacobian), "IDASetJacFnB");
    d.check(IDAQuadInitB(d.mem, b->which, &Impl::backwardQuadrature, b->q), "IDAQuadInitB");
    d.check(IDAQuadSVtolerancesB(d.mem, b->which, d.rtol, b->atolQ), "IDAQuadSVtolerancesB");
    d.check(IDASetQuadErrConB(d.mem, b->which, SUNTRUE), "IDASetQuadErrConB");
    d.backward.push_back(std::move(b));
  }
  d.pending = nullptr;
  d.cacheValid = false;
  // the backward steps taken so far by every backward problem
  const auto backwardSteps = [&] {
    long total = 0;
    for (const auto& b : d.backward) {
      long steps = 0;
      if (void* bmem = IDAGetAdjIDABmem(d.mem, b->which); bmem && IDAGetNumSteps(bmem, &steps) == IDA_SUCCESS) {
        total += steps;
      }
    }
    return total;
  };
  // progress from the backward residuals' times (an intermediate tout of IDASolveB would
  // stop the backward problems there: other steps, measured 20 % more on the elastic crank)
  if (progress) d.backwardTime = [&](double t) { progress(t, backwardSteps()); };
  const int flag = IDASolveB(d.mem, t0, IDA_NORMAL);
  d.backwardTime = nullptr;
  if (d.pending) std::rethrow_exception(std::exchange(d.pending, nullptr));
  if (flag < 0) {
    realtype t = 0.0, h = 0.0;
    void* bmem = IDAGetAdjIDABmem(d.mem, d.backward.front()->which);
    if (bmem) {
      IDAGetCurrentTime(bmem, &t);
      IDAGetLastStep(bmem, &h);
    }
    std::ostringstream os;
    os << "IDAS adjoint failed at t = " << t << " with step size " << h << ": " << flagName(flag);
    if (!d.lastIdaMessage.empty()) os << " (" << d.lastIdaMessage << ")";
    throw SolverError(os.str(), t, h);
  }
  AdjointSolution out{MatX::Zero(n, count), MatX::Zero(n, count), MatX::Zero(np, count), backwardSteps()};
  for (const auto& b : d.backward) {
    realtype t = 0.0;
    d.check(IDAGetB(d.mem, b->which, &t, b->y, b->yp), "IDAGetB");
    d.check(IDAGetQuadB(d.mem, b->which, &t, b->q), "IDAGetQuadB");
    out.lambda0.col(b->k) = Eigen::Map<const VecX>(N_VGetArrayPointer(b->y), n);
    out.lambdaRate0.col(b->k) = Eigen::Map<const VecX>(N_VGetArrayPointer(b->yp), n);
    // IDAS's backward quadrature runs from T to t0: q(t0) = -int_{t0}^{T} rhs dt (IdasGuide)
    out.integral.col(b->k) = -Eigen::Map<const VecX>(N_VGetArrayPointer(b->q), np);
  }
  return out;
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
  int checkpoints = 0;
  const int flag = d.recording ? IDASolveF(d.mem, tout, &tret, d.yy, d.yp, IDA_NORMAL, &checkpoints)
                               : IDASolve(d.mem, tout, &tret, d.yy, d.yp, IDA_NORMAL);
  if (d.recording) checkpoints_ = checkpoints;
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
  t_ = tret;
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
