/// @file
/// Singular positions of a mechanism during a run: the diagnosis of a failure (is the
/// constraint Jacobian G losing rank?) and the crossing with the augmented Lagrangian
/// integrator ALI3-P, after which the DAE integrator restarts.
#pragma once

#include <optional>
#include <string>

#include "core/errors.hpp"
#include "simulation/output_recorder.hpp"
#include "simulation/run_state.hpp"

namespace flexmbd {

/// A run may cross singular positions with ALI3-P: the settings allow it
/// (crossSingular), the run is not on ALI3-P already, and the model has constraints
/// (planar or spatial: ALI3-P integrates q' = T(q) v in velocity space).
bool mayCrossSingularPositions(const System& sys, const SolverSettings& settings, IntegratorKind kind);

/// What singularityDiagnosis measured: the message, and whether it found the mechanism at
/// or approaching a singular position (the cases the augmented-Lagrangian bridge crosses).
struct SingularityDiagnosis {
  std::string text;
  bool singular = false;
  double ratio = 1.0;  ///< smallest/largest singular value of G at the failure
};

/// Smallest/largest singular value of G, or 1 without constraints (G has no rows).
double constraintConditioning(const MatX& G);

/// After a solver failure at tFail: is the mechanism at a singular position? The last
/// output state is carried to tFail (Taylor, then minimum-norm Newton on g(q, tFail) = 0,
/// which may stop short beyond a lock-up) and the constraint Jacobian G is examined there.
/// startRatio: constraintConditioning at the start of the run. An empty diagnosis (text
/// "", not singular) without constraints, or with more constraint equations than
/// velocities. `released`: equations released as redundant (ascending), left out of G.
/// @throws what the constraint evaluation throws.
SingularityDiagnosis singularityDiagnosis(const System& sys, const OutputSample& last, double tFail,
                                          double startRatio, const std::vector<int>& released = {});

/// A crossing of a singular position that failed: the integrator's reason, the diagnosis
/// and why the augmented-Lagrangian bridge could not cross either.
struct CrossingFailure : SolverError {
  using SolverError::SolverError;
};

/// The decision to cross after a failure, and how far.
struct CrossingPlan {
  std::string diagnosis;  ///< singularityDiagnosis's text, for the message if the crossing fails
  int restarts = 0;       ///< consecutive failures just after a crossing, this one included
  /// The crossing ends where the conditioning of G has grown to endFactor times its value
  /// where the crossing began (kCrossingEndFactor, doubled per restart).
  double endFactor = 0.0;
};

/// After the DAE integrator failed: cross (the mechanism is at or approaching a singular
/// position, or the integrator failed just after a crossing) or not (nullopt: crossing is
/// not allowed, the solution diverged, or G is conditioned as at the start).
/// @pre state.integrator is the integrator that failed.
std::optional<CrossingPlan> planCrossing(const RunContext& ctx, const RunState& state,
                                         const RecordedOutputs& outputs, const SolverError& failure);

/// The state a crossing starts from: the integrator's last step before its failure if it
/// keeps it (and the accelerations can be computed there), else the last output.
OutputSample crossingStart(const System& sys, const DaeLayout& layout, const DaeIntegrator& integrator,
                           const SolverError& failure, const OutputSample& lastOutput);

/// Across the singular position where the integrator stopped: the integrator is retired
/// (its statistics go to state.finished), ALI3-P runs from `start` past the failure, writing
/// the outputs on its way, until G is conditioned again (CrossingPlan::endFactor), then the
/// integrator restarts there from a consistent state (unless t_end was reached). The
/// crossing is appended to state.crossings.
/// @pre state.integrator is the integrator that failed; start from crossingStart.
/// @throws CrossingFailure if ALI3-P fails too (its statistics counted); what the
/// outputs throw (OutputRecorder::record) passes through.
void crossSingularPosition(const RunContext& ctx, RunState& state, OutputRecorder& recorder,
                           ProgressReporter& progress, const SolverError& failure, const CrossingPlan& plan,
                           const OutputSample& start);

}  // namespace flexmbd
