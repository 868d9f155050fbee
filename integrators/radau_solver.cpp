#include "integrators/radau_solver.hpp"

#include <klu.h>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <limits>
#include <sstream>
#include <vector>

#include "core/errors.hpp"
#include "integrators/klu_ordering.hpp"

namespace flexmbd {

namespace {

using Cplx = std::complex<double>;
using VecXc = Eigen::VectorXcd;
using MatXc = Eigen::MatrixXcd;

constexpr double kEps = std::numeric_limits<double>::epsilon();
// Simplified Newton: at most 7 iterations per step (HairerWanner1996, IV.8, p. 121: "nit = 7").
constexpr int kMaxNewtonIterations = 7;
// Newton diverges if the contraction rate theta_k = ||dZ_k|| / ||dZ_k-1|| (HairerWanner1996, IV.8)
// reaches this.
constexpr double kDivergenceRate = 0.99;
// Step-size controller (HairerWanner1996, IV.8, (8.21)-(8.25)): safety factor, and h_new/h within
// [1/5, 8].
constexpr double kSafety = 0.9;
constexpr double kMaxGrowth = 8.0;
constexpr double kMaxShrink = 5.0;
// After a Newton failure the step is halved; a step rejected by the error test at the
// very first step (when no error history exists) is cut by ten (HairerWanner1996, IV.8, p. 124).
constexpr double kNewtonFailureShrink = 0.5;
constexpr double kFirstRejectShrink = 0.1;
// Jacobian reuse (HairerWanner1996, IV.8, p. 124): keep J0, M0 for the next step if the last Newton
// iteration contracted at least this fast.
constexpr double kThetaJacobianReuse = 0.1;
// ...and keep h itself (so the LU factors too) if the new h/h lies in this range.
constexpr double kKeepStepLow = 1.0, kKeepStepHigh = 1.2;
// KLU refactorization keeps the pivot order of the last full factorization; when the
// crude reciprocal condition min|u_ii| / max|u_ii| falls below this fraction of its value
// at that factorization, the pivots are no longer adequate: factor with pivoting again.
constexpr double kRepivotRcondRatio = 1e-3;
// Order choice (RadauStages min < max; docs/formulations.md): one order down when the
// last Newton iteration contracted slower than kRateOrderDown or failed, or at a second
// error-test failure in a row; one up when it
// contracted faster than kRateOrderUp after kStepsBeforeOrderUp steps at this order, the
// step was not a retry and the step size settles (the proposed ratio in the band).
constexpr double kRateOrderDown = 0.8;
constexpr double kRateOrderUp = 0.02;
constexpr long kStepsBeforeOrderUp = 10;
constexpr double kRatioOrderUpLow = 0.8, kRatioOrderUpHigh = 1.3;

// ---------------------------------------------------------------------------------
// The linear algebra of the transformed Newton systems (HairerWanner1996, IV.8, (8.16), for s stages):
//   E_0 = J0 + (gamma / h) M0                     (real)
//   E_k = J0 + ((alpha_k - i beta_k) / h) M0      (complex, k = 1 .. (s-1)/2)
// with J0 = dF/dy and M0 = dF/dy' at the point of the last Jacobian evaluation.

constexpr int kMaxPairs = (kRadauMaxStages - 1) / 2;

class NewtonAlgebra {
 public:
  virtual ~NewtonAlgebra() = default;
  /// J0 = J(cj = 0), M0 = J(1) - J(0) at (t, y, y') (two calls of the problem's jacobian).
  virtual void evaluateJacobian(const DaeProblem& dae, double t, const VecX& y, const VecX& yp, DaeScratch& s) = 0;
  /// Factors E_0 .. E_pairs of the method k for the step size h; false if one is singular.
  virtual bool factor(const RadauCoefficients& k, double h) = 0;
  /// x := E_0^-1 x; false on failure.
  virtual bool solveReal(VecX& x) = 0;
  /// re + i im := E_pair^-1 (re + i im), pair = 1 .. pairs; false on failure.
  virtual bool solveComplex(int pair, VecX& re, VecX& im) = 0;
  /// out = M0 x.
  virtual void multiplyMass(const VecX& x, VecX& out) const = 0;
};

class DenseNewtonAlgebra final : public NewtonAlgebra {
 public:
  explicit DenseNewtonAlgebra(int n) : J0_(n, n), M0_(n, n), E1_(n, n), E2_(n, n), lu1_(n), x_(n), cb_(n), cx_(n) {
    for (auto& lu : lu2_) lu = Eigen::PartialPivLU<MatXc>(n);
  }
  void evaluateJacobian(const DaeProblem& dae, double t, const VecX& y, const VecX& yp, DaeScratch& s) override {
    const int n = static_cast<int>(J0_.rows());
    J0_.setZero();
    M0_.setZero();
    JacobianSink j0 = JacobianSink::dense(J0_.data(), n), j1 = JacobianSink::dense(M0_.data(), n);
    dae.jacobian(t, y.data(), yp.data(), 0.0, j0, s);
    dae.jacobian(t, y.data(), yp.data(), 1.0, j1, s);
    M0_ -= J0_;
  }
  bool factor(const RadauCoefficients& k, double h) override {
    E1_ = J0_ + (k.gamma / h) * M0_;
    lu1_.compute(E1_);
    bool ok = lu1_.matrixLU().diagonal().cwiseAbs().minCoeff() > 0.0 && lu1_.matrixLU().allFinite();
    for (int p = 0; p < k.pairs && ok; ++p) {
      E2_ = J0_.cast<Cplx>() + Cplx(k.alpha[p] / h, -k.beta[p] / h) * M0_.cast<Cplx>();
      lu2_[p].compute(E2_);
      ok = lu2_[p].matrixLU().diagonal().cwiseAbs().minCoeff() > 0.0 && lu2_[p].matrixLU().allFinite();
    }
    return ok;
  }
  bool solveReal(VecX& x) override {
    x_ = lu1_.solve(x);
    x = x_;
    return x.allFinite();
  }
  bool solveComplex(int pair, VecX& re, VecX& im) override {
    cb_.real() = re;
    cb_.imag() = im;
    cx_ = lu2_[pair - 1].solve(cb_);
    re = cx_.real();
    im = cx_.imag();
    return re.allFinite() && im.allFinite();
  }
  void multiplyMass(const VecX& x, VecX& out) const override { out.noalias() = M0_ * x; }

 private:
  MatX J0_, M0_, E1_;
  MatXc E2_;
  Eigen::PartialPivLU<MatX> lu1_;
  std::array<Eigen::PartialPivLU<MatXc>, kMaxPairs> lu2_;
  VecX x_;
  VecXc cb_, cx_;
};

// RAII for KLU's C objects; none of them is copyable.

class KluCommon {
 public:
  /// KLU defaults with the engine's ordering; `ordering` must outlive this object.
  explicit KluCommon(const KluOrdering& ordering) {
    klu_l_defaults(&common_);
    ordering.configure(common_);
  }
  KluCommon(const KluCommon&) = delete;
  KluCommon& operator=(const KluCommon&) = delete;
  klu_l_common* get() { return &common_; }

 private:
  klu_l_common common_;
};

class KluSymbolic {
 public:
  KluSymbolic(SuiteSparse_long n, SuiteSparse_long* Ap, SuiteSparse_long* Ai, klu_l_common* common)
      : common_(common), symbolic_(klu_l_analyze(n, Ap, Ai, common)) {}
  ~KluSymbolic() {
    if (symbolic_) klu_l_free_symbolic(&symbolic_, common_);
  }
  KluSymbolic(const KluSymbolic&) = delete;
  KluSymbolic& operator=(const KluSymbolic&) = delete;
  klu_l_symbolic* get() const { return symbolic_; }

 private:
  klu_l_common* common_;
  klu_l_symbolic* symbolic_;
};

/// A numeric LU (real, or complex with interleaved values) on a fixed symbolic analysis:
/// refactored in place (no allocation) while the pivot order stays adequate.
class KluNumeric {
 public:
  KluNumeric(bool isComplex, klu_l_common* common) : complex_(isComplex), common_(common) {}
  ~KluNumeric() { release(); }
  KluNumeric(const KluNumeric&) = delete;
  KluNumeric& operator=(const KluNumeric&) = delete;

  bool factor(SuiteSparse_long* Ap, SuiteSparse_long* Ai, double* values, klu_l_symbolic* symbolic) {
    if (numeric_) {
      const SuiteSparse_long ok = complex_ ? klu_zl_refactor(Ap, Ai, values, symbolic, numeric_, common_)
                                           : klu_l_refactor(Ap, Ai, values, symbolic, numeric_, common_);
      if (ok && rcond(symbolic) >= kRepivotRcondRatio * rcondAtPivoting_) return true;
      release();
    }
    numeric_ = complex_ ? klu_zl_factor(Ap, Ai, values, symbolic, common_)
                        : klu_l_factor(Ap, Ai, values, symbolic, common_);
    if (!numeric_) return false;
    rcondAtPivoting_ = rcond(symbolic);
    return rcondAtPivoting_ > 0.0;
  }
  bool solve(klu_l_symbolic* symbolic, SuiteSparse_long n, double* b) {
    return (complex_ ? klu_zl_solve(symbolic, numeric_, n, 1, b, common_)
                     : klu_l_solve(symbolic, numeric_, n, 1, b, common_)) != 0;
  }

 private:
  double rcond(klu_l_symbolic* symbolic) {
    const SuiteSparse_long ok =
        complex_ ? klu_zl_rcond(symbolic, numeric_, common_) : klu_l_rcond(symbolic, numeric_, common_);
    return ok && std::isfinite(common_->rcond) ? common_->rcond : 0.0;
  }
  void release() {
    if (!numeric_) return;
    if (complex_) klu_zl_free_numeric(&numeric_, common_);
    else klu_l_free_numeric(&numeric_, common_);
    numeric_ = nullptr;
  }
  bool complex_;
  klu_l_common* common_;
  klu_l_numeric* numeric_ = nullptr;
  double rcondAtPivoting_ = 0.0;
};

class KluNewtonAlgebra final : public NewtonAlgebra {
 public:
  /// The KLU ordering is chosen by trial factorisations at (t0, y0, y0') (KluOrdering).
  KluNewtonAlgebra(const DaeProblem& dae, double t0, const VecX& y0, const VecX& yp0)
      : pattern_(dae.pattern()),
        n_(pattern_.size()),
        Ap_(pattern_.colStart().begin(), pattern_.colStart().end()),
        Ai_(pattern_.rowIndex().begin(), pattern_.rowIndex().end()),
        J0_(Ai_.size()),
        M0_(Ai_.size()),
        E1_(Ai_.size()),
        E2_(2 * Ai_.size()),
        cb_(2 * static_cast<size_t>(n_)),
        ordering_(KluOrdering::choose(dae, t0, y0, yp0, kOrderingTrialCj)),
        common_(ordering_),
        symbolic_(n_, Ap_.data(), Ai_.data(), common_.get()),
        real_(false, common_.get()),
        complex_{KluNumeric(true, common_.get()), KluNumeric(true, common_.get()), KluNumeric(true, common_.get())} {
    if (!symbolic_.get()) throw SolverError("Radau5: KLU's symbolic analysis of the Jacobian pattern failed", 0.0, 0.0);
  }
  void evaluateJacobian(const DaeProblem& dae, double t, const VecX& y, const VecX& yp, DaeScratch& s) override {
    std::fill(J0_.begin(), J0_.end(), 0.0);
    std::fill(M0_.begin(), M0_.end(), 0.0);
    JacobianSink j0 = JacobianSink::sparse(J0_.data(), pattern_), j1 = JacobianSink::sparse(M0_.data(), pattern_);
    dae.jacobian(t, y.data(), yp.data(), 0.0, j0, s);
    dae.jacobian(t, y.data(), yp.data(), 1.0, j1, s);
    for (size_t p = 0; p < M0_.size(); ++p) M0_[p] -= J0_[p];
  }
  bool factor(const RadauCoefficients& k, double h) override {
    const double g = k.gamma / h;
    for (size_t p = 0; p < J0_.size(); ++p) E1_[p] = J0_[p] + g * M0_[p];
    if (!real_.factor(Ap_.data(), Ai_.data(), E1_.data(), symbolic_.get())) return false;
    for (int q = 0; q < k.pairs; ++q) {
      const double a = k.alpha[q] / h, b = k.beta[q] / h;
      for (size_t p = 0; p < J0_.size(); ++p) {
        E2_[2 * p] = J0_[p] + a * M0_[p];
        E2_[2 * p + 1] = -b * M0_[p];
      }
      if (!complex_[q].factor(Ap_.data(), Ai_.data(), E2_.data(), symbolic_.get())) return false;
    }
    return true;
  }
  bool solveReal(VecX& x) override { return real_.solve(symbolic_.get(), n_, x.data()) && x.allFinite(); }
  bool solveComplex(int pair, VecX& re, VecX& im) override {
    for (int i = 0; i < n_; ++i) {
      cb_[2 * i] = re[i];
      cb_[2 * i + 1] = im[i];
    }
    if (!complex_[pair - 1].solve(symbolic_.get(), n_, cb_.data())) return false;
    for (int i = 0; i < n_; ++i) {
      re[i] = cb_[2 * i];
      im[i] = cb_[2 * i + 1];
    }
    return re.allFinite() && im.allFinite();
  }
  void multiplyMass(const VecX& x, VecX& out) const override {
    out.setZero();
    for (int c = 0; c < n_; ++c) {
      for (SuiteSparse_long p = Ap_[c]; p < Ap_[c + 1]; ++p) out[Ai_[p]] += M0_[p] * x[c];
    }
  }

 private:
  const SparsePattern& pattern_;
  int n_;
  std::vector<SuiteSparse_long> Ap_, Ai_;
  std::vector<double> J0_, M0_, E1_, E2_, cb_;
  // destroyed in reverse order: the factors, the analysis, then the settings and groups
  KluOrdering ordering_;  // before common_: holds the CAMD constraint set its ordering callback reads
  KluCommon common_;
  KluSymbolic symbolic_;
  KluNumeric real_;
  std::array<KluNumeric, kMaxPairs> complex_;
};

}  // namespace

// ---------------------------------------------------------------------------------
// The solver.

/// What depends on the stage count besides the method itself.
struct StageSettings {
  const RadauCoefficients* k = nullptr;
  // The estimate is of order s + 1 in h while the method has order 2s - 1: the tolerances
  // are mapped to rtol' = 0.1 rtol^((s+1)/(2s)), atol' = atol rtol'/rtol so that the global
  // error comes out near rtol (tolerance proportionality; HairerWanner1996, IV.8, p. 124, for s = 3).
  double rtol = 0.0, atolFactor = 0.0;
  // Newton stopping tolerance kappa Tol in the rtol'-weighted norm (HairerWanner1996, IV.8, (8.14) and
  // p. 121: max(10 eps / rtol', min(0.03, sqrt(rtol')))), here with kappa Tol scaled by
  // rtol / rtol': the iteration error is held below the user's tolerance, not the
  // transformed one, because the dense-output estimate (judged against the user's
  // tolerance) differentiates the stage values and would otherwise measure the iteration
  // error (measured on the Bari crank at 13th order: 72,000 steps at rtol 1e-5 against
  // 622 with the iteration held 1000 times tighter; docs/formulations.md).
  double newtonTol = 0.0;
  // Hairer & Wanner's own: max(10 eps / rtol', min(0.03, sqrt(rtol'))); an iteration whose increments
  // stall (at round-off) below it counts as converged (RadauSolver::Impl::newton).
  double newtonTolStandard = 0.0;
  // At most 7 simplified Newton iterations with 3 stages (HairerWanner1996, IV.8, p. 121), two more per
  // two more stages (the higher orders start from a less accurate extrapolation).
  int maxNewton = 0;
  double errorExponent = 0.0;  // 1 / (s + 1): the step-size controller's exponent

  StageSettings() = default;
  StageSettings(int stages, double rtolUser) : k(&RadauCoefficients::get(stages)) {
    rtol = 0.1 * std::pow(rtolUser, (stages + 1.0) / (2.0 * stages));
    atolFactor = rtol / rtolUser;
    newtonTolStandard = std::max(10.0 * kEps / rtol, std::min(0.03, std::sqrt(rtol)));
    newtonTol = std::max(10.0 * kEps / rtol, std::min(0.03, std::sqrt(rtol)) * (rtolUser / rtol));
    maxNewton = kMaxNewtonIterations + (stages - 3);
    errorExponent = 1.0 / (stages + 1.0);
  }
};

struct RadauSolver::Impl {
  const DaeProblem& dae;
  std::unique_ptr<DaeScratch> scratch;
  std::unique_ptr<NewtonAlgebra> la;
  bool sparse = false;
  int n = 0;
  VecX differential;  // 1 for unknowns in the error test
  int nDifferential = 0;

  // Orders: the stage counts allowed, the current one and the settings of each.
  RadauStages allowed;
  int s = 3;
  std::array<StageSettings, 3> settings;  // s = 3, 5, 7
  const StageSettings& cur() const { return settings[(s - 3) / 2]; }
  long stepsAtOrder = 0;

  double rtolUser = 0.0;
  VecX atolUser, atolI;  // atolI = atolUser * cur().atolFactor
  long maxSteps = 0;
  double hMax = 0.0, hMin = 0.0, hInitial = 0.0;
  double fixedStep = 0.0;

  // State at the end of the last accepted step.
  double t = 0.0;
  VecX y, yp;
  double h = 0.0;  // next step size to try (0: not chosen yet)
  // The last accepted step [tPoly, tPoly + hPoly] with sPoly stages: y0 and Z, its
  // collocation polynomial.
  bool havePoly = false;
  double tPoly = 0.0, hPoly = 0.0;
  int sPoly = 3;
  VecX yPoly;
  std::array<VecX, kRadauMaxStages> Zpoly;

  // Newton work vectors (per stage).
  std::array<VecX, kRadauMaxStages> Z, dZ, Ystage, Ypstage, Fstage, V;
  VecX scaleNewton, scaleError, err, work, work2;

  // Jacobian and factorization state.
  bool jacobianAtStepStart = false;  // J0, M0 evaluated at (t, y, yp)
  bool needJacobian = true;
  bool factored = false;
  double hFactored = 0.0;
  int sFactored = 0;
  double eta = 1.0;    // eta = theta / (1 - theta) of the last converged Newton iteration (HairerWanner1996, IV.8)
  double theta = 1.0;  // contraction rate of the last Newton iteration

  // Step-size controller state.
  bool first = true, lastRejected = false;
  double hAccepted = 0.0, errAccepted = 0.0;

  IntegratorStats st;
  VecX yOut, ypOut;

  Impl(const DaeProblem& problem, double t0, const VecX& y0, const VecX& yp0, const IntegratorOptions& o,
       RadauStages stages)
      : dae(problem), allowed(stages) {
    n = dae.size();
    const auto validStages = [](int x) { return x == 3 || x == 5 || x == 7; };
    if (!validStages(stages.min) || !validStages(stages.max) || !validStages(stages.initial) ||
        stages.min > stages.max || stages.initial < stages.min || stages.initial > stages.max) {
      throw InputError("RadauSolver: stage counts must be 3, 5 or 7 with min <= initial <= max");
    }
    if (y0.size() != n || yp0.size() != n) {
      throw InputError("RadauSolver: y0 and yp0 must have the DAE size " + std::to_string(n));
    }
    if (o.atol.size() != n) throw InputError("RadauSolver: atol must have the DAE size " + std::to_string(n));
    if (!(o.rtol > 0.0) || !(o.atol.minCoeff() > 0.0)) throw InputError("solver: tolerances must be positive");
    if (o.finiteDifferenceJacobian) {
      throw InputError("solver: fd_jacobian is an option of IDA only; radau uses the model's Jacobian");
    }
    if (!(o.maxSteps > 0)) throw InputError("solver: max_steps must be positive");
    if (!(o.maxStepSize >= 0.0) || !(o.minStepSize >= 0.0) || !(o.initialStepSize >= 0.0)) {
      throw InputError("solver: step size limits must be non-negative");
    }
    scratch = dae.makeScratch();
    rtolUser = o.rtol;
    atolUser = o.atol;
    for (int x = 3; x <= kRadauMaxStages; x += 2) settings[(x - 3) / 2] = StageSettings(x, rtolUser);
    s = stages.initial;
    atolI = atolUser * cur().atolFactor;
    maxSteps = o.maxSteps;
    hMax = o.maxStepSize;
    hMin = o.minStepSize;
    hInitial = o.initialStepSize;
    differential = dae.differentialIds();
    if (differential.size() != n) throw InputError("RadauSolver: differentialIds() must have the DAE size");
    nDifferential = static_cast<int>((differential.array() != 0.0).count());

    LinearSolverKind kind = o.linearSolver;
    if (kind == LinearSolverKind::Automatic) kind = n <= kDenseSizeLimit ? LinearSolverKind::Dense : LinearSolverKind::Klu;
    sparse = kind == LinearSolverKind::Klu;
    if (sparse) la = std::make_unique<KluNewtonAlgebra>(dae, t0, y0, yp0);
    else la = std::make_unique<DenseNewtonAlgebra>(n);

    t = t0;
    y = y0;
    yp = yp0;
    yPoly = VecX::Zero(n);
    for (auto* a : {&Zpoly, &Z, &dZ, &Ystage, &Ypstage, &Fstage, &V}) {
      for (VecX& x : *a) x = VecX::Zero(n);
    }
    for (VecX* x : {&scaleNewton, &scaleError, &err, &work, &work2}) *x = VecX::Zero(n);
    yOut = y0;
    ypOut = yp0;
    st.currentTime = t0;
  }

  [[noreturn]] void fail(const std::string& reason, double hh) const {
    std::ostringstream os;
    os << "Radau IIA (order " << 2 * s - 1 << ") failed at t = " << t << " with step size " << hh << ": " << reason;
    throw SolverError(os.str(), t, hh);
  }

  /// Weighted RMS over the differential unknowns.
  double errorNorm(const VecX& e, const VecX& scale) const {
    if (nDifferential == 0) return 0.0;
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
      if (differential[i] != 0.0) sum += (e[i] / scale[i]) * (e[i] / scale[i]);
    }
    return std::sqrt(sum / nDifferential);
  }

  /// Starting values of Newton: the last step's collocation polynomial (of its own stage
  /// count) extrapolated to t + c_i h (HairerWanner1996, IV.8, p. 120), Z_i = u(t + c_i h) - y, with
  /// y = u(tPoly + hPoly) = yPoly + Zpoly_sPoly; at the first step Z_i = c_i h y'_0.
  void predict(double hh) {
    const RadauCoefficients& k = *cur().k;
    if (!havePoly) {
      for (int i = 0; i < s; ++i) Z[i] = (k.c[i] * hh) * yp;
      return;
    }
    const RadauCoefficients& kp = *settings[(sPoly - 3) / 2].k;
    for (int i = 0; i < s; ++i) {
      const RadauVector L = kp.lagrange(1.0 + k.c[i] * hh / hPoly);
      Z[i] = -Zpoly[sPoly - 1];
      for (int j = 0; j < sPoly; ++j) Z[i] += L[j] * Zpoly[j];
    }
  }

  /// h Y'_i = sum_j W_ij Z_j, i.e. out = (1/h) sum_j W_ij Z_j (HairerWanner1996, IV.8).
  void stageDerivative(const RadauCoefficients& k, int i, double hh, VecX& out) const {
    out = (k.W(i, 0) / hh) * Z[0];
    for (int j = 1; j < s; ++j) out += (k.W(i, j) / hh) * Z[j];
  }

  struct NewtonResult {
    bool converged = false;
    int iterations = 0;
    double rate = 0.0;  // contraction rate of the last iteration (0 after one iteration)
    const char* failure = "";
  };

  /// The iteration stopped contracting (round-off) or ran out of iterations above the
  /// tighter target, but its last iterate passed Hairer & Wanner's own test (or the increments stall
  /// below it): converged, as Hairer & Wanner would have stopped.
  NewtonResult stalledAtRoundOff(NewtonResult r, double rate) {
    eta = rate < 1.0 ? rate / (1.0 - rate) : 1.0;
    r.converged = true;
    return r;
  }

  /// Simplified Newton on F(t + c_i h, y + Z_i, (1/h) sum_j W_ij Z_j) = 0, i = 1..s, with
  /// the frozen matrix I (x) J0 + (1/h) W (x) M0 transformed by T (HairerWanner1996, IV.8, (8.13)-(8.16)).
  NewtonResult newton(double hh) {
    const StageSettings& ss = cur();
    const RadauCoefficients& k = *ss.k;
    NewtonResult r;
    for (int i = 0; i < n; ++i) scaleNewton[i] = atolI[i] + ss.rtol * std::abs(y[i]);
    double etaK = std::pow(std::max(eta, kEps), 0.8);  // HairerWanner1996, IV.8, p. 121 (first iteration)
    double normPrev = 0.0;
    bool metStandard = false;  // the current Z passed Hairer & Wanner's own stopping test
    for (int it = 1; it <= ss.maxNewton; ++it) {
      r.iterations = it;
      ++st.nonlinearIterations;
      for (int i = 0; i < s; ++i) {
        Ystage[i] = y + Z[i];
        stageDerivative(k, i, hh, Ypstage[i]);
        dae.residual(t + k.c[i] * hh, Ystage[i].data(), Ypstage[i].data(), Fstage[i].data(), *scratch);
        ++st.residualEvals;
        if (!Fstage[i].allFinite()) {
          r.failure = "the residual is not finite (NaN or Inf) at a stage";
          return r;
        }
      }
      // right-hand sides V = -(T^-1 (x) I) F, then E_0 V_0 = rhs_0, E_p (V_2p-1 + i V_2p) = ...
      // (HairerWanner1996, IV.8, (8.16))
      for (int q = 0; q < s; ++q) {
        V[q] = -k.Tinv(q, 0) * Fstage[0];
        for (int i = 1; i < s; ++i) V[q] -= k.Tinv(q, i) * Fstage[i];
      }
      bool solved = la->solveReal(V[0]);
      for (int p = 1; p <= k.pairs && solved; ++p) solved = la->solveComplex(p, V[2 * p - 1], V[2 * p]);
      if (!solved) {
        r.failure = "the linear solve of the Newton system failed";
        return r;
      }
      double sum = 0.0;
      for (int i = 0; i < s; ++i) {
        dZ[i] = k.T(i, 0) * V[0];  // dZ = (T (x) I) V
        for (int q = 1; q < s; ++q) dZ[i] += k.T(i, q) * V[q];
        sum += (dZ[i].array() / scaleNewton.array()).square().sum();
      }
      const double norm = std::sqrt(sum / (static_cast<double>(s) * n));
      if (!std::isfinite(norm)) {
        r.failure = "the Newton increment is not finite";
        return r;
      }
      if (it >= 2) {
        const double thetaK = norm / normPrev;  // HairerWanner1996, IV.8, (8.11)
        r.rate = thetaK;
        theta = thetaK;
        if (thetaK >= kDivergenceRate) {
          if (metStandard || norm <= ss.newtonTolStandard) return stalledAtRoundOff(r, thetaK);
          r.failure = "the Newton iteration diverges";
          return r;
        }
        etaK = thetaK / (1.0 - thetaK);  // HairerWanner1996, IV.8, (8.12)
        // predicted error after the remaining iterations (HairerWanner1996, IV.8, p. 121), against
        // Hairer & Wanner's own tolerance: the tighter target never fails an iteration they would accept
        if (etaK * norm * std::pow(thetaK, ss.maxNewton - it) > ss.newtonTolStandard) {
          if (metStandard) return stalledAtRoundOff(r, thetaK);
          r.failure = "the Newton iteration converges too slowly";
          return r;
        }
      }
      for (int i = 0; i < s; ++i) Z[i] += dZ[i];
      if (etaK * norm <= ss.newtonTol) {  // stopping criterion eta_k ||dZ_k|| <= kappa Tol (HairerWanner1996, (8.14))
        eta = etaK;
        r.converged = true;
        return r;
      }
      metStandard = etaK * norm <= ss.newtonTolStandard;  // Hairer & Wanner would stop here
      normPrev = norm;
    }
    if (metStandard) return stalledAtRoundOff(r, theta);
    r.failure = "the Newton iteration did not converge in its iteration limit";
    return r;
  }

  /// Stiffly filtered error estimate (derived in docs/formulations.md): for M y' = f the
  /// estimate of HairerWanner1996, IV.8, (8.19)-(8.20) is err = (I - h gamma0 J)^-1 (yhat_1 - y_1); for
  /// F(t, y, y') = 0 with E_0 = J0 + (gamma/h) M0 this is
  ///   err = E_0^-1 M0 (y'_0 + (gamma/h) sum_j d_j Z_j).
  /// If err >= 1 at the first step or after a rejection, the improved estimate of
  /// (8.20), f(y0 + err) in place of f(y0), reads here err := err - E_0^-1 F(t0, y0 + err, y'_0)
  /// (M0 y'_0 - F(t0, y0 + err, y'_0) = f(y0 + err) for M y' - f); only the differential
  /// unknowns are perturbed.
  /// The filter removes what is stiff and what the constraints fix: for a mechanism whose
  /// motion a rheonomic driver prescribes, or a stiff component slaved to a smooth forcing,
  /// the step ends are exact but nothing would bound the step, and the output between
  /// them (the collocation polynomial) would be poor. So the defect of the collocation
  /// polynomial u at the point xDense where its interpolation error peaks is estimated
  /// too, filtered the same way, errD = E_0^-1 F(t0 + x h, u, u'), and the larger of the
  /// two norms is the step's error (docs/formulations.md).
  double estimateError(double hh) {
    const StageSettings& ss = cur();
    const RadauCoefficients& k = *ss.k;
    const double g = k.gamma / hh;
    work = yp;
    for (int j = 0; j < s; ++j) work += (g * k.d[j]) * Z[j];
    la->multiplyMass(work, err);
    if (!la->solveReal(err)) return std::numeric_limits<double>::infinity();
    for (int i = 0; i < n; ++i) {
      scaleError[i] = atolI[i] + ss.rtol * std::max(std::abs(y[i]), std::abs(y[i] + Z[s - 1][i]));
    }
    double e = errorNorm(err, scaleError);
    if (e >= 1.0 && (first || lastRejected)) {
      work = y + err.cwiseProduct(differential);
      dae.residual(t, work.data(), yp.data(), work2.data(), *scratch);
      ++st.residualEvals;
      if (work2.allFinite() && la->solveReal(work2)) {
        err -= work2;
        e = errorNorm(err, scaleError);
      }
    }
    // dense output: the defect of u at xDense, less its part interpolated from the
    // residual at the step start, F(t0, y0, y'_0): zero for an exact last step, but y0 and
    // y'_0 carry what the last step's Newton iteration left (in the constraint rows above
    // all), which u(x) inherits near the start and which does not shrink with h; at the
    // nodes c_i the defect is zero, so what remains is the interpolation error of the defect
    const double x = k.xDense;
    const RadauVector L = k.lagrange(x), Lp = k.lagrangeDerivative(x) / hh;
    work = y;
    Ypstage[0].setZero();  // u'(x) (the stage vectors are free after Newton)
    for (int j = 0; j < s; ++j) {
      work += L[j] * Z[j];
      Ypstage[0] += Lp[j] * Z[j];
    }
    dae.residual(t + x * hh, work.data(), Ypstage[0].data(), work2.data(), *scratch);
    dae.residual(t, y.data(), yp.data(), Fstage[0].data(), *scratch);
    st.residualEvals += 2;
    work2 -= k.lagrangeOfStart(x) * Fstage[0];
    if (!work2.allFinite() || !la->solveReal(work2)) return std::numeric_limits<double>::infinity();
    // the output error does not propagate: it is held to the user's tolerances, not the
    // transformed ones (weights atol + rtol |y| = (rtol / rtol') scaleError)
    e = std::max(e, (ss.rtol / rtolUser) * errorNorm(work2, scaleError));
    return std::isfinite(e) ? e : std::numeric_limits<double>::infinity();
  }

  void ensureMatrices(double hh) {
    if (needJacobian && !jacobianAtStepStart) {
      la->evaluateJacobian(dae, t, y, yp, *scratch);
      ++st.jacobianEvals;
      jacobianAtStepStart = true;
      factored = false;
    }
    needJacobian = false;
    if (factored && hh == hFactored && s == sFactored) return;
    ++st.linearSetups;
    factored = la->factor(*cur().k, hh);
    hFactored = hh;
    sFactored = s;
  }

  /// Switches to `stages`; the error history of the old order does not carry over.
  void setStages(int stages) {
    if (stages == s) return;
    s = stages;
    atolI = atolUser * cur().atolFactor;
    stepsAtOrder = 0;
    hAccepted = 0.0;
  }

  /// One accepted step (with as many retries as needed), not past tStop.
  void step(double tStop) {
    const char* lastFailure = "";
    for (;;) {
      double hh = fixedStep > 0.0 ? fixedStep : h;
      if (hMax > 0.0) hh = std::min(hh, hMax);
      bool hitsStop = false;
      if (t + 1.0001 * hh >= tStop) {  // land on tStop (also when only slightly short of it)
        hh = tStop - t;
        hitsStop = true;
      }
      if (!hitsStop && hh < hMin) {
        std::ostringstream os;
        os << "the step size fell below min_step = " << hMin;
        if (*lastFailure) os << " (last failure: " << lastFailure << ")";
        fail(os.str(), hh);
      }
      if (!(t + hh > t)) fail("the step size is below the resolution of t", hh);

      ensureMatrices(hh);
      NewtonResult nr;
      if (!factored) {
        nr.failure = "the Newton matrix is singular";
      } else {
        predict(hh);
        nr = newton(hh);
      }
      if (!nr.converged) {
        ++st.nonlinearConvFailures;
        lastFailure = nr.failure;
        if (fixedStep > 0.0) fail(std::string("fixed step size: ") + nr.failure, hh);
        h = kNewtonFailureShrink * hh;
        if (s > allowed.min) setStages(s - 2);  // a lower order converges more easily
        lastRejected = true;
        needJacobian = true;  // refreshed unless already evaluated at this step's start
        continue;
      }
      const double e = estimateError(hh);
      // step-size proposal h_new = h * fac * err^(-1/(s+1)) with fac decreasing with the
      // Newton iterations (HairerWanner1996, IV.8, (8.21) and p. 124)
      const int nit = cur().maxNewton;
      const double fac = std::min(kSafety, kSafety * (2 * nit + 1) / (2 * nit + nr.iterations));
      double quot = std::clamp(std::pow(e, cur().errorExponent) / fac, 1.0 / kMaxGrowth, kMaxShrink);
      if (e <= 1.0 || fixedStep > 0.0) {
        accept(hh, hitsStop, tStop, e, quot, nr);
        return;
      }
      ++st.errorTestFailures;
      lastFailure = "error test failed";
      h = first ? kFirstRejectShrink * hh : hh / quot;
      if (lastRejected && s > allowed.min) setStages(s - 2);  // a second rejection in a row: lower the order
      lastRejected = true;
      needJacobian = true;
    }
  }

  void accept(double hh, bool hitsStop, double tStop, double e, double quot, const NewtonResult& nr) {
    const RadauCoefficients& k = *cur().k;
    ++st.steps;
    ++stepsAtOrder;
    yPoly = y;
    for (int i = 0; i < s; ++i) Zpoly[i] = Z[i];
    sPoly = s;
    tPoly = t;
    hPoly = hh;
    havePoly = true;
    y += Z[s - 1];                      // stiffly accurate: y_1 = Y_s (HairerWanner1996)
    stageDerivative(k, s - 1, hh, yp);  // u'(t_1) = Y'_s
    t = hitsStop ? tStop : t + hh;
    jacobianAtStepStart = false;
    // predictive controller (Gustafsson; HairerWanner1996, IV.8, (8.25)): h_new = fac h_n err_n^(-1/(s+1))
    // (h_n / h_n-1) (err_n-1 / err_n)^(1/(s+1)); the smaller of the two proposals is taken
    if (hAccepted > 0.0) {
      const double quotGus = std::clamp(
          (hAccepted / hh) * std::pow(e * e / errAccepted, cur().errorExponent) / kSafety, 1.0 / kMaxGrowth,
          kMaxShrink);
      quot = std::max(quot, quotGus);
    }
    hAccepted = hh;
    errAccepted = std::max(1e-2, e);
    double hNew = hh / quot;
    if (lastRejected) hNew = std::min(hNew, hh);  // no growth right after a rejection
    const bool wasRejected = lastRejected;
    lastRejected = false;
    first = false;
    needJacobian = theta > kThetaJacobianReuse;
    const double ratio = hNew / hh;
    if (!needJacobian && ratio >= kKeepStepLow && ratio <= kKeepStepHigh) hNew = hh;  // keep the LU
    h = hNew;
    if (fixedStep <= 0.0) chooseStages(nr, ratio, wasRejected);
  }

  /// The order for the next step (HairerWanner1999, sec. 5: the contraction of the simplified
  /// Newton iteration as the signal; thresholds and the waiting time are this solver's,
  /// docs/formulations.md): a Newton iteration that contracts fast says the step is
  /// limited by accuracy, not by stiffness, where a higher order takes longer steps; one
  /// that contracts slowly says the opposite.
  void chooseStages(const NewtonResult& nr, double ratio, bool wasRejected) {
    if (allowed.min == allowed.max) return;
    const double rate = nr.iterations >= 2 ? nr.rate : 0.0;
    if (s > allowed.min && rate > kRateOrderDown) {
      setStages(s - 2);
    } else if (s < allowed.max && rate < kRateOrderUp && !wasRejected && stepsAtOrder >= kStepsBeforeOrderUp &&
               ratio >= kRatioOrderUpLow && ratio <= kRatioOrderUpHigh) {
      setStages(s + 2);
    }
  }

  /// y, y' at time tout of the last step's collocation polynomial.
  void interpolate(double tout) {
    const RadauCoefficients& kp = *settings[(sPoly - 3) / 2].k;
    const double x = (tout - tPoly) / hPoly;
    const RadauVector L = kp.lagrange(x), Lp = kp.lagrangeDerivative(x) / hPoly;
    yOut = yPoly;
    ypOut.setZero();
    for (int j = 0; j < sPoly; ++j) {
      yOut += L[j] * Zpoly[j];
      ypOut += Lp[j] * Zpoly[j];
    }
  }

  void chooseInitialStep(double tout) {
    if (hInitial > 0.0) {
      h = hInitial;
      return;
    }
    // as IDA's first step: 0.001 of the distance to tout, at most a change of half a
    // tolerance along y'_0
    for (int i = 0; i < n; ++i) scaleNewton[i] = atolI[i] + cur().rtol * std::abs(y[i]);
    h = 1e-3 * std::abs(tout - t);
    const double ypNorm = errorNorm(yp, scaleNewton);
    if (ypNorm * h > 0.5) h = 0.5 / ypNorm;
    if (hMax > 0.0) h = std::min(h, hMax);
    h = std::max(h, std::max(hMin, 1e3 * kEps * std::max(1.0, std::abs(t))));
  }

  double advance(double tout, double tStop) {
    if (!(tout <= tStop)) {
      std::ostringstream os;
      os << "Radau IIA: tout = " << tout << " lies beyond the stop time " << tStop;
      throw SolverError(os.str(), t, h);
    }
    if (tout <= t) {
      if (tout == t) {
        yOut = y;
        ypOut = yp;
      } else if (havePoly && tout >= tPoly) {
        interpolate(tout);
      } else {
        std::ostringstream os;
        os << "Radau IIA: tout = " << tout << " lies before the last step [" << tPoly << ", " << t << "]";
        throw SolverError(os.str(), t, h);
      }
      return tout;
    }
    // An exception of the model's residual or Jacobian (an InputError, a ModelError, an
    // assembly bug) is not a solver failure: it leaves as it was thrown.
    if (h <= 0.0) chooseInitialStep(tout);
    long steps = 0;
    while (t < tout) {
      if (++steps > maxSteps) {
        std::ostringstream os;
        os << "more than max_steps = " << maxSteps << " steps on the way to tout = " << tout;
        fail(os.str(), h);
      }
      step(tStop);
    }
    st.currentTime = t;
    st.lastStepSize = hPoly;
    if (t == tout) {
      yOut = y;
      ypOut = yp;
    } else {
      interpolate(tout);
    }
    return tout;
  }
};

RadauSolver::RadauSolver(const DaeProblem& dae, double t0, const VecX& y0, const VecX& yp0,
                         const IntegratorOptions& options, RadauStages stages)
    : impl_(std::make_unique<Impl>(dae, t0, y0, yp0, options, stages)) {}

RadauSolver::~RadauSolver() = default;

double RadauSolver::advance(double tout, double tStop) { return impl_->advance(tout, tStop); }
const VecX& RadauSolver::y() const { return impl_->yOut; }
const VecX& RadauSolver::yp() const { return impl_->ypOut; }
IntegratorStats RadauSolver::stats() const {
  IntegratorStats s = impl_->st;
  s.currentTime = impl_->t;
  s.lastStepSize = impl_->hPoly;
  return s;
}
bool RadauSolver::usesKlu() const { return impl_->sparse; }
int RadauSolver::stages() const { return impl_->sPoly; }

void RadauSolver::setFixedStepSize(double h) {
  if (!(h > 0.0)) throw InputError("RadauSolver::setFixedStepSize: h must be positive");
  impl_->fixedStep = h;
  impl_->h = h;
}

}  // namespace flexmbd
