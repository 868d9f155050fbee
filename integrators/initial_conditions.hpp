/// @file
/// Consistent initial values for the constrained equations of motion.
#pragma once

#include "core/linear_algebra.hpp"
#include "core/system.hpp"

namespace flexmbd {

/// Which constraint equations are released (redundant constraints resolved,
/// docs/formulations.md): the default refuses dependent equations, as a model error.
struct ReleasedEquations {
  /// Release the equations found dependent at the assembled position (dependentRows, in
  /// the order the joints and drivers were defined) instead of refusing them.
  bool detect = false;
  /// Otherwise these (ascending) are released; the others must be independent.
  std::vector<int> rows;
};

struct ConsistentState {
  /// lambda: 0 at the released equations (the DAE's multipliers, DaeSystem)
  VecX q, v, a, lambda;
  std::vector<int> released;     ///< the released equations (ascending)
  int positionIterations = 0;    ///< Newton iterations of the position projection
  double positionResidual = 0.0; ///< max |g| after projection
};

/// 1. positions projected onto g(q, t0) = 0 (Newton, minimum-norm corrections),
/// 2. velocities onto G v = -g_t (closest to v0 in the mass metric),
/// 3. accelerations and multipliers from [M G^T; G 0][a; lambda] = [Q; -gamma] (Haug1989).
/// With released equations, 2. and 3. use the independent rows only (the released ones
/// hold by their dependence on them) and lambda is 0 at the released rows.
/// @throws ModelError naming the constraints if they are redundant or conflicting
/// (rank-revealing check in the order they were added) and not released, or if the
/// mechanism cannot be assembled (remaining residual and the joints that carry it).
ConsistentState computeConsistentState(const System& sys, double t0, const VecX& q0,
                                       const VecX& v0, const ReleasedEquations& released = {});

/// Solves [M G^T; G 0][x; y] = [r1; r2] given the augmented matrix A (n + m square, n
/// velocities): dense rank-revealing LU up to 200 unknowns, sparse LU above.
/// @throws ModelError if it is singular.
void solveAugmented(const SpMat& A, int n, const VecX& r1, const VecX& r2, VecX& x, VecX& y);
/// The same from a dense augmented matrix (rank-revealing LU).
void solveAugmented(const MatX& A, int n, const VecX& r1, const VecX& r2, VecX& x, VecX& y);
/// The same from dense M (n x n) and G (m x n).
void solveAugmented(const MatX& M, const MatX& G, const VecX& r1, const VecX& r2, VecX& x, VecX& y);

/// Accelerations and multipliers of the state (q, v) at time t, from the augmented
/// system [M G^T; G 0][a; lambda] = [Q; f'' - v^T H v] (index-1 equations; Haug1989). At a
/// singular position (G rank-deficient, its rows consistent) the accelerations are the
/// unique mass-orthogonal projection and the multipliers the minimum-norm ones.
/// `released` (ascending): equations left out of the system, their multipliers 0.
void computeAccelerations(const System& sys, double t, const VecX& q, const VecX& v, VecX& a,
                          VecX& lambda, const std::vector<int>& released = {});

}  // namespace flexmbd
