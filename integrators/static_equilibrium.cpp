#include "integrators/static_equilibrium.hpp"

#include <Eigen/Dense>
#include <sstream>

#include "core/dae_system.hpp"
#include "core/errors.hpp"

namespace flexmbd {

StaticEquilibrium solveStaticEquilibrium(const System& sys, double t, const VecX& q0,
                                         const StaticEquilibriumOptions& options) {
  const DaeSystem dae(sys, Formulation::Index3);  // y = [q, v, lambda]; F = [q'-v, M v'-Q+G^T l, g]
  const DaeLayout& L = dae.layout();
  const int nq = L.nq, m = L.m, n = nq + m;
  VecX y = VecX::Zero(L.size), yp = VecX::Zero(L.size), F(L.size);
  y.segment(L.q, nq) = q0;
  // unknowns x = [q, lambda]; equations r = [F_v, F_g] (at v = v' = 0, F_v = -Q + G^T lambda)
  const auto residual = [&](VecX& r) {
    dae.residual(t, y.data(), yp.data(), F.data());
    r.resize(n);
    r << F.segment(L.v, nq), F.segment(L.lambda, m);
  };
  VecX r;
  residual(r);
  StaticEquilibrium out;
  MatX J(L.size, L.size);
  for (int it = 1; it <= options.maxIterations; ++it) {
    J.setZero();
    JacobianSink sink = JacobianSink::dense(J.data(), L.size);
    dae.jacobian(t, y.data(), yp.data(), 0.0, sink);
    MatX A(n, n);
    A << J.block(L.v, L.q, nq, nq), J.block(L.v, L.lambda, nq, m), J.block(L.lambda, L.q, m, nq),
        J.block(L.lambda, L.lambda, m, m);
    const Eigen::FullPivLU<MatX> lu(A);
    if (!lu.isInvertible()) {
      throw ModelError("static equilibrium: the tangent stiffness is singular at iteration " + std::to_string(it) +
                       " (an unconstrained rigid motion, or an unstable position)");
    }
    const VecX dx = -lu.solve(r);
    // backtracking on the residual norm
    const double r0 = r.norm();
    double step = 1.0;
    const VecX x0 = (VecX(n) << y.segment(L.q, nq), y.segment(L.lambda, m)).finished();
    for (int k = 0; k < 30; ++k) {
      y.segment(L.q, nq) = x0.head(nq) + step * dx.head(nq);
      y.segment(L.lambda, m) = x0.tail(m) + step * dx.tail(m);
      residual(r);
      if (r.allFinite() && r.norm() <= (1.0 - 1e-4 * step) * r0) break;
      step *= 0.5;
    }
    out.iterations = it;
    const double scale = 1.0 + y.segment(L.q, nq).lpNorm<Eigen::Infinity>();
    if (step * dx.head(nq).lpNorm<Eigen::Infinity>() <= options.tolerance * scale) {
      out.q = y.segment(L.q, nq);
      out.lambda = y.segment(L.lambda, m);
      out.forceResidual = r.head(nq).lpNorm<Eigen::Infinity>();
      out.constraintResidual = m > 0 ? r.tail(m).lpNorm<Eigen::Infinity>() : 0.0;
      return out;
    }
  }
  std::ostringstream os;
  os << "static equilibrium: no convergence after " << options.maxIterations << " Newton iterations (force residual "
     << r.head(nq).lpNorm<Eigen::Infinity>() << ", constraint residual "
     << (m > 0 ? r.tail(m).lpNorm<Eigen::Infinity>() : 0.0) << ")";
  throw ModelError(os.str());
}

}  // namespace flexmbd
