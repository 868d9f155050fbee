// Static equilibrium of a constrained system: Q(t, q, 0) = G^T lambda, g(q, t) = 0.
#pragma once

#include "core/system.hpp"

namespace flexmbd {

struct StaticEquilibriumOptions {
  double tolerance = 1e-10;   ///< on max |correction of q| relative to (1 + max |q|)
  int maxIterations = 50;
};

struct StaticEquilibrium {
  VecX q, lambda;
  int iterations = 0;
  double forceResidual = 0.0;       ///< max |Q - G^T lambda| at the solution
  double constraintResidual = 0.0;  ///< max |g|
};

/// Newton iterations on [ -Q(t, q, 0) + G^T lambda ; g(q, t) ] = 0 from q0, with the
/// tangent [ -dQ/dq + sum lambda_a H_a , G^T ; G , 0 ] assembled by the same code as the
/// integrator's Jacobian (DaeSystem, at v = v' = 0), and a backtracking line search.
/// @throws ModelError if it does not converge (reports the residuals) or the tangent
/// is singular (an unstable or unconstrained configuration).
StaticEquilibrium solveStaticEquilibrium(const System& sys, double t, const VecX& q0,
                                         const StaticEquilibriumOptions& options = {});

}  // namespace flexmbd
