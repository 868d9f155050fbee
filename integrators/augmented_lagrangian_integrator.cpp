#include "integrators/augmented_lagrangian_integrator.hpp"


#include <algorithm>
#include <cmath>
#include <sstream>
#include <limits>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/SVD>

#include "core/stop_request.hpp"
#include "core/errors.hpp"
#include "core/linear_algebra.hpp"
#include "core/system_evaluation.hpp"

namespace flexmbd {
namespace {

/// Penalty factor alpha relative to the inertia of a step: alpha G^T G ~ kPenalty (4/h^2) M.
/// The multiplier iteration lambda* += alpha g (BayoLedesma1996, eq. 20) reduces a violation in a well-conditioned
/// constraint direction by ~1/kPenalty per Newton iteration, while the Newton matrix loses
/// ~log10(kPenalty) = 6 of its 16 digits: enough for rtol down to 1e-10.
constexpr double kPenalty = 1e6;
/// Constraint directions whose singular value is below this fraction of the largest are
/// nearly dependent: the multiplier iteration contracts there by 1 / (1 + kPenalty
/// kDependentRatio^2) = 1e-2 per iteration at best, and not at all at the singular position.
constexpr double kDependentRatio = 3e-3;
/// A converged position may violate the constraints by at most kMaxViolation error weights
/// of a coordinate of the model's size: more is left only where no position satisfies
/// them (past a driven lock-up, with the nearly dependent directions not corrected).
constexpr double kMaxViolation = 10.0;
/// Newton on the positions has converged when the correction is below this fraction of
/// the error weights (the step's local error is 1 in these units).
constexpr double kNewtonTolerance = 1e-3;
constexpr int kMaxNewtonIterations = 10;
/// Convergence where the multiplier iteration stalls on a nearly dependent constraint: the
/// violation below kConstraintTolerance of the smallest error weight, the last correction
/// below kSingularNewtonTolerance of the weights (the step's local error is 1 in them).
constexpr double kConstraintTolerance = 1.0, kSingularNewtonTolerance = 0.5;
/// ... or the iteration has stalled (corrections shrinking by less than this factor): the
/// violation left is along a nearly dependent direction, which only a move along the
/// bifurcation direction could remove.
constexpr double kStalledContraction = 0.8;
/// Round-off levels, in units of epsilon (|q| + model size): a constraint violation below
/// kRoundOffViolation is not fed into the multipliers, a Newton correction below
/// kRoundOffCorrection ends the iteration (tight atol can ask for less than round-off).
constexpr double kRoundOffViolation = 100.0, kRoundOffCorrection = 1000.0;
/// Velocity and acceleration projections: at most this many passes (one reaches ~1/kPenalty).
constexpr int kProjectionPasses = 2;
/// Step size controller for the local error est ~ h^3 (order 2 method): safety factor,
/// largest growth and shrink factors per step (HairerNorsettWanner, II.4).
constexpr double kSafety = 0.9, kMaxGrowth = 2.0, kMinShrink = 0.2, kMinShrinkRejected = 0.1;
/// An error estimate above 1 that stays above kArtifactPersistence of its value after the
/// step shrank kArtifactShrink times does not scale as h^3: it is accepted if below
/// kMaxArtifactError (measured at the rank-2 change point of a multi-parallelogram: 4.4
/// for every step from 1e-5 down to 1e-12 s).
constexpr double kArtifactShrink = 4.0, kArtifactPersistence = 0.5, kMaxArtifactError = 100.0;
/// A step whose Newton iteration fails is retried with this fraction of its size.
constexpr double kNewtonFailureShrink = 0.25;

double wrms(const VecX& x, const VecX& w) {
  return std::sqrt((x.array() / w.array()).square().mean());
}

void requireFinalized(const System& sys) {
  if (!sys.isFinalized()) throw InputError("ali3p: the system must be finalized first");
}

}  // namespace

struct AugmentedLagrangianIntegrator::Impl {
  const System& sys;
  AugmentedLagrangianOptions opt;
  DaeSystem ggl, index1;  // residual blocks: F_v, g, G v + g_t; and G a + (G v)_q T v + g_tt
  std::unique_ptr<DaeScratch> scratch, scratch1;
  int nq, nv, m;
  bool identityT;  ///< q' = v (planar models): T = I, q (+) d = q + d
  DaeLayout L, L1;
  // work arrays (sized once)
  VecX y, yp, F, y1, yp1, F1;
  MatX J, P, G, T;  // T(q) (nq x nv), filled only when identityT is false
  Eigen::PartialPivLU<MatX> lu;
  VecX r, dv, dq, w, qN, qTmp, dN, vN, aN, lamN, err, errQ, g;
  MatX gram;  // G G^T (m x m) and its eigen-decomposition: the nearly dependent constraint directions
  Eigen::SelfAdjointEigenSolver<MatX> eig;
  // state at the end of the last step and at its start; dStep = q (-) qPrev, the last step's displacement
  double t = 0.0, tPrev = 0.0, h = 0.0, massScale = 1.0, constraintScale = 1.0;
  VecX q, v, a, lam, qPrev, vPrev, aPrev, dStep;
  IntegratorStats stats;
  long forcedSteps = 0;  ///< steps accepted with an error estimate that is not truncation error
  bool errorTest = true;
  double fixedStep = 0.0;  ///< step size without the error test

  Impl(const System& s, const AugmentedLagrangianOptions& o)
      : sys(s), opt(o), ggl(s, Formulation::Ggl, defaultStabilisationMetric(s), o.released),
        index1(s, Formulation::Index1, defaultStabilisationMetric(s), o.released),
        scratch(ggl.makeScratch()), scratch1(index1.makeScratch()),
        nq(s.numCoordinates()), nv(s.numVelocities()), m(s.numConstraintEquations()),
        identityT(s.velocitiesAreCoordinateRates()), L(ggl.layout()), L1(index1.layout()),
        lu(nv), eig(m) {  // sized in place: Eigen's sized constructor leaves m_info unset, so no move-assignment
    y = yp = F = VecX::Zero(L.size);
    y1 = yp1 = F1 = VecX::Zero(L1.size);
    J = MatX::Zero(L.size, L.size);
    P = MatX::Zero(nv, nv);
    G = MatX::Zero(m, nv);
    T = MatX::Zero(identityT ? 0 : nq, identityT ? 0 : nv);
    r = dv = dN = vN = aN = err = dStep = VecX::Zero(nv);
    dq = w = qN = qTmp = errQ = VecX::Zero(nq);
    lamN = g = VecX::Zero(m);
    gram = MatX::Zero(m, m);
  }

  // ----- velocity space and coordinates ------------------------------------------------
  /// T(qq) body by body (q' = T v, Body::addCoordinateRateMatrix); nothing for T = I.
  void rateMatrix(const VecX& qq) {
    if (identityT) return;
    T.setZero();
    for (int b = 0; b < sys.numBodies(); ++b) {
      const BodyIndex bi(b);
      const Body& body = sys.body(bi);
      const int qoff = sys.coordinateOffset(bi), voff = sys.velocityOffset(bi);
      body.addCoordinateRateMatrix(qq.segment(qoff, sys.numCoordinates(bi)), MatrixSink(T, qoff, voff));
    }
  }
  /// out = T dd: a velocity-space change in coordinates (first order), for the error weights
  /// of the coordinates (T from the last rateMatrix).
  void toCoordinates(const VecX& dd, VecX& out) const {
    if (identityT) {
      out = dd;
    } else {
      out.noalias() = T * dd;
    }
  }
  /// out = base (+) dd body by body (Body::applyIncrement: Euler parameters rotated and
  /// renormalised); out must not alias base.
  void increment(const VecX& base, const VecX& dd, VecX& out) const {
    for (int b = 0; b < sys.numBodies(); ++b) {
      const BodyIndex bi(b);
      const int nqb = sys.numCoordinates(bi);
      if (nqb == 0) continue;
      const int qoff = sys.coordinateOffset(bi);
      sys.body(bi).applyIncrement(base.segment(qoff, nqb), dd.segment(sys.velocityOffset(bi), sys.numVelocities(bi)),
                                  out.segment(qoff, nqb));
    }
  }
  /// Trapezoidal predictor with a_{n+1} = a_n: d = h v_n + h^2/2 a_n, q_{n+1} = q_n (+) d.
  /// For T = I, d is the coordinate difference itself (the planar arithmetic of before).
  void predict(double hh) {
    if (identityT) {
      qN = q + hh * v + 0.5 * hh * hh * a;
      dN = qN - q;
    } else {
      dN = hh * v + 0.5 * hh * hh * a;
      increment(q, dN, qN);
    }
  }
  /// A Newton correction dd (velocity space): q_{n+1} <- q_{n+1} (+) dd, d <- d + dd (the
  /// composition of rotations differs from the sum by O(|d| |dd|): O(h^4) a step after the
  /// first correction, below the method's O(h^3) local error).
  void correct(const VecX& dd) {
    if (identityT) {
      qN += dd;
      dN = qN - q;
    } else {
      increment(qN, dd, qTmp);
      qN.swap(qTmp);
      dN += dd;
    }
  }
  /// Trapezoidal rule in the displacement: v_{n+1} = 2/h d - v_n, a_{n+1} = 4/h^2 d - 4/h v_n - a_n
  /// (Newmark beta = 1/4, gamma = 1/2; on a Lie group: BrulsCardonaArnold2012).
  void trapezoidalRates(double hh) {
    vN = (2.0 / hh) * dN - v;
    aN = (4.0 / (hh * hh)) * dN - (4.0 / hh) * v - a;
  }

  // ----- residuals ---------------------------------------------------------------------
  /// F (GGL, mu = 0) at (q, v, a) with multipliers lam; with the Jacobian dF/dy + cj dF/dy'
  /// and G (the velocity Jacobian dF_gv/dv, m x nv; zero rows for released equations) if asked.
  /// y'_q is left 0: F_q is not used, and F_v, F_g, F_gv do not depend on q'.
  void evaluate(double tt, const VecX& qq, const VecX& vv, const VecX& aa, const VecX& ll, bool jacobian, double cj) {
    y.setZero();
    yp.setZero();
    y.segment(L.q, nq) = qq;
    y.segment(L.v, nv) = vv;
    y.segment(L.lambda, m) = ll;
    yp.segment(L.v, nv) = aa;
    ggl.residual(tt, y.data(), yp.data(), F.data(), *scratch);
    ++stats.residualEvals;
    if (jacobian) {
      J.setZero();
      JacobianSink sink = JacobianSink::dense(J.data(), L.size);
      ggl.jacobian(tt, y.data(), yp.data(), cj, sink, *scratch);
      G = J.block(L.mu, L.v, m, nv);
      ++stats.jacobianEvals;
    }
  }

  /// Acceleration-level constraint residual G a + (G v)_q T v + g_tt (into F1 at L1.lambda).
  void evaluateAccelerationConstraints(double tt, const VecX& qq, const VecX& vv, const VecX& aa) {
    y1.setZero();
    yp1.setZero();
    y1.segment(L1.q, nq) = qq;
    y1.segment(L1.v, nv) = vv;
    yp1.segment(L1.v, nv) = aa;
    index1.residual(tt, y1.data(), yp1.data(), F1.data(), *scratch1);
    ++stats.residualEvals;
  }

  template <class Derived>
  void weights(const Eigen::MatrixBase<Derived>& qq) {
    w = opt.rtol * qq.cwiseAbs() + opt.atolPosition;
  }

  /// The violation to correct: g without its components along the nearly dependent
  /// constraint directions (u_k of G G^T = U S^2 U^T with s_k < kDependentRatio s_max).
  /// There a violation is of second order in a move along the bifurcation direction,
  /// which the multiplier iteration would make in ill-conditioned small steps; the
  /// position along it is left to the inertia (the predictor), as in the exact motion.
  /// (Released equations have zero rows in G: their g_k = lambda_k = 0 is left out too.)
  void removeDependentDirections() {
    if (m == 0) return;
    gram.noalias() = G * G.transpose();
    eig.compute(gram);
    const double cut = kDependentRatio * kDependentRatio * std::max(eig.eigenvalues()[m - 1], 0.0);
    for (int k = 0; k < m && eig.eigenvalues()[k] < cut; ++k) {
      const auto u = eig.eigenvectors().col(k);
      g -= u.dot(g) * u;
    }
  }

  /// The Newton matrix / (h^2/4) in velocity-space increments dd (q = q (+) dd, d += dd):
  /// dF_v/dq T + 2/h dF_v/dv (cj = 2/h) + alpha G^T G (CuadradoCardenalBayo1997, eq. 11; T = I planar)
  void newtonMatrix(double hh, double alpha) {
    if (identityT) {
      P = J.block(L.v, L.q, nv, nq) + (2.0 / hh) * J.block(L.v, L.v, nv, nv);
    } else {
      P.noalias() = J.block(L.v, L.q, nv, nq) * T;
      P += (2.0 / hh) * J.block(L.v, L.v, nv, nv);
    }
    if (m > 0) P.noalias() += alpha * G.transpose() * G;
  }

  /// Mass-orthogonal projections with the last Newton matrix (BayoLedesma1996, eqs. 27, 31):
  /// P (v - v*) = -alpha G^T (G v* + g_t),  P (a - a*) = -alpha G^T (G a* + (G v)_q T v + g_tt)
  void project(double tn, double alpha) {
    for (int pass = 0; pass < kProjectionPasses; ++pass) {
      evaluate(tn, qN, vN, aN, lamN, false, 0.0);
      r.noalias() = G.transpose() * (alpha * F.segment(L.mu, m));  // alpha goes into the product (no temporary)
      dv = lu.solve(r);
      vN -= dv;
    }
    for (int pass = 0; pass < kProjectionPasses; ++pass) {
      evaluateAccelerationConstraints(tn, qN, vN, aN);
      r.noalias() = G.transpose() * (alpha * F1.segment(L1.lambda, m));
      dv = lu.solve(r);
      aN -= dv;
    }
  }

  /// One attempt with step size hh from (t, q, v, a, lam). True if Newton converged;
  /// then qN, dN, vN, aN, lamN hold the projected end state.
  bool attempt(double hh) {
    const double tn = t + hh;
    const double alpha = m > 0 ? kPenalty * 4.0 / (hh * hh) * massScale / constraintScale : 0.0;
    predict(hh);
    lamN = lam;
    weights(q);
    const double roundOffScale = std::numeric_limits<double>::epsilon() * (opt.lengthScale + q.cwiseAbs().maxCoeff());
    // tolerance of a constraint violation (length units): the error weight of a coordinate of the model's size
    const double constraintScaleTolerance = opt.rtol * opt.lengthScale + opt.atolPosition.minCoeff();
    double lastNorm = 0.0;
    bool converged = false;
    for (int it = 0; it < kMaxNewtonIterations; ++it) {
      trapezoidalRates(hh);
      evaluate(tn, qN, vN, aN, lamN, true, 2.0 / hh);
      rateMatrix(qN);
      ++stats.nonlinearIterations;
      g = F.segment(L.lambda, m);
      const double violation = m > 0 ? g.cwiseAbs().maxCoeff() : 0.0;
      removeDependentDirections();
      r = F.segment(L.v, nv);
      if (m > 0) {
        // multiplier update lambda* += alpha g(q_{k+1}) (BayoLedesma1996, eq. 20), not on a
        // violation at round-off: alpha times round-off moves near-singular directions
        if (it > 0 && g.cwiseAbs().maxCoeff() > kRoundOffViolation * roundOffScale) {
          lamN += alpha * g;
          r.noalias() += G.transpose() * (alpha * g);
        }
        r.noalias() += G.transpose() * (alpha * g);  // M a + G^T (lambda* + alpha g) - Q (BayoLedesma1996, eq. 19)
      }
      newtonMatrix(hh, alpha);
      lu.compute(P);
      ++stats.linearSetups;
      dv = lu.solve(r);
      dv *= -1.0;  // the correction -P^{-1} r (negation exact)
      if (!dv.allFinite()) return false;
      toCoordinates(dv, dq);  // the correction in coordinates, for the error weights
      correct(dv);
      const double norm = wrms(dq, w);
      const bool atRoundOff = dv.cwiseAbs().maxCoeff() <= kRoundOffCorrection * roundOffScale;
      // Near a singular position the multiplier iteration barely moves a violation along the
      // nearly dependent constraint direction (contraction 1 - alpha sigma_min^2 / ...): a
      // violation far below atol with corrections inside the error weights is converged.
      const bool stalled = it > 1 && norm > kStalledContraction * lastNorm;
      const bool satisfied = it > 0 && m > 0 && (norm <= kSingularNewtonTolerance || stalled) &&
                             g.cwiseAbs().maxCoeff() <= kConstraintTolerance * constraintScaleTolerance;
      if ((norm <= kNewtonTolerance && it > 0) || atRoundOff || satisfied) {
        // the whole violation, the nearly dependent directions included: where it is not
        // small no position satisfies the constraints (a driven lock-up), not a crossing
        converged = violation <= kMaxViolation * constraintScaleTolerance;
        break;
      }
      if (it > 1 && norm > 2.0 * lastNorm) return false;  // diverging
      lastNorm = norm;
    }
    if (!converged) return false;
    trapezoidalRates(hh);
    if (m > 0) project(tn, alpha);
    return qN.allFinite() && vN.allFinite() && aN.allFinite();
  }

  /// Local error of the trapezoidal rule h^2/12 (a_{n+1} - a_n) (ZienkiewiczXie1991,
  /// beta = 1/4), velocity space, in the coordinates' error weights (through T(q_{n+1})).
  double errorEstimate(double hh) {
    err = (hh * hh / 12.0) * (aN - a);
    rateMatrix(qN);
    toCoordinates(err, errQ);
    weights(qN.cwiseAbs().cwiseMax(q.cwiseAbs()));
    return wrms(errQ, w);
  }
};

AugmentedLagrangianIntegrator::AugmentedLagrangianIntegrator(const System& sys, double t0, const VecX& q0,
                                                             const VecX& v0, const VecX& a0, const VecX& lambda0,
                                                             const AugmentedLagrangianOptions& options)
    : impl_((requireFinalized(sys), std::make_unique<Impl>(sys, options))) {
  Impl& s = *impl_;
  const int nq = s.nq, nv = s.nv;
  if (q0.size() != nq || v0.size() != nv || a0.size() != nv || lambda0.size() != s.m) {
    throw InputError("ali3p: initial state of the wrong size (q " + std::to_string(nq) + ", v and a " +
                     std::to_string(nv) + ", lambda " + std::to_string(s.m) + " entries expected)");
  }
  if (s.opt.atolPosition.size() != nq) {
    throw InputError("ali3p: absolute tolerances must be given per coordinate");
  }
  if (!(s.opt.rtol > 0.0) || !(s.opt.atolPosition.array() > 0.0).all()) {
    throw InputError("ali3p: tolerances must be positive");
  }
  s.t = s.tPrev = t0;
  s.q = s.qPrev = q0;
  s.v = s.vPrev = v0;
  s.a = s.aPrev = a0;
  s.lam = lambda0;
  s.dStep.setZero();
  // scales of the penalty: the largest diagonal entries of M and of G^T G at the start
  const MatX M = massMatrix(sys, q0);
  s.massScale = std::max(M.diagonal().cwiseAbs().maxCoeff(), 1e-300);
  if (s.m > 0) {
    MatX G0;
    evaluateConstraints(sys, q0, t0, nullptr, &G0);  // velocity Jacobian (m x nv)
    s.constraintScale = std::max(withoutRows(G0, s.opt.released).colwise().squaredNorm().maxCoeff(), 1e-300);
  }
  s.weights(q0);
  s.rateMatrix(q0);
  s.toCoordinates(a0, s.errQ);
  const double an = wrms(s.errQ, s.w);
  // first step: the Taylor term h^2/2 |a| at a tenth of the error weights
  s.h = s.opt.initialStepSize > 0.0 ? s.opt.initialStepSize : (an > 0.0 ? std::sqrt(0.2 / an) : 1e-3);
  if (s.opt.maxStepSize > 0.0) s.h = std::min(s.h, s.opt.maxStepSize);
}

AugmentedLagrangianIntegrator::~AugmentedLagrangianIntegrator() = default;

double AugmentedLagrangianIntegrator::step(double tStop) {
  Impl& s = *impl_;
  if (!(tStop > s.t)) return s.t;
  double rejectedError = 0.0, rejectedStep = 0.0;  // the first rejection of this step
  for (;;) {
    double hh = s.h;
    bool last = false;
    if (s.t + hh >= tStop || s.t + 1.01 * hh >= tStop) {  // land on tStop exactly, no sliver step
      hh = tStop - s.t;
      last = true;
    }
    if (hh < s.opt.minStepSize && !last) {
      std::ostringstream os;
      os << "ali3p: the step size fell to " << hh << " at t = " << s.t << " (below min_step "
         << s.opt.minStepSize << ") after " << s.stats.nonlinearConvFailures << " Newton failures and "
         << s.stats.errorTestFailures << " error test failures in " << s.stats.steps << " steps";
      throw SolverError(os.str(), s.t, hh);
    }
    if (!s.attempt(hh)) {
      ++s.stats.nonlinearConvFailures;
      s.h = kNewtonFailureShrink * hh;
      continue;
    }
    const double e = s.errorEstimate(hh);
    const double factor = e > 0.0 ? kSafety * std::pow(e, -1.0 / 3.0) : kMaxGrowth;
    // An error that does not fall as the step shrinks is not the truncation error (h^3): near
    // a singular position it is the correction of the last step's violation along a nearly
    // dependent constraint, (4/h^2) delta q in the accelerations. Bounded, it is accepted.
    const bool notTruncation = rejectedStep >= kArtifactShrink * hh &&
                               e >= kArtifactPersistence * rejectedError * (hh / rejectedStep) && e <= kMaxArtifactError;
    if (notTruncation) ++s.forcedSteps;
    if (!(e <= 1.0) && !notTruncation && s.errorTest) {
      if (rejectedStep == 0.0) {
        rejectedError = e;
        rejectedStep = hh;
      }
      ++s.stats.errorTestFailures;
      s.h = hh * std::clamp(factor, kMinShrinkRejected, 1.0);
      continue;
    }
    s.tPrev = s.t;
    s.qPrev = s.q;
    s.vPrev = s.v;
    s.aPrev = s.a;
    s.t = last ? tStop : s.t + hh;
    s.q = s.qN;
    s.dStep = s.dN;
    s.v = s.vN;
    s.a = s.aN;
    s.lam = s.lamN;
    ++s.stats.steps;
    s.stats.lastStepSize = hh;
    s.stats.currentTime = s.t;
    // a step shortened to land on tStop does not shrink the next one
    if (s.errorTest) {
      s.h = last ? std::max(s.h, hh * std::clamp(factor, kMinShrink, kMaxGrowth))
                 : hh * std::clamp(factor, kMinShrink, kMaxGrowth);
    } else if (!last) {
      // without the error test: the size set when it was switched off, regained after Newton failures
      s.h = std::min(kMaxGrowth * hh, s.fixedStep);
    }
    if (s.opt.maxStepSize > 0.0) s.h = std::min(s.h, s.opt.maxStepSize);
    return s.t;
  }
}

double AugmentedLagrangianIntegrator::time() const { return impl_->t; }
const VecX& AugmentedLagrangianIntegrator::q() const { return impl_->q; }
const VecX& AugmentedLagrangianIntegrator::v() const { return impl_->v; }
const VecX& AugmentedLagrangianIntegrator::a() const { return impl_->a; }
const VecX& AugmentedLagrangianIntegrator::lambda() const { return impl_->lam; }
IntegratorStats AugmentedLagrangianIntegrator::stats() const { return impl_->stats; }
long AugmentedLagrangianIntegrator::forcedSteps() const { return impl_->forcedSteps; }
void AugmentedLagrangianIntegrator::setErrorTest(bool on) {
  if (!on && impl_->errorTest) impl_->fixedStep = impl_->h;
  impl_->errorTest = on;
}
double AugmentedLagrangianIntegrator::nextStepSize() const { return impl_->h; }

void AugmentedLagrangianIntegrator::interpolate(double tt, VecX& qq, VecX& vv) const {
  const Impl& s = *impl_;
  const double hh = s.t - s.tPrev;
  if (!(hh > 0.0)) {
    qq = s.q;
    vv = s.v;
    return;
  }
  // cubic Hermite basis on [t_{n-1}, t_n]
  const double x = std::clamp((tt - s.tPrev) / hh, 0.0, 1.0);
  const double h00 = 2 * x * x * x - 3 * x * x + 1, h10 = x * x * x - 2 * x * x + x;
  const double h01 = -2 * x * x * x + 3 * x * x, h11 = x * x * x - x * x;
  if (s.identityT) {
    qq = h00 * s.qPrev + (h10 * hh) * s.vPrev + h01 * s.q + (h11 * hh) * s.v;
  } else {
    // q_{n-1} (+) (h01 d + h10 h v_{n-1} + h11 h v_n), d = q_n (-) q_{n-1}: the same cubic (h00 + h01 = 1)
    // in velocity space. Not used for T = I, where its different round-off would change planar
    // runs: outputs inside a crossing feed the next diagnosis (measured 6e-5 on the parallelogram).
    qq = s.sys.applyIncrement(s.qPrev, h01 * s.dStep + (h10 * hh) * s.vPrev + (h11 * hh) * s.v);
  }
  vv = h00 * s.vPrev + (h10 * hh) * s.aPrev + h01 * s.v + (h11 * hh) * s.a;
}

double AugmentedLagrangianIntegrator::constraintConditioning() const {
  const Impl& s = *impl_;
  if (s.m == 0) return 1.0;
  MatX G;
  evaluateConstraints(s.sys, s.q, s.t, nullptr, &G);
  return singularValueRatio(withoutRows(G, s.opt.released));
}

namespace {

AugmentedLagrangianOptions solverOptions(const DaeSystem& dae, const IntegratorOptions& o) {
  const DaeLayout& L = dae.layout();
  AugmentedLagrangianOptions a;
  a.rtol = o.rtol;
  if (o.atol.size() != L.size) throw InputError("ali3p: absolute tolerances of the wrong size");
  a.atolPosition = o.atol.segment(L.q, L.nq);
  a.initialStepSize = o.initialStepSize;
  a.maxStepSize = o.maxStepSize;
  a.minStepSize = o.minStepSize > 0.0 ? o.minStepSize : 1e-14;
  a.released = dae.releasedEquations();
  return a;
}

}  // namespace

AugmentedLagrangianSolver::AugmentedLagrangianSolver(const DaeSystem& dae, double t0, const VecX& y0,
                                                     const VecX& yp0, const IntegratorOptions& options)
    : dae_(dae),
      integrator_(dae.system(), t0, y0.segment(dae.layout().q, dae.layout().nq),
                  y0.segment(dae.layout().v, dae.layout().nv), yp0.segment(dae.layout().v, dae.layout().nv),
                  y0.segment(dae.layout().lambda, dae.layout().m), solverOptions(dae, options)),
      y_(y0), yp_(yp0), maxSteps_(options.maxSteps) {}

double AugmentedLagrangianSolver::advance(double tout, double tStop) {
  const DaeLayout& L = dae_.layout();
  const long steps0 = integrator_.stats().steps;
  while (integrator_.time() < tout) {
    pollStop(integrator_.time());  // core/stop_request.hpp
    integrator_.step(tStop);
    if (integrator_.stats().steps - steps0 > maxSteps_) {
      throw SolverError("ali3p: more than max_steps = " + std::to_string(maxSteps_) + " steps before t = " +
                            std::to_string(tout), integrator_.time(),
                        integrator_.stats().lastStepSize);
    }
  }
  integrator_.interpolate(tout, q_, v_);
  y_.setZero();
  yp_.setZero();
  y_.segment(L.q, L.nq) = q_;
  y_.segment(L.v, L.nv) = v_;
  y_.segment(L.lambda, L.m) = integrator_.lambda();
  yp_.segment(L.q, L.nq) = dae_.system().coordinateRates(q_, v_);  // q' = T(q) v
  yp_.segment(L.v, L.nv) = integrator_.a();
  return tout;
}

}  // namespace flexmbd
