#include "integrators/static_equilibrium.hpp"

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

}  // namespace

StaticEquilibrium solveStaticEquilibrium(const System& sys, double t, const VecX& q0,
                                         const StaticEquilibriumOptions& options) {
  if (sys.isFinalized() && !sys.velocitiesAreCoordinateRates()) {
    throw InputError("static equilibrium: supported for planar models only so far (this model has bodies with "
                     "rotation parameters)");
  }
  const DaeSystem dae(sys, Formulation::Index3);  // y = [q, v, lambda]; F = [q'-v, M v'-Q+G^T l, g]
  const DaeLayout& L = dae.layout();
  const int nq = L.nq, m = L.m, n = nq + m;
  VecX y = VecX::Zero(L.size), yp = VecX::Zero(L.size), F(L.size);
  y.segment(L.q, nq) = q0;
  // unknowns x = [q, lambda]; equations r = [F_v, F_g] (at v = v' = 0, F_v = -Q + G^T lambda)
  const auto fullResidual = [&](VecX& r) {
    dae.residual(t, y.data(), yp.data(), F.data());
    r.resize(n);
    r << F.segment(L.v, nq), F.segment(L.lambda, m);
  };
  const auto getX = [&] { return (VecX(n) << y.segment(L.q, nq), y.segment(L.lambda, m)).finished(); };
  const auto setX = [&](const VecX& x) {
    y.segment(L.q, nq) = x.head(nq);
    y.segment(L.lambda, m) = x.tail(m);
  };
  VecX r0;
  fullResidual(r0);  // the unbalanced load at the start
  double s = 0.0;    // load fraction of the last converged state
  // residual of the homotopy at load fraction sl: r(x) - (1 - sl) r(x0)
  const auto residual = [&](double sl, VecX& r) {
    fullResidual(r);
    r.noalias() -= (1.0 - sl) * r0;
  };

  StaticEquilibrium out;
  MatX J(L.size, L.size), A(n, n);
  VecX r, x0;
  std::string lastFailure;
  // Newton at load fraction sl from the current x; true if converged.
  const auto newton = [&](double sl, int& iterations) {
    residual(sl, r);
    for (int it = 1; it <= options.maxIterations; ++it) {
      ++out.iterations;
      iterations = it;
      J.setZero();
      JacobianSink sink = JacobianSink::dense(J.data(), L.size);
      dae.jacobian(t, y.data(), yp.data(), 0.0, sink);
      A << J.block(L.v, L.q, nq, nq), J.block(L.v, L.lambda, nq, m), J.block(L.lambda, L.q, m, nq),
          J.block(L.lambda, L.lambda, m, m);
      const Eigen::FullPivLU<MatX> lu(A);
      if (!lu.isInvertible()) {
        throw ModelError("static equilibrium: the tangent stiffness is singular at iteration " + std::to_string(it) +
                         " (load fraction " + std::to_string(sl) +
                         "; an unconstrained rigid motion, or an unstable position)");
      }
      const VecX dx = -lu.solve(r);
      // backtracking on the residual norm
      const double rn = r.norm();
      double step = 1.0;
      const VecX xs = getX();
      bool decreased = false;
      for (int k = 0; k < 30; ++k) {
        setX(xs + step * dx);
        residual(sl, r);
        if (r.allFinite() && r.norm() <= (1.0 - 1e-4 * step) * rn) {
          decreased = true;
          break;
        }
        step *= 0.5;
      }
      const double scale = 1.0 + y.segment(L.q, nq).lpNorm<Eigen::Infinity>();
      if (step * dx.head(nq).lpNorm<Eigen::Infinity>() <= options.tolerance * scale && r.allFinite()) return true;
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
         << "; force residual " << r.head(nq).lpNorm<Eigen::Infinity>() << ", constraint residual "
         << (m > 0 ? r.tail(m).lpNorm<Eigen::Infinity>() : 0.0);
      throw ModelError(os.str());
    }
    ++tried;
    lastTried = ds;
    const double target = std::min(1.0, s + ds);
    x0 = getX();
    int iterations = 0;
    if (newton(target, iterations)) {
      s = target;
      ++out.increments;
      if (iterations <= kQuickConvergenceIterations) ds *= 2.0;
      ds = std::min(ds, 1.0 - s);
    } else {
      setX(x0);  // back to the last converged state
      ds *= 0.5;
    }
  }
  out.q = y.segment(L.q, nq);
  out.lambda = y.segment(L.lambda, m);
  fullResidual(r);
  out.forceResidual = r.head(nq).lpNorm<Eigen::Infinity>();
  out.constraintResidual = m > 0 ? r.tail(m).lpNorm<Eigen::Infinity>() : 0.0;
  return out;
}

}  // namespace flexmbd
