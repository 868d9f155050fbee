#include "simulation/singular_crossing.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

#include <Eigen/SVD>

#include "core/linear_algebra.hpp"
#include "core/system_evaluation.hpp"
#include "integrators/augmented_lagrangian_integrator.hpp"
#include "integrators/initial_conditions.hpp"

namespace flexmbd {
namespace {

/// A constraint row whose Gram-Schmidt remainder falls below this fraction of its norm
/// counts as dependent in a failure diagnosis. Measured (tests/test_stability.cpp): where
/// IDA stops at the lock-up of examples/slider_crank_lockup.json the smallest/largest
/// singular value of G is 1.6e-5, at the crossing of examples/slider_crank_equal_links.json
/// 1e-7; a regular position of the rigid slider-crank has 0.17.
constexpr double kNearlyDependent = 1e-2;

/// A failure is called "approaching a singular position" when the singular value ratio of
/// G has fallen below this fraction of its value at the start of the run (the model's own
/// regular value): 0.1. Measured: the undriven parallelogram fails at 2e-3 and 2e-4 of
/// its starting 0.35 (rtol 1e-10, 1e-8), 0.015 rad before its change point; the
/// slider-crank made to fail at a regular position stays at 0.3-1x its start.
constexpr double kApproachingSingular = 0.1;

/// Where the DAE integrator stops with the constraint Jacobian G worse conditioned than
/// kCrossingTrigger times at the start, the failure is taken for the approach of a singular
/// position and crossed. Measured on the undriven parallelogram: IDA stops at a singular
/// value ratio of 2e-3 (rtol 1e-8) to 0.33 (rtol 1e-12) of its value at the start.
constexpr double kCrossingTrigger = 0.5;
/// A crossing ends past the failure, where the ratio has grown back to kCrossingEndFactor
/// times its value where it began (at most kCrossingEndConditioning of the start's): IDA
/// fails where the ratio is so small for its tolerance, so it restarts well above that.
constexpr double kCrossingEndFactor = 4.0, kCrossingEndConditioning = 0.9;
/// The core of a crossing, from where it begins until the singular value ratio of G, past
/// its minimum, is back at its value there: ALI3-P takes steps of 1/kCoreStepDivisor of the
/// DAE integrator's last regular step (at its last output) without error test (see
/// AugmentedLagrangianIntegrator::setErrorTest): its error estimate measures the positions
/// along the nearly dependent directions, known only to the Newton tolerance, not the
/// truncation error, and collapses the steps (measured on a multi-parallelogram).
constexpr double kCoreStepDivisor = 2.0;
/// Tolerances of a crossing relative to the run's: ALI3-P is of order 2 against IDA's 5, so
/// its local errors are held smaller for global errors of the same size.
constexpr double kCrossingToleranceFactor = 1e-2;
/// ... but not below rtol 1e-12: at 1e-14 the error estimate h^2/12 (a_{n+1} - a_n) is
/// round-off near the singular position (accelerations along the nearly dependent
/// direction are determined to 1/sigma_min) and the steps collapse (measured).
constexpr double kMinCrossingRtol = 1e-12;
/// ... and absolute ones not below 1e3 round-offs of the model size.
constexpr double kMinCrossingAtolRoundOffs = 1e3;
/// An integrator that fails within this many steps of its restart after a crossing has not
/// left the singular position's neighbourhood: the crossing goes on, to twice the ratio.
constexpr long kRestartSteps = 50;

/// Most steps of one crossing. Measured: 4 to 226 steps per crossing on the undriven
/// parallelogram (rtol 1e-8); a driven lock-up at rtol 1e-4 ground on for 1,000,000 steps
/// (78 s CPU) before max_steps ended it. 20,000 is 90 times the largest measured.
constexpr long kMaxCrossingSteps = 20000;
/// Most consecutive attempts at one singular position (a failure within kRestartSteps of the
/// restart is crossed again with twice the end ratio): 8 doublings reach 1000 times the
/// start of the crossing, beyond which the ratio is capped by kCrossingEndConditioning anyway.
constexpr int kMaxCrossingRestarts = 8;

/// The options of ALI3-P for a crossing of this run, its first step a fraction of the DAE
/// integrator's last regular one.
AugmentedLagrangianOptions crossingOptions(const RunContext& ctx, double regularStep) {
  const SolverSettings& settings = ctx.settings;
  const DaeLayout& L = ctx.dae.layout();
  AugmentedLagrangianOptions bo;
  const double factor = std::max(kCrossingToleranceFactor, kMinCrossingRtol / settings.rtol);
  bo.rtol = settings.rtol * factor;
  // not below round-off of the model's size (coordinates near 0 have weight atol alone)
  bo.atolPosition = (factor * ctx.options.atol.segment(L.q, L.nq))
                        .cwiseMax(kMinCrossingAtolRoundOffs * std::numeric_limits<double>::epsilon() * ctx.modelSize);
  bo.maxStepSize = settings.maxStepSize;
  bo.minStepSize = ctx.options.minStepSize;
  bo.lengthScale = ctx.modelSize;
  bo.initialStepSize = regularStep / kCoreStepDivisor;
  bo.released = ctx.dae.releasedEquations();  // as the run integrates them
  return bo;
}

}  // namespace

bool mayCrossSingularPositions(const System& sys, const SolverSettings& settings, IntegratorKind kind) {
  return settings.crossSingular && kind != IntegratorKind::AugmentedLagrangian && sys.numConstraintEquations() > 0;
}

double constraintConditioning(const MatX& G) { return singularValueRatio(G); }

SingularityDiagnosis singularityDiagnosis(const System& sys, const OutputSample& last, double tFail,
                                          double startRatio, const std::vector<int>& released) {
  const int m = sys.numConstraintEquations() - static_cast<int>(released.size());
  if (m == 0 || last.q.size() == 0 || m > sys.numVelocities()) return {};
  const double dt = tFail - last.t;
  VecX q = sys.applyIncrement(last.q, dt * last.v + 0.5 * dt * dt * last.a);
  VecX g;
  MatX G;
  evaluateConstraints(sys, q, tFail, &g, &G);
  for (int it = 0; it < 10 && g.allFinite() && g.lpNorm<Eigen::Infinity>() > 1e-13 * (1.0 + q.norm()); ++it) {
    const VecX dq = -G.completeOrthogonalDecomposition().solve(g);
    if (!dq.allFinite() || dq.norm() > 0.1 * (1.0 + q.norm())) break;  // diverging: keep the last q
    VecX gn;
    MatX Gn;
    const VecX qn = sys.applyIncrement(q, dq);
    evaluateConstraints(sys, qn, tFail, &gn, &Gn);
    if (!gn.allFinite() || gn.norm() >= g.norm()) break;
    q = qn;
    g = gn;
    G = Gn;
  }
  if (!G.allFinite()) return {};
  std::vector<int> kept;  // the equations not released, as rows of the full G
  for (int i = 0, k = 0; i < G.rows(); ++i) {
    if (k < static_cast<int>(released.size()) && released[k] == i) {
      ++k;
    } else {
      kept.push_back(i);
    }
  }
  G = withoutRows(G, released);
  const double ratio = constraintConditioning(G);
  std::vector<int> rows = dependentRows(G, kNearlyDependent);
  for (int& r : rows) r = kept[r];
  bool driven = false;
  for (int c = 0; c < sys.numConstraints(); ++c) driven = driven || sys.constraint(ConstraintIndex(c)).isDriver();
  std::ostringstream os;
  os.precision(3);
  os << "; constraint Jacobian at t = " << formatTime(tFail) << ": smallest/largest singular value " << ratio << " ("
     << startRatio << " at the start)";
  if (rows.empty()) {
    if (ratio < kApproachingSingular * startRatio) {
      os << ", full rank but " << startRatio / ratio
         << " times worse conditioned than at the start: the mechanism is approaching a singular position";
      return {os.str(), true, ratio};
    }
    os << ", full rank and conditioned as at the start: not a singular position";
    return {os.str(), false, ratio};
  }
  os << ", nearly rank-deficient: ";
  for (size_t k = 0; k < rows.size(); ++k) os << (k ? "; " : "") << sys.describeEquation(rows[k]);
  os << (rows.size() == 1 ? " becomes" : " become") << " dependent on the "
     << (driven ? "joints and drivers" : "joints") << " defined before: "
     << (driven ? "a singular position (lock-up, dead centre or change point) where the drivers do not determine "
                  "the motion"
                : "a singular position of the undriven mechanism (change point or dead centre), where the "
                  "constraints lose rank");
  return {os.str(), true, ratio};
}

std::optional<CrossingPlan> planCrossing(const RunContext& ctx, const RunState& state,
                                         const RecordedOutputs& outputs, const SolverError& failure) {
  if (!ctx.mayCross || outputs.diverged(ctx.modelSize)) return std::nullopt;
  SingularityDiagnosis d;
  try {
    d = singularityDiagnosis(ctx.sys, outputs.last, failure.time(), ctx.startRatio, ctx.dae.releasedEquations());
  } catch (const std::exception&) {
    // no diagnosis: only a failure just after a crossing is crossed
  }
  // a failure just after a crossing is part of it (the restart was too close to the singular position)
  const bool justRestarted = !state.crossings.empty() && state.integrator->stats().steps < kRestartSteps;
  if (!d.singular && d.ratio >= kCrossingTrigger * ctx.startRatio && !justRestarted) return std::nullopt;
  CrossingPlan plan;
  plan.diagnosis = d.text;
  plan.restarts = justRestarted ? state.restarts + 1 : 0;
  if (plan.restarts > kMaxCrossingRestarts) {
    throw CrossingFailure(std::string(failure.what()) + d.text + "; crossing the singular position failed " +
                              std::to_string(plan.restarts) + " times in a row (at most " +
                              std::to_string(kMaxCrossingRestarts) + " attempts): the integrator does not get past it",
                          failure.time(), failure.stepSize());
  }
  plan.endFactor = kCrossingEndFactor * std::pow(2.0, plan.restarts);
  return plan;
}

OutputSample crossingStart(const System& sys, const DaeLayout& layout, const DaeIntegrator& integrator,
                           const SolverError& failure, const OutputSample& lastOutput) {
  VecX yf;
  if (integrator.solutionAtFailure(yf) && failure.time() > lastOutput.t) {
    OutputSample s;
    s.t = failure.time();
    s.q = yf.segment(layout.q, layout.nq);
    s.v = yf.segment(layout.v, layout.nv);
    try {
      computeAccelerations(sys, s.t, s.q, s.v, s.a, s.lambda);
      if (s.q.allFinite() && s.v.allFinite() && s.a.allFinite() && s.lambda.allFinite()) return s;
    } catch (const std::exception&) {
      // no accelerations there: the crossing starts from the last output
    }
  }
  return lastOutput;
}

void crossSingularPosition(const RunContext& ctx, RunState& state, OutputRecorder& recorder,
                           ProgressReporter& progress, const SolverError& failure, const CrossingPlan& plan,
                           const OutputSample& start) {
  addStats(state.finished, state.integrator->stats());
  state.integrator.reset();
  const OutputSchedule& outputs = ctx.outputs;
  const double tEnd = outputs.tEnd;
  const long maxSteps = ctx.settings.maxSteps;
  SingularCrossing crossing;
  crossing.tFailure = failure.time();
  crossing.tStart = start.t;
  AugmentedLagrangianIntegrator ali(ctx.sys, start.t, start.q, start.v, start.a, start.lambda,
                                    crossingOptions(ctx, state.regularStep));
  const double ratio0 = ali.constraintConditioning();
  const double endRatio = std::min(plan.endFactor * ratio0, kCrossingEndConditioning * ctx.startRatio);
  double minRatio = ratio0;
  ali.setErrorTest(false);
  VecX qi, vi;
  try {
    const long stepBound = std::min(maxSteps, kMaxCrossingSteps);
    for (long steps = 0;; ++steps) {
      if (steps >= stepBound) {
        throw SolverError("more than " + std::to_string(stepBound) +
                              (stepBound == maxSteps ? " steps (max_steps)" : " steps in one crossing") +
                              ", from t = " + formatTime(start.t) + " to t = " + formatTime(ali.time()) +
                              " (a crossing takes at most " + std::to_string(kMaxCrossingSteps) +
                              "): the mechanism does not get past the singular position at this tolerance",
                          ali.time(), ali.stats().lastStepSize);
      }
      const double t = ali.step(tEnd);
      for (long& k = state.nextOutput; k <= outputs.count && outputs.time(k) <= t; ++k) {
        ali.interpolate(outputs.time(k), qi, vi);
        recorder.record(outputs.time(k), qi, vi);
        progress.update(outputs.time(k), state.totalSteps() + ali.stats().steps);
      }
      if (t >= tEnd) break;
      const double ratio = ali.constraintConditioning();
      minRatio = std::min(minRatio, ratio);
      if (ratio > minRatio && ratio >= ratio0) ali.setErrorTest(true);  // the core is passed
      if (t > failure.time() && ratio >= endRatio) break;
    }
  } catch (const SolverError& e) {
    addStats(state.finished, ali.stats());
    throw CrossingFailure(std::string(failure.what()) + plan.diagnosis +
                              "; crossing it with the augmented Lagrangian integrator (ali3p) from t = " +
                              formatTime(start.t) + " failed too: " + e.what(),
                          std::max(failure.time(), e.time()), e.stepSize());
  }
  crossing.tEnd = ali.time();
  crossing.steps = ali.stats().steps;
  state.crossings.push_back(crossing);
  addStats(state.finished, ali.stats());
  if (ali.time() < tEnd) {
    const ConsistentState cs =
        computeConsistentState(ctx.sys, ali.time(), ali.q(), ali.v(), {false, ctx.dae.releasedEquations()});
    VecX y, yp;
    packConsistentState(ctx.dae, cs, y, yp);
    state.restart(ctx.dae, ali.time(), y, yp, ctx.options);
  }
}

}  // namespace flexmbd
