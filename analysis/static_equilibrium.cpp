#include "analysis/static_equilibrium.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <sstream>

#include "core/dae_system.hpp"
#include "core/errors.hpp"

namespace flexmbd {

namespace {

/// An increment that converged in at most this many Newton iterations doubles the next
/// one (a mildly nonlinear stretch: Newton's quadratic convergence needs 2-4 there).
constexpr int kQuickConvergenceIterations = 4;

/// The static problem in velocity space (docs/spatial.md, "Static equilibrium"): the state
/// (q, lambda), its residual r = [F_v, F_g] of the index-3 DAE at v = v' = 0
/// (F_v = -Q(t, q, 0) + G^T lambda, nv rows; F_g = g(q, t), m rows) and the tangent
/// dr/d[dx, dlambda] for q = q_k (+) dx (Body::applyIncrement): [F_v,q T, G^T; F_g,q T, 0].
/// For planar models T = I and q (+) dx = q + dx. Work arrays are sized once here.
class StaticProblem {
 public:
  StaticProblem(const System& sys, double t, const VecX& q0, const std::vector<int>& released)
      : sys_(sys),
        t_(t),
        dae_(sys, Formulation::Index3, defaultStabilisationMetric(sys), released),
        L_(dae_.layout()),
        y_(VecX::Zero(L_.size)),
        yp_(VecX::Zero(L_.size)),
        F_(L_.size),
        J_(L_.size, L_.size),
        T_(sys.velocitiesAreCoordinateRates() ? 0 : L_.nq, sys.velocitiesAreCoordinateRates() ? 0 : L_.nv) {
    if (q0.size() != L_.nq || !q0.allFinite()) {
      throw InputError("static equilibrium: the starting coordinates need " + std::to_string(L_.nq) +
                       " finite entries, got " + std::to_string(q0.size()));
    }
    y_.segment(L_.q, L_.nq) = q0;
  }
  int nv() const { return L_.nv; }
  int m() const { return L_.m; }
  int size() const { return L_.nv + L_.m; }
  auto q() const { return y_.segment(L_.q, L_.nq); }
  auto lambda() const { return y_.segment(L_.lambda, L_.m); }
  VecX state() const { return (VecX(L_.nq + L_.m) << q(), lambda()).finished(); }
  void setState(const VecX& s) {
    y_.segment(L_.q, L_.nq) = s.head(L_.nq);
    y_.segment(L_.lambda, L_.m) = s.tail(L_.m);
  }
  /// The state base (+) step dx: q = q_base (+) step dx_v (re-normalised Euler
  /// parameters), lambda = lambda_base + step dx_lambda.
  void moveFrom(const VecX& base, double step, const VecX& dx) {
    const VecX qb = base.head(L_.nq);
    y_.segment(L_.q, L_.nq) = sys_.applyIncrement(qb, step * dx.head(L_.nv));
    y_.segment(L_.lambda, L_.m) = base.tail(L_.m) + step * dx.tail(L_.m);
  }
  /// r = [F_v, F_g] at the current state.
  void residual(VecX& r) {
    dae_.residual(t_, y_.data(), yp_.data(), F_.data());
    r.resize(size());
    r << F_.segment(L_.v, L_.nv), F_.segment(L_.lambda, L_.m);
  }
  /// A = [F_v,q T, F_v,lambda; F_g,q T, F_g,lambda] from the DAE Jacobian at cj = 0 (the
  /// lambda-lambda block is the identity on released equations, zero otherwise).
  void tangent(MatX& A) {
    const int nq = L_.nq, nv = L_.nv, m = L_.m;
    J_.setZero();
    JacobianSink sink = JacobianSink::dense(J_.data(), L_.size);
    dae_.jacobian(t_, y_.data(), yp_.data(), 0.0, sink);
    A.resize(size(), size());
    if (sys_.velocitiesAreCoordinateRates()) {
      A.topLeftCorner(nv, nv) = J_.block(L_.v, L_.q, nv, nq);
      A.bottomLeftCorner(m, nv) = J_.block(L_.lambda, L_.q, m, nq);
    } else {
      fillRateMatrix();
      A.topLeftCorner(nv, nv).noalias() = J_.block(L_.v, L_.q, nv, nq) * T_;
      A.bottomLeftCorner(m, nv).noalias() = J_.block(L_.lambda, L_.q, m, nq) * T_;
    }
    A.topRightCorner(nv, m) = J_.block(L_.v, L_.lambda, nv, m);
    A.bottomRightCorner(m, m) = J_.block(L_.lambda, L_.lambda, m, m);
  }
  /// max |q| (the scale of the convergence test).
  double coordinateScale() const { return q().lpNorm<Eigen::Infinity>(); }

 private:
  /// T(q) (nq x nv) body by body: q' = T(q) v (Body::addCoordinateRateMatrix).
  void fillRateMatrix() {
    T_.setZero();
    const VecX qc = q();
    for (int b = 0; b < sys_.numBodies(); ++b) {
      const BodyIndex bi(b);
      const Body& body = sys_.body(bi);
      const int qoff = sys_.coordinateOffset(bi), voff = sys_.velocityOffset(bi);
      body.addCoordinateRateMatrix(qc.segment(qoff, body.numCoordinates()), MatrixSink(T_, qoff, voff));
    }
  }

  const System& sys_;
  double t_;
  DaeSystem dae_;
  const DaeLayout& L_;
  VecX y_, yp_, F_;
  MatX J_, T_;
};

/// Starting multipliers. From lambda = 0 the tangent has no geometric stiffness
/// sum lambda_a H_a: a mechanism held only by its joints under a constant load (a rigid
/// pendulum under gravity: dQ/dq T = 0) has a singular tangent there. Then lambda starts
/// from the least-squares balance of the starting load, G^T lambda ~ Q (minimum norm;
/// the reactions that hold what the joints can hold), which gives the joints their
/// stiffness. Models whose tangent is regular at lambda = 0 (those solved before spatial
/// models were: stressed structures) keep lambda = 0, and their iterations.
void chooseStartingMultipliers(StaticProblem& P, const std::vector<int>& released) {
  if (P.m() == 0) return;
  MatX A;
  P.tangent(A);
  if (Eigen::FullPivLU<MatX>(A).isInvertible()) return;
  VecX r;
  P.residual(r);  // F_v = -Q at lambda = 0
  // the kept equations' reactions only: a released one's row is lambda_k = 0, and sharing
  // the load with it would leave the kept joints half their stiffness (a first Newton step
  // twice too long, past the bottom of a pendulum to its top)
  MatX Gt = A.topRightCorner(P.nv(), P.m());
  for (const int k : released) Gt.col(k).setZero();
  const VecX lambda = Gt.completeOrthogonalDecomposition().solve(-r.head(P.nv()));  // minimum norm: 0 at released
  VecX x = P.state();
  x.tail(P.m()) = lambda;
  P.setState(x);
}

/// Most unknowns (velocities and multipliers) of the dense Newton solve: 3,000 is a 72 MB
/// matrix and some 10 s per factorisation.
constexpr int kDenseStaticLimit = 3000;

}  // namespace

StaticEquilibrium solveStaticEquilibrium(const System& sys, double t, const VecX& q0,
                                         const StaticEquilibriumOptions& options) {
  StaticProblem P(sys, t, q0, options.released);
  const int nv = P.nv(), m = P.m();
  if (nv + m > kDenseStaticLimit) {
    // the Newton solve is dense (FullPivLU): n^3 time, 8 n^2 bytes per matrix; measured on
    // the 1,000-element spatial beam (n = 6,012): 293 s CPU, 2.3 GB, and its condition
    // (EA/l against the bending terms, ~1e13) read as singular
    throw InputError("static equilibrium: " + std::to_string(nv + m) + " unknowns (velocities and multipliers), more "
                     "than the " + std::to_string(kDenseStaticLimit) +
                     " its dense Newton solve takes (minutes and GBs beyond): a modal reduction of the "
                     "flexible bodies (\"modes\"), or modes about a state of a run (--at)");
  }
  chooseStartingMultipliers(P, options.released);
  VecX r0;
  P.residual(r0);  // the unbalanced load at the start
  double s = 0.0;  // load fraction of the last converged state
  // residual of the homotopy at load fraction sl: r(x) - (1 - sl) r(x0)
  const auto residual = [&](double sl, VecX& r) {
    P.residual(r);
    r.noalias() -= (1.0 - sl) * r0;
  };

  StaticEquilibrium out;
  MatX A;
  VecX r, x0;
  std::string lastFailure;
  // Newton at load fraction sl from the current state; true if converged.
  const auto newton = [&](double sl, int& iterations) {
    residual(sl, r);
    for (int it = 1; it <= options.maxIterations; ++it) {
      ++out.iterations;
      iterations = it;
      P.tangent(A);
      const Eigen::FullPivLU<MatX> lu(A);
      if (!lu.isInvertible()) {
        throw ModelError("static equilibrium: the tangent stiffness is singular at iteration " + std::to_string(it) +
                         " (load fraction " + std::to_string(sl) +
                         "; an unconstrained rigid motion, an unstable position, or redundant constraints not "
                         "released)");
      }
      const VecX dx = -lu.solve(r);  // [dx_v, dlambda]
      // backtracking on the residual norm
      const double rn = r.norm();
      double step = 1.0;
      const VecX xs = P.state();
      bool decreased = false;
      for (int k = 0; k < 30; ++k) {
        P.moveFrom(xs, step, dx);
        residual(sl, r);
        if (r.allFinite() && r.norm() <= (1.0 - 1e-4 * step) * rn) {
          decreased = true;
          break;
        }
        step *= 0.5;
      }
      const double scale = 1.0 + P.coordinateScale();
      if (step * dx.head(nv).lpNorm<Eigen::Infinity>() <= options.tolerance * scale && r.allFinite()) return true;
      if (!decreased || !r.allFinite()) {
        lastFailure = "the line search found no decrease of the residual at iteration " + std::to_string(it);
        return false;
      }
    }
    lastFailure = "no convergence in " + std::to_string(options.maxIterations) + " Newton iterations";
    return false;
  };

  double ds = 1.0;  // the whole load first
  double lastTried = ds;
  int tried = 0;
  while (s < 1.0) {
    if (tried >= options.maxIncrements || ds < options.minIncrement) {
      std::ostringstream os;
      os << "static equilibrium: load stepping stopped at load fraction " << s << " after " << out.increments
         << " converged increments (" << tried << " tried, the last one " << lastTried << "): " << lastFailure
         << "; force residual " << r.head(nv).lpNorm<Eigen::Infinity>() << ", constraint residual "
         << (m > 0 ? r.tail(m).lpNorm<Eigen::Infinity>() : 0.0);
      throw ModelError(os.str());
    }
    ++tried;
    lastTried = ds;
    const double target = std::min(1.0, s + ds);
    x0 = P.state();
    int iterations = 0;
    if (newton(target, iterations)) {
      s = target;
      ++out.increments;
      if (iterations <= kQuickConvergenceIterations) ds *= 2.0;
      ds = std::min(ds, 1.0 - s);
    } else {
      P.setState(x0);  // back to the last converged state
      ds *= 0.5;
    }
  }
  out.q = P.q();
  out.lambda = P.lambda();
  P.residual(r);
  out.forceResidual = r.head(nv).lpNorm<Eigen::Infinity>();
  out.constraintResidual = m > 0 ? r.tail(m).lpNorm<Eigen::Infinity>() : 0.0;
  return out;
}

}  // namespace flexmbd
