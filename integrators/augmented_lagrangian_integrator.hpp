/// @file
/// Index-3 augmented Lagrangian formulation with mass-orthogonal projections (ALI3-P) and
/// the trapezoidal rule: BayoLedesma1996; CuadradoCardenalBayo1997. Written from the
/// formulas of these papers.
///
/// Its Newton matrix M + h/2 C + h^2/4 (K + alpha G^T G) (CuadradoCardenalBayo1997) stays regular where the
/// constraint Jacobian G loses rank, so it carries a mechanism through the isolated
/// singular positions (change points, dead centres) where the index-2 and index-3 DAE
/// integrators stop: the engine uses it as a bridge across them (simulation/simulation.cpp)
/// and as an integrator of its own ("ali3p").
///
/// Models whose velocities are not coordinate rates (q' = T(q) v: spatial bodies with Euler
/// parameters) are integrated in velocity space: the unknown of a step is its displacement
/// d (nv), q_{n+1} = q_n (+) d by each body's own increment (Body::applyIncrement), the
/// trapezoidal rule relates d, v and a as it relates q_{n+1} - q_n, v and a for T = I, and
/// Newton's corrections are velocity-space increments (docs/formulations.md).
#pragma once

#include <memory>
#include <vector>

#include "core/dae_system.hpp"
#include "integrators/dae_integrator.hpp"

namespace flexmbd {

/// Tolerances and limits of the ALI3-P integrator.
struct AugmentedLagrangianOptions {
  double rtol = 1e-8;
  VecX atolPosition;   ///< per coordinate (nq): local error test of positions
  double initialStepSize = 0.0;  ///< 0: from the accelerations (h^2/2 |a| = 1 in the error weights)
  double maxStepSize = 0.0;      ///< 0: no limit
  double minStepSize = 1e-14;    ///< failure below this
  double lengthScale = 1.0;      ///< model size: the scale of round-off in positions and constraints
  /// Constraint equations released as redundant (ascending; docs/formulations.md, "Redundant
  /// constraints"): left out of G, g and the multipliers, as in DaeSystem.
  std::vector<int> released;
};

/// The ALI3-P integrator on a finalized System. State: positions q, velocities v,
/// accelerations a (all consistent after the projections) and the multiplier estimate
/// lambda* of the augmented Lagrangian. Dense linear algebra (nv x nv): meant for
/// mechanisms and for short bridges of larger models.
class AugmentedLagrangianIntegrator {
 public:
  /// q0 (nq), v0 (nv) must satisfy the position and velocity constraints (e.g. from
  /// computeConsistentState); a0 (nv) and lambda0 (m) are the consistent accelerations and
  /// multipliers there. @throws InputError on bad options.
  AugmentedLagrangianIntegrator(const System& sys, double t0, const VecX& q0, const VecX& v0, const VecX& a0,
                                const VecX& lambda0, const AugmentedLagrangianOptions& options);
  ~AugmentedLagrangianIntegrator();
  AugmentedLagrangianIntegrator(const AugmentedLagrangianIntegrator&) = delete;
  AugmentedLagrangianIntegrator& operator=(const AugmentedLagrangianIntegrator&) = delete;

  /// One accepted step, never past tStop (error test, Newton failures and step size
  /// changes inside). Returns the time reached. @throws SolverError with the reason, the
  /// time reached and the step size tried when the step size falls below the minimum.
  double step(double tStop);
  double time() const;
  const VecX& q() const;
  const VecX& v() const;
  const VecX& a() const;
  const VecX& lambda() const;
  /// Positions and velocities at t in the last step [t_{n-1}, t_n]: cubic Hermite
  /// interpolation of the displacement from q_{n-1} (0 and d at the ends, rates v), applied
  /// as q_{n-1} (+) d(t), and of v from (v, a) at both ends. Allocates (outputs only).
  void interpolate(double t, VecX& q, VecX& v) const;
  /// Smallest/largest singular value of G (released equations left out) at the current
  /// positions (1 without constraints).
  double constraintConditioning() const;
  IntegratorStats stats() const;
  /// Steps accepted although their error estimate exceeded 1, because it did not fall as
  /// the step shrank (not a truncation error: the correction of a constraint violation
  /// along a nearly dependent direction at a singular position).
  long forcedSteps() const;
  /// Off: every step whose Newton iteration converges is accepted and the step size is
  /// the one planned when it was switched off (shrunk by Newton failures, regained after). For the core of a singular position, where
  /// positions along the nearly dependent directions are determined only to the Newton
  /// tolerance and the error estimate measures that, not the truncation error.
  void setErrorTest(bool on);
  double nextStepSize() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// ALI3-P behind the DaeIntegrator interface: y() and yp() in the layout of `dae` (the
/// DaeSystem whose unknowns the run outputs; its formulation is not used for stepping).
class AugmentedLagrangianSolver final : public DaeIntegrator {
 public:
  /// y0, yp0 must be consistent. @throws InputError on bad options.
  AugmentedLagrangianSolver(const DaeSystem& dae, double t0, const VecX& y0, const VecX& yp0,
                            const IntegratorOptions& options);
  double advance(double tout, double tStop) override;
  const VecX& y() const override { return y_; }
  const VecX& yp() const override { return yp_; }
  IntegratorStats stats() const override { return integrator_.stats(); }
  bool usesKlu() const override { return false; }

 private:
  const DaeSystem& dae_;
  AugmentedLagrangianIntegrator integrator_;
  VecX y_, yp_, q_, v_;
  long maxSteps_;
};

}  // namespace flexmbd
