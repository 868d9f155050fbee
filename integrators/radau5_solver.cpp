#include "integrators/radau5_solver.hpp"

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

// ---------------------------------------------------------------------------------
// The method's coefficients.

const Radau5Coefficients& Radau5Coefficients::get() {
  static const Radau5Coefficients k = [] {
    Radau5Coefficients r;
    const double s6 = std::sqrt(6.0);
    // Radau IIA, s = 3 (H&W II, IV.5, Table 5.6)
    r.c << (4.0 - s6) / 10.0, (4.0 + s6) / 10.0, 1.0;
    r.A << (88.0 - 7.0 * s6) / 360.0, (296.0 - 169.0 * s6) / 1800.0, (-2.0 + 3.0 * s6) / 225.0,
        (296.0 + 169.0 * s6) / 1800.0, (88.0 + 7.0 * s6) / 360.0, (-2.0 - 3.0 * s6) / 225.0,
        (16.0 - s6) / 36.0, (16.0 + s6) / 36.0, 1.0 / 9.0;
    r.W = r.A.inverse();
    // A^-1 has one real eigenvalue gamma and a pair alpha +- i beta (H&W IV.8, (8.15)). With
    // the eigenvector v = a + i b of alpha + i beta (beta > 0): W a = alpha a - beta b and
    // W b = beta a + alpha b, so T = [v_gamma, a, b] gives T^-1 W T = Lambda (8.16).
    const Eigen::EigenSolver<Eigen::Matrix3d> es(r.W);
    int real = 0, pair = 0;
    for (int k = 0; k < 3; ++k) {
      if (std::abs(es.eigenvalues()[k].imag()) < 1e-12) real = k;
      else if (es.eigenvalues()[k].imag() > 0.0) pair = k;
    }
    r.gamma = es.eigenvalues()[real].real();
    r.alpha = es.eigenvalues()[pair].real();
    r.beta = es.eigenvalues()[pair].imag();
    r.T.col(0) = es.eigenvectors().col(real).real();
    r.T.col(1) = es.eigenvectors().col(pair).real();
    r.T.col(2) = es.eigenvectors().col(pair).imag();
    r.Tinv = r.T.inverse();
    // Embedded method of order 3 (H&W IV.8, (8.17)): yhat_1 = y0 + h (gamma0 y'_0 + sum bhat_i
    // Y'_i) with gamma0 = 1/gamma and bhat from the quadrature conditions sum_i bhat_i c_i^(q-1)
    // + gamma0 0^(q-1) = 1/q, q = 1, 2, 3. With h Y'_i = sum_j W_ij Z_j and y_1 = y0 + h b^T Y':
    // yhat_1 - y_1 = gamma0 h y'_0 + sum_j d_j Z_j, d = W^T (bhat - b) (8.18).
    Eigen::Matrix3d V;
    V.row(0).setOnes();
    V.row(1) = r.c.transpose();
    V.row(2) = r.c.cwiseProduct(r.c).transpose();
    const Eigen::Vector3d bhat = V.inverse() * Eigen::Vector3d(1.0 - 1.0 / r.gamma, 0.5, 1.0 / 3.0);
    r.d = r.W.transpose() * (bhat - r.A.row(2).transpose());
    // Lagrange basis on 0, c1, c2, c3 without constant term (L_j(0) = 0): L_j(c_k) = delta_jk,
    // i.e. [c_k, c_k^2, c_k^3] P = I row by row (collocation polynomial, H&W IV.8 (8.12)).
    Eigen::Matrix3d C;
    for (int k = 0; k < 3; ++k) C.row(k) << r.c[k], r.c[k] * r.c[k], r.c[k] * r.c[k] * r.c[k];
    r.P = C.inverse();
    // extremum of psi(s) = s (s - c1)(s - c2)(s - 1) on (c2, 1), its largest on [0, 1]:
    // bisection on psi'
    auto psi = [&](double s) { return s * (s - r.c[0]) * (s - r.c[1]) * (s - 1.0); };
    auto dpsi = [&](double s) { return (psi(s + 1e-7) - psi(s - 1e-7)) / 2e-7; };
    double lo = r.c[1], hi = 1.0;
    for (int it = 0; it < 60; ++it) {
      const double mid = 0.5 * (lo + hi);
      (dpsi(mid) < 0.0 ? lo : hi) = mid;  // psi decreases from 0 at c2 to its minimum
    }
    r.sDense = 0.5 * (lo + hi);
    return r;
  }();
  return k;
}

namespace {

using Cplx = std::complex<double>;
using VecXc = Eigen::VectorXcd;
using MatXc = Eigen::MatrixXcd;

constexpr double kEps = std::numeric_limits<double>::epsilon();
// Simplified Newton: at most 7 iterations per step (H&W IV.8, p. 121: "nit = 7").
constexpr int kMaxNewtonIterations = 7;
// Newton diverges if the contraction rate theta_k = ||dZ_k|| / ||dZ_k-1|| reaches this.
constexpr double kDivergenceRate = 0.99;
// Step-size controller (H&W IV.8, (8.21)-(8.25)): safety factor, and h_new/h within
// [1/5, 8].
constexpr double kSafety = 0.9;
constexpr double kMaxGrowth = 8.0;
constexpr double kMaxShrink = 5.0;
// After a Newton failure the step is halved; a step rejected by the error test at the
// very first step (when no error history exists) is cut by ten (H&W IV.8, p. 124).
constexpr double kNewtonFailureShrink = 0.5;
constexpr double kFirstRejectShrink = 0.1;
// Jacobian reuse (H&W IV.8, p. 124): keep J0, M0 for the next step if the last Newton
// iteration contracted at least this fast.
constexpr double kThetaJacobianReuse = 0.1;
// ...and keep h itself (so the LU factors too) if the new h/h lies in this range.
constexpr double kKeepStepLow = 1.0, kKeepStepHigh = 1.2;
// KLU refactorization keeps the pivot order of the last full factorization; when the
// crude reciprocal condition min|u_ii| / max|u_ii| falls below this fraction of its value
// at that factorization, the pivots are no longer adequate: factor with pivoting again.
constexpr double kRepivotRcondRatio = 1e-3;

// ---------------------------------------------------------------------------------
// The linear algebra of the transformed Newton systems (H&W IV.8, (8.16)):
//   E1 = J0 + (gamma / h) M0                  (real)
//   E2 = J0 + ((alpha - i beta) / h) M0       (complex)
// with J0 = dF/dy and M0 = dF/dy' at the point of the last Jacobian evaluation.

class NewtonAlgebra {
 public:
  virtual ~NewtonAlgebra() = default;
  /// J0 = J(cj = 0), M0 = J(1) - J(0) at (t, y, y') (two calls of the problem's jacobian).
  virtual void evaluateJacobian(const DaeProblem& dae, double t, const VecX& y, const VecX& yp, DaeScratch& s) = 0;
  /// Factors E1 and E2 for the step size h; false if either is singular.
  virtual bool factor(double h) = 0;
  /// x := E1^-1 x; false on failure.
  virtual bool solveReal(VecX& x) = 0;
  /// re + i im := E2^-1 (re + i im); false on failure.
  virtual bool solveComplex(VecX& re, VecX& im) = 0;
  /// out = M0 x.
  virtual void multiplyMass(const VecX& x, VecX& out) const = 0;
};

class DenseNewtonAlgebra final : public NewtonAlgebra {
 public:
  explicit DenseNewtonAlgebra(int n)
      : J0_(n, n), M0_(n, n), E1_(n, n), E2_(n, n), lu1_(n), lu2_(n), x_(n), cb_(n), cx_(n) {}
  void evaluateJacobian(const DaeProblem& dae, double t, const VecX& y, const VecX& yp, DaeScratch& s) override {
    const int n = static_cast<int>(J0_.rows());
    J0_.setZero();
    M0_.setZero();
    JacobianSink j0 = JacobianSink::dense(J0_.data(), n), j1 = JacobianSink::dense(M0_.data(), n);
    dae.jacobian(t, y.data(), yp.data(), 0.0, j0, s);
    dae.jacobian(t, y.data(), yp.data(), 1.0, j1, s);
    M0_ -= J0_;
  }
  bool factor(double h) override {
    const Radau5Coefficients& k = Radau5Coefficients::get();
    E1_ = J0_ + (k.gamma / h) * M0_;
    E2_ = J0_.cast<Cplx>() + Cplx(k.alpha / h, -k.beta / h) * M0_.cast<Cplx>();
    lu1_.compute(E1_);
    lu2_.compute(E2_);
    return lu1_.matrixLU().diagonal().cwiseAbs().minCoeff() > 0.0 &&
           lu2_.matrixLU().diagonal().cwiseAbs().minCoeff() > 0.0 && lu1_.matrixLU().allFinite() &&
           lu2_.matrixLU().allFinite();
  }
  bool solveReal(VecX& x) override {
    x_ = lu1_.solve(x);
    x = x_;
    return x.allFinite();
  }
  bool solveComplex(VecX& re, VecX& im) override {
    cb_.real() = re;
    cb_.imag() = im;
    cx_ = lu2_.solve(cb_);
    re = cx_.real();
    im = cx_.imag();
    return re.allFinite() && im.allFinite();
  }
  void multiplyMass(const VecX& x, VecX& out) const override { out.noalias() = M0_ * x; }

 private:
  MatX J0_, M0_, E1_;
  MatXc E2_;
  Eigen::PartialPivLU<MatX> lu1_;
  Eigen::PartialPivLU<MatXc> lu2_;
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
        complex_(true, common_.get()) {
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
  bool factor(double h) override {
    const Radau5Coefficients& k = Radau5Coefficients::get();
    const double g = k.gamma / h, a = k.alpha / h, b = k.beta / h;
    for (size_t p = 0; p < J0_.size(); ++p) {
      E1_[p] = J0_[p] + g * M0_[p];
      E2_[2 * p] = J0_[p] + a * M0_[p];
      E2_[2 * p + 1] = -b * M0_[p];
    }
    return real_.factor(Ap_.data(), Ai_.data(), E1_.data(), symbolic_.get()) &&
           complex_.factor(Ap_.data(), Ai_.data(), E2_.data(), symbolic_.get());
  }
  bool solveReal(VecX& x) override { return real_.solve(symbolic_.get(), n_, x.data()) && x.allFinite(); }
  bool solveComplex(VecX& re, VecX& im) override {
    for (int i = 0; i < n_; ++i) {
      cb_[2 * i] = re[i];
      cb_[2 * i + 1] = im[i];
    }
    if (!complex_.solve(symbolic_.get(), n_, cb_.data())) return false;
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
  KluNumeric real_, complex_;
};

}  // namespace

// ---------------------------------------------------------------------------------
// The solver.

struct Radau5Solver::Impl {
  const DaeProblem& dae;
  const Radau5Coefficients& k = Radau5Coefficients::get();
  std::unique_ptr<DaeScratch> scratch;
  std::unique_ptr<NewtonAlgebra> la;
  bool sparse = false;
  int n = 0;
  VecX differential;  // 1 for unknowns in the error test
  int nDifferential = 0;

  // Tolerances. RADAU5's estimate is of order 4 in h while the method has order 5; the
  // tolerances are mapped to rtol' = 0.1 rtol^(2/3), atol' = atol rtol'/rtol so that the
  // global error comes out near rtol (tolerance proportionality, H&W IV.8, p. 124).
  double rtolI = 0.0, rtolUser = 0.0;
  VecX atolI;
  // Newton stopping tolerance kappa Tol in the weighted norm (H&W IV.8, (8.14) and p. 121):
  // max(10 eps / rtol', min(0.03, sqrt(rtol'))).
  double newtonTol = 0.0;
  long maxSteps = 0;
  double hMax = 0.0, hMin = 0.0, hInitial = 0.0;
  double fixedStep = 0.0;

  // State at the end of the last accepted step.
  double t = 0.0;
  VecX y, yp;
  double h = 0.0;  // next step size to try (0: not chosen yet)
  // The last accepted step [tPoly, tPoly + hPoly]: y0 and Z, its collocation polynomial.
  bool havePoly = false;
  double tPoly = 0.0, hPoly = 0.0;
  VecX yPoly;
  std::array<VecX, 3> Zpoly;

  // Newton work vectors (per stage).
  std::array<VecX, 3> Z, dZ, Ystage, Ypstage, Fstage;
  VecX v1, v2, v3, scaleNewton, scaleError, err, work, work2;

  // Jacobian and factorization state.
  bool jacobianAtStepStart = false;  // J0, M0 evaluated at (t, y, yp)
  bool needJacobian = true;
  bool factored = false;
  double hFactored = 0.0;
  double eta = 1.0;    // eta = theta / (1 - theta) of the last converged Newton iteration
  double theta = 1.0;  // contraction rate of the last Newton iteration

  // Step-size controller state.
  bool first = true, lastRejected = false;
  double hAccepted = 0.0, errAccepted = 0.0;

  IntegratorStats st;
  VecX yOut, ypOut;

  Impl(const DaeProblem& problem, double t0, const VecX& y0, const VecX& yp0, const IntegratorOptions& o)
      : dae(problem) {
    n = dae.size();
    if (y0.size() != n || yp0.size() != n) {
      throw InputError("Radau5Solver: y0 and yp0 must have the DAE size " + std::to_string(n));
    }
    if (o.atol.size() != n) throw InputError("Radau5Solver: atol must have the DAE size " + std::to_string(n));
    if (!(o.rtol > 0.0) || !(o.atol.minCoeff() > 0.0)) throw InputError("solver: tolerances must be positive");
    if (o.finiteDifferenceJacobian) {
      throw InputError("solver: fd_jacobian is an option of IDA only; radau5 uses the model's Jacobian");
    }
    if (!(o.maxSteps > 0)) throw InputError("solver: max_steps must be positive");
    if (!(o.maxStepSize >= 0.0) || !(o.minStepSize >= 0.0) || !(o.initialStepSize >= 0.0)) {
      throw InputError("solver: step size limits must be non-negative");
    }
    scratch = dae.makeScratch();
    rtolUser = o.rtol;
    rtolI = 0.1 * std::pow(o.rtol, 2.0 / 3.0);
    atolI = o.atol * (rtolI / o.rtol);
    newtonTol = std::max(10.0 * kEps / rtolI, std::min(0.03, std::sqrt(rtolI)));
    maxSteps = o.maxSteps;
    hMax = o.maxStepSize;
    hMin = o.minStepSize;
    hInitial = o.initialStepSize;
    differential = dae.differentialIds();
    if (differential.size() != n) throw InputError("Radau5Solver: differentialIds() must have the DAE size");
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
    for (auto* a : {&Zpoly, &Z, &dZ, &Ystage, &Ypstage, &Fstage}) {
      for (VecX& x : *a) x = VecX::Zero(n);
    }
    for (VecX* x : {&v1, &v2, &v3, &scaleNewton, &scaleError, &err, &work, &work2}) *x = VecX::Zero(n);
    yOut = y0;
    ypOut = yp0;
    st.currentTime = t0;
  }

  [[noreturn]] void fail(const std::string& reason, double hh) const {
    std::ostringstream os;
    os << "Radau5 failed at t = " << t << " with step size " << hh << ": " << reason;
    throw SolverError(os.str(), t, hh);
  }

  /// Weighted RMS over the differential unknowns.
  double errorNorm(const VecX& e, const VecX& scale) const {
    if (nDifferential == 0) return 0.0;
    double s = 0.0;
    for (int i = 0; i < n; ++i) {
      if (differential[i] != 0.0) s += (e[i] / scale[i]) * (e[i] / scale[i]);
    }
    return std::sqrt(s / nDifferential);
  }

  /// Starting values of Newton: the last step's collocation polynomial extrapolated to
  /// t + c_i h (H&W IV.8, p. 120), Z_i = u(t + c_i h) - y; at the first step Z_i = c_i h y'_0.
  void predict(double hh) {
    if (!havePoly) {
      for (int i = 0; i < 3; ++i) Z[i] = (k.c[i] * hh) * yp;
      return;
    }
    for (int i = 0; i < 3; ++i) {
      const double s = 1.0 + k.c[i] * hh / hPoly;
      const Eigen::Vector3d L = k.P.transpose() * Eigen::Vector3d(s, s * s, s * s * s);
      Z[i] = L[0] * Zpoly[0] + L[1] * Zpoly[1] + (L[2] - 1.0) * Zpoly[2];
    }
  }

  struct NewtonResult {
    bool converged = false;
    int iterations = 0;
    const char* failure = "";
  };

  /// Simplified Newton on F(t + c_i h, y + Z_i, (1/h) sum_j W_ij Z_j) = 0, i = 1..3, with
  /// the frozen matrix I (x) J0 + (1/h) W (x) M0 transformed by T (H&W IV.8, (8.13)-(8.16)).
  NewtonResult newton(double hh) {
    NewtonResult r;
    for (int i = 0; i < n; ++i) scaleNewton[i] = atolI[i] + rtolI * std::abs(y[i]);
    double etaK = std::pow(std::max(eta, kEps), 0.8);  // H&W IV.8, p. 121 (first iteration)
    double normPrev = 0.0;
    for (int it = 1; it <= kMaxNewtonIterations; ++it) {
      r.iterations = it;
      ++st.nonlinearIterations;
      for (int i = 0; i < 3; ++i) {
        Ystage[i] = y + Z[i];
        Ypstage[i] = (k.W(i, 0) / hh) * Z[0] + (k.W(i, 1) / hh) * Z[1] + (k.W(i, 2) / hh) * Z[2];
        dae.residual(t + k.c[i] * hh, Ystage[i].data(), Ypstage[i].data(), Fstage[i].data(), *scratch);
        ++st.residualEvals;
        if (!Fstage[i].allFinite()) {
          r.failure = "the residual is not finite (NaN or Inf) at a stage";
          return r;
        }
      }
      // right-hand sides -(T^-1 (x) I) F, then E1 dV1 = rhs1, E2 (dV2 + i dV3) = rhs2 + i rhs3
      v1 = -k.Tinv(0, 0) * Fstage[0] - k.Tinv(0, 1) * Fstage[1] - k.Tinv(0, 2) * Fstage[2];
      v2 = -k.Tinv(1, 0) * Fstage[0] - k.Tinv(1, 1) * Fstage[1] - k.Tinv(1, 2) * Fstage[2];
      v3 = -k.Tinv(2, 0) * Fstage[0] - k.Tinv(2, 1) * Fstage[1] - k.Tinv(2, 2) * Fstage[2];
      if (!la->solveReal(v1) || !la->solveComplex(v2, v3)) {
        r.failure = "the linear solve of the Newton system failed";
        return r;
      }
      double sum = 0.0;
      for (int i = 0; i < 3; ++i) {
        dZ[i] = k.T(i, 0) * v1 + k.T(i, 1) * v2 + k.T(i, 2) * v3;  // dZ = (T (x) I) dV
        sum += (dZ[i].array() / scaleNewton.array()).square().sum();
      }
      const double norm = std::sqrt(sum / (3.0 * n));
      if (!std::isfinite(norm)) {
        r.failure = "the Newton increment is not finite";
        return r;
      }
      if (it >= 2) {
        const double thetaK = norm / normPrev;  // H&W IV.8, (8.11)
        if (thetaK >= kDivergenceRate) {
          theta = thetaK;
          r.failure = "the Newton iteration diverges";
          return r;
        }
        etaK = thetaK / (1.0 - thetaK);  // (8.12)
        theta = thetaK;
        // predicted error after the remaining iterations (H&W IV.8, p. 121)
        if (etaK * norm * std::pow(thetaK, kMaxNewtonIterations - it) > newtonTol) {
          r.failure = "the Newton iteration converges too slowly";
          return r;
        }
      }
      for (int i = 0; i < 3; ++i) Z[i] += dZ[i];
      if (etaK * norm <= newtonTol) {  // stopping criterion eta_k ||dZ_k|| <= kappa Tol (8.14)
        eta = etaK;
        r.converged = true;
        return r;
      }
      normPrev = norm;
    }
    r.failure = "the Newton iteration did not converge in 7 iterations";
    return r;
  }

  /// Stiffly filtered error estimate (derived in docs/formulations.md): for M y' = f the
  /// estimate of H&W IV.8, (8.19)-(8.20) is err = (I - h gamma0 J)^-1 (yhat_1 - y_1); for
  /// F(t, y, y') = 0 with E1 = J0 + (gamma/h) M0 this is
  ///   err = E1^-1 M0 (y'_0 + (gamma/h) sum_j d_j Z_j).
  /// If err >= 1 at the first step or after a rejection, the improved estimate of
  /// (8.20), f(y0 + err) in place of f(y0), reads here err := err - E1^-1 F(t0, y0 + err, y'_0)
  /// (M0 y'_0 - F(t0, y0 + err, y'_0) = f(y0 + err) for M y' - f); only the differential
  /// unknowns are perturbed.
  /// The filter removes what is stiff and what the constraints fix: for a mechanism whose
  /// motion a rheonomic driver prescribes, or a stiff component slaved to a smooth forcing,
  /// the step ends are exact but nothing would bound the step, and the output between
  /// them (the collocation polynomial, error O(h^4)) would be poor. So the defect of the
  /// collocation polynomial u at the point sDense where its interpolation error peaks is
  /// estimated too, filtered the same way, errD = E1^-1 F(t0 + s h, u, u'), and the larger
  /// of the two norms is the step's error (docs/formulations.md).
  double estimateError(double hh) {
    const double g = k.gamma / hh;
    work = yp + (g * k.d[0]) * Z[0] + (g * k.d[1]) * Z[1] + (g * k.d[2]) * Z[2];
    la->multiplyMass(work, err);
    if (!la->solveReal(err)) return std::numeric_limits<double>::infinity();
    for (int i = 0; i < n; ++i) {
      scaleError[i] = atolI[i] + rtolI * std::max(std::abs(y[i]), std::abs(y[i] + Z[2][i]));
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
    // dense output
    const double s = k.sDense;
    const Eigen::Vector3d L = k.P.transpose() * Eigen::Vector3d(s, s * s, s * s * s);
    const Eigen::Vector3d Lp = k.P.transpose() * Eigen::Vector3d(1.0, 2.0 * s, 3.0 * s * s) / hh;
    work = y + L[0] * Z[0] + L[1] * Z[1] + L[2] * Z[2];
    v1 = Lp[0] * Z[0] + Lp[1] * Z[1] + Lp[2] * Z[2];
    dae.residual(t + s * hh, work.data(), v1.data(), work2.data(), *scratch);
    ++st.residualEvals;
    if (!work2.allFinite() || !la->solveReal(work2)) return std::numeric_limits<double>::infinity();
    // the output error does not propagate: it is held to the user's tolerances, not the
    // transformed ones (weights atol + rtol |y| = (rtol / rtol') scaleError)
    e = std::max(e, (rtolI / rtolUser) * errorNorm(work2, scaleError));
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
    if (factored && hh == hFactored) return;
    ++st.linearSetups;
    factored = la->factor(hh);
    hFactored = hh;
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
        lastRejected = true;
        needJacobian = true;  // refreshed unless already evaluated at this step's start
        continue;
      }
      const double e = estimateError(hh);
      // step-size proposal h_new = h * fac * err^(-1/4) with fac decreasing with the Newton
      // iterations (H&W IV.8, (8.21) and p. 124)
      const double fac =
          std::min(kSafety, kSafety * (2 * kMaxNewtonIterations + 1) / (2 * kMaxNewtonIterations + nr.iterations));
      double quot = std::clamp(std::pow(e, 0.25) / fac, 1.0 / kMaxGrowth, kMaxShrink);
      if (e <= 1.0 || fixedStep > 0.0) {
        accept(hh, hitsStop, tStop, e, quot);
        return;
      }
      ++st.errorTestFailures;
      lastFailure = "error test failed";
      h = first ? kFirstRejectShrink * hh : hh / quot;
      lastRejected = true;
      needJacobian = true;
    }
  }

  void accept(double hh, bool hitsStop, double tStop, double e, double quot) {
    ++st.steps;
    yPoly = y;
    for (int i = 0; i < 3; ++i) Zpoly[i] = Z[i];
    tPoly = t;
    hPoly = hh;
    havePoly = true;
    y += Z[2];  // stiffly accurate: y_1 = Y_3
    yp = (k.W(2, 0) / hh) * Z[0] + (k.W(2, 1) / hh) * Z[1] + (k.W(2, 2) / hh) * Z[2];  // u'(t_1) = Y'_3
    t = hitsStop ? tStop : t + hh;
    jacobianAtStepStart = false;
    // predictive controller (Gustafsson; H&W IV.8, (8.25)): h_new = fac h_n err_n^(-1/4)
    // (h_n / h_n-1) (err_n-1 / err_n)^(1/4); the smaller of the two proposals is taken
    if (hAccepted > 0.0) {
      const double quotGus =
          std::clamp((hAccepted / hh) * std::pow(e * e / errAccepted, 0.25) / kSafety, 1.0 / kMaxGrowth, kMaxShrink);
      quot = std::max(quot, quotGus);
    }
    hAccepted = hh;
    errAccepted = std::max(1e-2, e);
    double hNew = hh / quot;
    if (lastRejected) hNew = std::min(hNew, hh);  // no growth right after a rejection
    lastRejected = false;
    first = false;
    needJacobian = theta > kThetaJacobianReuse;
    const double ratio = hNew / hh;
    if (!needJacobian && ratio >= kKeepStepLow && ratio <= kKeepStepHigh) hNew = hh;  // keep the LU
    h = hNew;
  }

  /// y, y' at time s of the last step's collocation polynomial.
  void interpolate(double tout) {
    const double s = (tout - tPoly) / hPoly;
    const Eigen::Vector3d L = k.P.transpose() * Eigen::Vector3d(s, s * s, s * s * s);
    const Eigen::Vector3d Lp = k.P.transpose() * Eigen::Vector3d(1.0, 2.0 * s, 3.0 * s * s);
    yOut = yPoly + L[0] * Zpoly[0] + L[1] * Zpoly[1] + L[2] * Zpoly[2];
    ypOut = (Lp[0] / hPoly) * Zpoly[0] + (Lp[1] / hPoly) * Zpoly[1] + (Lp[2] / hPoly) * Zpoly[2];
  }

  void chooseInitialStep(double tout) {
    if (hInitial > 0.0) {
      h = hInitial;
      return;
    }
    // as IDA's first step: 0.001 of the distance to tout, at most a change of half a
    // tolerance along y'_0
    for (int i = 0; i < n; ++i) scaleNewton[i] = atolI[i] + rtolI * std::abs(y[i]);
    h = 1e-3 * std::abs(tout - t);
    const double ypNorm = errorNorm(yp, scaleNewton);
    if (ypNorm * h > 0.5) h = 0.5 / ypNorm;
    if (hMax > 0.0) h = std::min(h, hMax);
    h = std::max(h, std::max(hMin, 1e3 * kEps * std::max(1.0, std::abs(t))));
  }

  double advance(double tout, double tStop) {
    if (!(tout <= tStop)) {
      std::ostringstream os;
      os << "Radau5: tout = " << tout << " lies beyond the stop time " << tStop;
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
        os << "Radau5: tout = " << tout << " lies before the last step [" << tPoly << ", " << t << "]";
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

Radau5Solver::Radau5Solver(const DaeProblem& dae, double t0, const VecX& y0, const VecX& yp0,
                           const IntegratorOptions& options)
    : impl_(std::make_unique<Impl>(dae, t0, y0, yp0, options)) {}

Radau5Solver::~Radau5Solver() = default;

double Radau5Solver::advance(double tout, double tStop) { return impl_->advance(tout, tStop); }
const VecX& Radau5Solver::y() const { return impl_->yOut; }
const VecX& Radau5Solver::yp() const { return impl_->ypOut; }
IntegratorStats Radau5Solver::stats() const {
  IntegratorStats s = impl_->st;
  s.currentTime = impl_->t;
  s.lastStepSize = impl_->hPoly;
  return s;
}
bool Radau5Solver::usesKlu() const { return impl_->sparse; }

void Radau5Solver::setFixedStepSize(double h) {
  if (!(h > 0.0)) throw InputError("Radau5Solver::setFixedStepSize: h must be positive");
  impl_->fixedStep = h;
  impl_->h = h;
}

}  // namespace flexmbd
