/// @file
/// Static equilibrium of a constrained system: Q(t, q, 0) = G^T lambda, g(q, t) = 0 (Haug1989).
#pragma once

#include <vector>

#include "core/system.hpp"

namespace flexmbd {

struct StaticEquilibriumOptions {
  double tolerance = 1e-10;   ///< on max |correction of q| relative to (1 + max |q|)
  int maxIterations = 50;     ///< Newton iterations per load increment
  /// Load increments (tried ones, failed ones included) before giving up.
  int maxIncrements = 64;
  /// Smallest load increment, as a fraction of the whole load, before giving up.
  double minIncrement = 1.0 / 4096;
  /// Constraint equations released (ascending; redundant constraints resolved, as
  /// ConsistentState::released): each one's row becomes lambda_k = 0 (DaeSystem). Empty:
  /// every equation is kept, and redundant ones make the tangent singular (ModelError).
  std::vector<int> released;
};

struct StaticEquilibrium {
  VecX q, lambda;                   ///< q: nq coordinates (unit Euler parameters); lambda: m
  int iterations = 0;               ///< Newton iterations, all increments
  int increments = 0;               ///< converged load increments (1: the load in one solve)
  double forceResidual = 0.0;       ///< max |Q - G^T lambda| at the solution (velocity space, nv)
  double constraintResidual = 0.0;  ///< max |g|
};

/// Newton iterations on r = [ -Q(t, q, 0) + G^T lambda ; g(q, t) ] = 0 (Haug1989; nv + m equations,
/// Q and G in velocity space) from q0 and lambda = 0 (or, where the tangent is singular at
/// lambda = 0, as for a pendulum held only by its joint, the least-squares multipliers
/// G^T lambda ~ Q of the starting load). The unknowns are velocity-space
/// increments: q <- q (+) dx (Body::applyIncrement: Euler parameters rotated in body axes
/// and re-normalised; q + dx for planar bodies) and lambda <- lambda + dlambda, with the
/// tangent [ (-dQ/dq + sum lambda_a H_a) T(q) , G^T ; (dg/dq) T(q) , 0 ] (q' = T(q) v;
/// T = I for planar models) assembled by the same code as the integrator's Jacobian
/// (DaeSystem, at v = v' = 0), and a backtracking line search. Load stepping: the whole
/// load is tried first; if Newton fails, the residual r(x0) (the unbalanced load at the
/// start) is applied in increments: r(x) - (1 - s) r(x0) = 0 for s rising to 1 (Newton
/// homotopy; for an unstressed start, f_int(q) - s f_ext), the increment halved after a
/// failure and doubled after a convergence in few iterations.
/// @throws InputError if the system is not finalized or q0 has the wrong size.
/// @throws ModelError if it does not converge (names the load fraction reached, the
/// increment and the residuals) or the tangent is singular (an unstable or unconstrained
/// configuration, or redundant constraints not listed in options.released).
StaticEquilibrium solveStaticEquilibrium(const System& sys, double t, const VecX& q0,
                                         const StaticEquilibriumOptions& options = {});

}  // namespace flexmbd
