/// @file
/// Whole-system quantities assembled from the components, on dense global arrays:
/// used by consistent initialisation, outputs and tests (the integrator's residual and
/// Jacobian assembly is in dae_system.hpp).
#pragma once

#include <string>
#include <vector>

#include "core/system.hpp"

namespace flexmbd {

/// g(q, t) = h(q) - f(t) (m; Haug1989), and optionally G = dg/dq (m x nq, dense).
void evaluateConstraints(const System& sys, const VecX& q, double t, VecX* g, MatX* G);
/// Velocity-level residual G v - f'(t) (m).
VecX velocityConstraintResidual(const System& sys, const VecX& q, const VecX& v, double t);
/// Acceleration right-hand side: G a = f''(t) - [v^T H_a v]_a (m) (Haug1989).
VecX accelerationConstraintRhs(const System& sys, const VecX& q, const VecX& v, double t);
/// The augmented matrix [M G^T; G 0] (nv + m square, sparse) at q: each body writes its
/// mass matrix's structural non-zeros through a sink, as in the DAE Jacobian, and each
/// constraint its G block; no dense array (outputs of large flexible models).
SpMat augmentedMatrix(const System& sys, const VecX& q);
/// The same, dense, from the same component loops (small systems: cheaper than triplets).
MatX denseAugmentedMatrix(const System& sys, const VecX& q);
/// Block-diagonal mass matrix (nv x nv, dense; small systems and tests).
MatX massMatrix(const System& sys, const VecX& q);
/// All generalised forces except constraint forces: internal, gravity, force elements.
VecX generalizedForces(const System& sys, double t, const VecX& q, const VecX& v);

double kineticEnergy(const System& sys, const VecX& q, const VecX& v);
/// Gravity, internal (elastic) and spring energy.
double potentialEnergy(const System& sys, const VecX& q);
/// True if no driver, no damping and no prescribed load: total energy is conserved.
bool isConservative(const System& sys);

/// Reaction outputs of every constraint, in order, from the multipliers (m).
VecX reactionOutputs(const System& sys, const VecX& q, const VecX& lambda);
/// "<joint>.fx", ... matching reactionOutputs.
std::vector<std::string> reactionOutputNames(const System& sys);

}  // namespace flexmbd
