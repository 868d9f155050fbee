#include "simulation/run_stages.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "core/errors.hpp"
#include "core/number_text.hpp"
#include "core/user_function.hpp"
#include "core/system_evaluation.hpp"
#include "integrators/bdf_stability.hpp"
#include "simulation/integrator_choice.hpp"
#include "simulation/singular_crossing.hpp"

namespace flexmbd {
namespace {

/// Warning thresholds: position constraint violation above 1e-3 of the model size,
/// velocity violation above 1e-3 of the model's velocity scale (largest speed seen, at
/// least size / span), an initial correction above 1e-3 of the size or 1e-3 rad. Ten
/// times below the coarsest tolerance accepted; regular runs stay 1e5 times below them.
constexpr double kWarnFraction = 1e-3;
constexpr double kWarnAngle = 1e-3;

/// Default min_step: 1e-12 of the span, at most 1e-12 s. Of the span alone, a long run
/// (t_end = 2^31 s) got min_step = 2e-3 s and failed at its first step. 1e-12 s is below
/// every physical time scale of the models (their fastest elastic modes have periods above
/// 1e-6 s): a step that small has collapsed (lock-up, singularity), it does not resolve.
constexpr double kDefaultMinStepFraction = 1e-12;
constexpr double kDefaultMinStepSeconds = 1e-12;

/// IDA is caught in the order-1 trap when at least kTrapFraction of its steps over a window
/// of kTrapWindow steps failed the error test (measured: 458,257 failures in 460,780 steps
/// on the 4-element crank with Rayleigh beta 3e-4 s, 24 s; Radau IIA: 844 steps, 15
/// failures, 0.03 s). Healthy runs stay below 0.1 (the undamped rod: 1.4 %).
constexpr long kTrapWindow = 2000;

/// A conservative run fails when its energy grows by more than this fraction of the largest
/// kinetic energy of its outputs: BDF and Radau IIA dissipate (their energy errors are
/// losses of the order of rtol; the default suite's conservative runs all pass), and energy
/// created from nothing (an overflowing 1/m) is 100 % of it.
constexpr double kMaxEnergyGrowthFraction = 0.1;
/// Round-offs of the energy's magnitude never counted as growth.
constexpr double kEnergyRoundOffs = 1e3;
constexpr double kTrapFraction = 0.8;

std::string initialCorrectionWarning(const InitialCorrection& c) {
  return "initial position of body '" + c.body + "' corrected: " + c.coordinate + " given " + formatValue(c.given) +
         ", now " + formatValue(c.corrected) + " (largest change " + formatValue(c.position) + " in position, " +
         formatValue(c.angle) + " rad in angle) to satisfy " +
         (c.constraint.empty() ? std::string("the joints of other bodies")
                               : c.constraint + " (residual " + formatValue(c.residual) + " at the given values)");
}

RunFailure interruptedAt(const RunInterrupted& e, double t) { return {e.what(), t, e.signal, false}; }
RunFailure writeFailedAt(const OutputWriteError& e, double t) { return {e.what(), t, 0, true}; }

/// The solver's reason, with what the outputs show: the divergence, or else the
/// singularity diagnosis at tDiagnosis. Each part is optional: if one cannot be computed,
/// the message keeps what came before it.
std::string withDiagnosis(std::string message, const FailureContext& ctx, double tDiagnosis) {
  if (const std::string note = ctx.outputs.largeDeformationNote(ctx.modelSize); !note.empty()) {
    message += "; " + note;
  }
  try {
    message += divergenceReport(ctx.outputs.largestCoordinate, ctx.modelSize, ctx.outputs.tEvaluating);
    if (!ctx.outputs.diverged(ctx.modelSize)) {
      message += singularityDiagnosis(ctx.sys, ctx.outputs.last, tDiagnosis, ctx.startRatio,
                                      ctx.released ? *ctx.released : std::vector<int>{})
                     .text;
    }
  } catch (const std::exception&) {
    // the diagnosis is optional: the solver's reason stays the message
  }
  return message;
}

}  // namespace

// --- start -------------------------------------------------------------------------

std::vector<InitialCorrection> initialCorrections(const System& sys, double t0, const VecX& given,
                                                  const VecX& corrected, double modelSize) {
  std::vector<InitialCorrection> out;
  VecX g;
  if (sys.numConstraintEquations() > 0) evaluateConstraints(sys, given, t0, &g, nullptr);
  const std::vector<std::string> names = sys.coordinateNames();
  const std::vector<CoordinateKind> kinds = sys.coordinateKinds();
  for (int b = 1; b < sys.numBodies(); ++b) {
    const Body& body = sys.body(BodyIndex(b));
    const int off = sys.coordinateOffset(BodyIndex(b));
    InitialCorrection c;
    c.body = body.name();
    double worst = 0.0;  // change relative to its warning threshold
    for (int k = off; k < off + body.numCoordinates(); ++k) {
      const double d = std::fabs(corrected[k] - given[k]);
      const bool angle = kinds[k] == CoordinateKind::Angle;
      (angle ? c.angle : c.position) = std::max(angle ? c.angle : c.position, d);
      const double rel = d / (angle ? kWarnAngle : kWarnFraction * modelSize);
      if (rel > worst) {
        worst = rel;
        c.coordinate = names[k];
        c.given = given[k];
        c.corrected = corrected[k];
      }
    }
    if (c.position == 0.0 && c.angle == 0.0) continue;
    for (int ci = 0; ci < sys.numConstraints(); ++ci) {
      const Constraint& con = sys.constraint(ConstraintIndex(ci));
      const auto& bodies = con.bodies();
      if (std::find(bodies.begin(), bodies.end(), BodyIndex(b)) == bodies.end()) continue;
      const int row0 = sys.constraintOffset(ConstraintIndex(ci));
      for (int r = row0; r < row0 + con.numEquations(); ++r) {
        if (std::fabs(g[r]) > c.residual) {
          c.residual = std::fabs(g[r]);
          c.constraint = std::string(con.isDriver() ? "driver '" : "joint '") + con.name() + "'";
        }
      }
    }
    out.push_back(c);
  }
  return out;
}

/// One warning per body whose given initial velocities, not all zero, were changed by
/// more than kWarnFraction of the velocity scale to satisfy the joints (a body given at
/// rest takes its drivers' and joints' velocities without a word: that is how driven
/// models start). Scale: the largest given speed, angular rates times the model size.
void velocityCorrectionWarnings(const System& sys, const VecX& given, const VecX& corrected, double modelSize,
                                std::vector<std::string>& warnings) {
  const std::vector<CoordinateKind> kinds = sys.velocityKinds();
  const auto speed = [&](int k, double x) { return std::fabs(x) * (kinds[k] == CoordinateKind::Angle ? modelSize : 1.0); };
  double scale = 0.0;
  for (int k = 0; k < given.size(); ++k) scale = std::max(scale, speed(k, given[k]));
  if (!(scale > 0.0)) return;
  const std::vector<std::string> names = sys.velocityNames();
  for (int b = 1; b < sys.numBodies(); ++b) {
    const Body& body = sys.body(BodyIndex(b));
    const int off = sys.velocityOffset(BodyIndex(b)), n = body.numVelocities();
    if (given.segment(off, n).cwiseAbs().maxCoeff() == 0.0) continue;  // given at rest
    int worst = -1;
    double change = 0.0;
    for (int k = off; k < off + n; ++k) {
      const double d = speed(k, corrected[k] - given[k]);
      if (d > change) change = d, worst = k;
    }
    if (worst < 0 || change <= kWarnFraction * scale) continue;
    warnings.push_back("initial velocity of body '" + body.name() + "' corrected: " + names[worst] + " given " +
                       formatValue(given[worst]) + ", now " + formatValue(corrected[worst]) +
                       " to satisfy the joints and drivers (velocities that violate them are projected onto them)");
  }
}

RunStart startRun(const DaeSystem& dae, const ConsistentState& init, double t0) {
  const System& sys = dae.system();
  RunStart start;
  dae.packState(init.q, init.v, init.a, init.lambda, start.y0, start.yp0);
  start.positionIterations = init.positionIterations;
  start.modelSize = sys.characteristicLength();
  start.corrections = initialCorrections(sys, t0, sys.initialCoordinates(), init.q, start.modelSize);
  for (const InitialCorrection& c : start.corrections) {
    if (c.position > kWarnFraction * start.modelSize || c.angle > kWarnAngle) {
      start.warnings.push_back(initialCorrectionWarning(c));
    }
  }
  velocityCorrectionWarnings(sys, sys.initialVelocities(), init.v, start.modelSize, start.warnings);
  if (!dae.releasedEquations().empty()) {
    // one line at the start naming what was released (the summary lists them too)
    std::string names;
    for (const int r : dae.releasedEquations()) names += (names.empty() ? "" : "; ") + sys.describeEquation(r);
    start.warnings.push_back("redundant constraints resolved: " + names +
                             (dae.releasedEquations().size() == 1 ? " depends" : " depend") +
                             " on the joints and drivers defined before and "+
                             (dae.releasedEquations().size() == 1 ? "is" : "are") + " released (integrated with the "
                             "independent equations); the reactions of the redundant set are not unique, the "
                             "minimum-norm ones are reported");
  }
  if (dae.layout().m > 0) {
    MatX G0;
    evaluateConstraints(sys, init.q, t0, nullptr, &G0);
    start.startRatio = constraintConditioning(withoutRows(G0, dae.releasedEquations()));
  }
  return start;
}

std::optional<RunFailure> recordInitialOutput(OutputRecorder& recorder, const DaeLayout& layout,
                                              const RunStart& start, double t0) {
  try {
    recorder.record(t0, start.y0.segment(layout.q, layout.nq), start.y0.segment(layout.v, layout.nv));
  } catch (const NonFiniteResult& e) {
    // Nothing was integrated: the scene's own values overflow (masses, speeds, loads).
    throw InputError(std::string("the initial state has ") + e.what() +
                     ": values of the scene overflow (check masses, inertias, speeds, loads)");
  } catch (const RunInterrupted& e) {
    return interruptedAt(e, t0);
  } catch (const OutputWriteError& e) {
    return writeFailedAt(e, t0);
  }
  return std::nullopt;
}

// --- choose ------------------------------------------------------------------------

double defaultMinStepSize(const SolverSettings& settings) {
  return std::min(kDefaultMinStepFraction * (settings.tEnd - settings.tStart), kDefaultMinStepSeconds);
}

ChosenIntegrator chooseIntegratorOptions(const System& sys, const DaeSystem& dae, const SolverSettings& settings,
                                         const ModelScales* scales) {
  ChosenIntegrator choice;
  const IntegratorChoice picked = chooseIntegrator(sys, settings);
  choice.kind = picked.kind;
  choice.reason = picked.reason;
  choice.warning = picked.warning;
  choice.scales = scales ? *scales : modelScales(sys, settings);
  choice.tolerances = classTolerances(settings, choice.scales);
  IntegratorOptions& o = choice.options;
  o.rtol = settings.rtol;
  o.atol = absoluteTolerances(dae, choice.tolerances);
  applyEnergyVelocityWeights(picked, dae.layout(), o.atol);
  o.maxSteps = settings.maxSteps;
  o.maxStepSize = settings.maxStepSize;
  o.maxOrder = settings.maxOrder;
  if (choice.kind == IntegratorKind::Ida && settings.formulation != Formulation::Index1) {
    // Damped modes outside the A(alpha) sectors of BDF4/5 set off bursts of error-test
    // failures that strand IDA at order 1 with GGL (docs/formulations.md; index 1 measured unaffected)
    const BdfOrderLimit limit = stableBdfOrder(sys, settings.maxOrder);
    o.maxOrder = limit.order;
    choice.orderLimit = limit.reason();
  }
  o.initialStepSize = settings.initialStepSize;
  o.minStepSize = settings.minStepSize.value_or(defaultMinStepSize(settings));
  o.linearSolver = settings.linearSolver;
  o.finiteDifferenceJacobian = settings.finiteDifferenceJacobian;
  return choice;
}

// --- integrate and hand over -------------------------------------------------------

RunState startIntegrator(const RunContext& ctx, const RunStart& start, IntegratorKind kind) {
  RunState state;
  state.kind = kind;
  state.restart(ctx.dae, ctx.outputs.t0, start.y0, start.yp0, ctx.options);
  state.usedKlu = state.integrator->usesKlu();
  return state;
}

bool StepWindow::complete() const { return steps >= kTrapWindow; }

StepWindow stepWindow(const IntegratorStats& now, const IntegratorStats& windowStart) {
  return {now.steps - windowStart.steps, now.errorTestFailures - windowStart.errorTestFailures};
}

std::optional<std::string> shouldHandOver(IntegratorKind kind, const StepWindow& window, bool outputsRemain,
                                          bool finiteDifferenceJacobian, double t) {
  if (!window.complete() || kind != IntegratorKind::Ida || !outputsRemain || finiteDifferenceJacobian) {
    return std::nullopt;
  }
  if (static_cast<double>(window.errorTestFailures) < kTrapFraction * static_cast<double>(window.steps)) {
    return std::nullopt;
  }
  return "at t = " + formatTime(t) + " from ida to radau5: " + std::to_string(window.errorTestFailures) +
         " error-test failures in the last " + std::to_string(window.steps) + " steps";
}

void handOverToRadau(const RunContext& ctx, RunState& state, const OutputSample& last, const std::string& reason) {
  state.integratorSwitch = reason;
  const ConsistentState cs =
      computeConsistentState(ctx.sys, last.t, last.q, last.v, {false, ctx.dae.releasedEquations()});
  VecX y, yp;
  packConsistentState(ctx.dae, cs, y, yp);
  addStats(state.finished, state.integrator->stats());
  state.kind = IntegratorKind::Radau5;
  state.restart(ctx.dae, last.t, y, yp, ctx.options);
}

void requireStepBudget(const RunContext& ctx, const RunState& state, double t) {
  const long steps = state.totalSteps();
  if (steps <= ctx.settings.maxTotalSteps) return;
  const double mean = (t - ctx.outputs.t0) / static_cast<double>(steps);
  throw StepBudgetExceeded("the run took " + std::to_string(steps) + " steps by t = " + formatTime(t) +
                               ", more than max_total_steps (" + std::to_string(ctx.settings.maxTotalSteps) +
                               "): its steps average " + fmt(mean, 3) + " s, " + fmt(mean / ctx.settings.outputStep, 3) +
                               " of the output step (a model far stiffer than its outputs need, a tiny max_step, or "
                               "a motion out of control; raise max_total_steps for a longer run: docs/stability.md, "
                               "section 8)",
                           t);
}

void integrateToNextOutput(const RunContext& ctx, RunState& state, OutputRecorder& recorder,
                           ProgressReporter& progress) {
  const DaeLayout& L = ctx.dae.layout();
  const long k = state.nextOutput;
  const double t = state.integrator->advance(ctx.outputs.time(k), ctx.outputs.tEnd);
  recorder.record(t, state.integrator->y().segment(L.q, L.nq), state.integrator->y().segment(L.v, L.nv));
  progress.update(t, state.totalSteps());
  requireStepBudget(ctx, state, t);
  const IntegratorStats now = state.integrator->stats();
  state.regularStep = now.lastStepSize;
  // IDA rejecting nearly every step (the order-1 trap of heavily damped elastic modes,
  // docs/formulations.md): the rest of the run with Radau IIA
  const StepWindow window = stepWindow(now, state.windowStart);
  if (const std::optional<std::string> reason = shouldHandOver(
          state.kind, window, k < ctx.outputs.count, ctx.options.finiteDifferenceJacobian, t)) {
    handOverToRadau(ctx, state, recorder.recorded().last, *reason);
  } else if (window.complete()) {
    state.windowStart = now;
  }
  state.nextOutput = k + 1;
}

void integrateOutputs(const RunContext& ctx, RunState& state, OutputRecorder& recorder, ProgressReporter& progress) {
  while (state.nextOutput <= ctx.outputs.count) {
    try {
      while (state.nextOutput <= ctx.outputs.count) integrateToNextOutput(ctx, state, recorder, progress);
    } catch (const SolverError& failure) {
      const std::optional<CrossingPlan> plan = planCrossing(ctx, state, recorder.recorded(), failure);
      if (!plan) throw;
      state.restarts = plan->restarts;
      const OutputSample start =
          crossingStart(ctx.sys, ctx.dae.layout(), *state.integrator, failure, recorder.recorded().last);
      crossSingularPosition(ctx, state, recorder, progress, failure, *plan, start);
    }
  }
}

std::optional<RunFailure> integrateOnOneIntegrator(const RunContext& ctx, RunState& state, OutputRecorder& recorder,
                                                   ProgressReporter& progress) {
  const DaeLayout& L = ctx.dae.layout();
  try {
    for (; state.nextOutput <= ctx.outputs.count; ++state.nextOutput) {
      const double t = state.integrator->advance(ctx.outputs.time(state.nextOutput), ctx.outputs.tEnd);
      requireStepBudget(ctx, state, t);
      recorder.record(t, state.integrator->y().segment(L.q, L.nq), state.integrator->y().segment(L.v, L.nv));
      progress.update(t, state.totalSteps());
    }
    return std::nullopt;
  } catch (...) {
    const FailureContext failed{ctx.sys, recorder.recorded(), ctx.modelSize, ctx.startRatio,
                                state.integrator->stats().currentTime, &ctx.dae.releasedEquations()};
    return diagnoseFailure(std::current_exception(), failed);
  }
}

// --- diagnose ----------------------------------------------------------------------

std::string divergenceReport(double largest, double modelSize, double t) {
  if (!hasDiverged(largest, modelSize)) return "";
  std::ostringstream os;
  os.precision(3);
  os << "; the solution diverged: a coordinate reached " << largest << " at t = " << formatTime(t) << ", "
     << largest / modelSize << " times the model size " << modelSize;
  return os.str();
}

RunFailure diagnoseFailure(const std::exception_ptr& error, const FailureContext& ctx) {
  const double tOutput = ctx.outputs.tEvaluating;
  try {
    std::rethrow_exception(error);
  } catch (const CrossingFailure& e) {
    return {e.what(), e.time()};
  } catch (const StepBudgetExceeded& e) {
    return {e.what(), e.time()};
  } catch (const UserFunctionError& e) {  // a user law raised: its message, at its time
    return {e.what(), e.time()};
  } catch (const SolverError& e) {
    return {withDiagnosis(e.what(), ctx, e.time()), e.time()};
  } catch (const RunInterrupted& e) {
    return interruptedAt(e, tOutput);
  } catch (const OutputWriteError& e) {
    return writeFailedAt(e, tOutput);
  } catch (const NonFiniteResult& e) {
    return {std::string(e.what()) + ": the run stops before this output (the rows before it are kept)", tOutput};
  } catch (const std::exception& e) {
    // an input error found during the run (exit 2) and an assembly bug keep their type;
    // a model error at an output state (ModelError, a singular matrix) is a failed run
    const bool inputError = dynamic_cast<const InputError*>(&e) && !dynamic_cast<const ModelError*>(&e);
    if (inputError || dynamic_cast<const std::logic_error*>(&e)) throw;
    // post-processing of an output state failed (e.g. a singular mass matrix after the
    // solution blew up, or an output exactly at a singular position of the mechanism,
    // where the augmented matrix for the accelerations is singular): a failure of the
    // run, reported like a solver failure
    return {withDiagnosis("evaluating the outputs at t = " + std::to_string(tOutput) + " failed: " + e.what(), ctx,
                          tOutput),
            ctx.integratorTime.value_or(tOutput)};
  }
}

std::optional<RunFailure> integrateAndDiagnose(const RunContext& ctx, RunState& state, OutputRecorder& recorder,
                                               ProgressReporter& progress) {
  try {
    integrateOutputs(ctx, state, recorder, progress);
    return std::nullopt;
  } catch (...) {
    const std::optional<double> integratorTime =
        state.integrator ? std::optional<double>(state.integrator->stats().currentTime) : std::nullopt;
    return diagnoseFailure(std::current_exception(),
                           FailureContext{ctx.sys, recorder.recorded(), ctx.modelSize, ctx.startRatio, integratorTime,
                                          &ctx.dae.releasedEquations()});
  }
}

// --- finish ------------------------------------------------------------------------

namespace {

/// What the start and the outputs recorded.
SimulationSummary summaryOfOutputs(const RunStart& start, const RecordedOutputs& outputs) {
  SimulationSummary s;
  s.initialPositionIterations = start.positionIterations;
  s.modelSize = start.modelSize;
  s.initialCorrections = start.corrections;
  s.warnings = start.warnings;
  s.tReached = outputs.tReached;
  s.maxPositionViolation = outputs.maxPositionViolation;
  s.maxVelocityViolation = outputs.maxVelocityViolation;
  s.energyStart = outputs.energyStart;
  s.energyEnd = outputs.energyEnd;
  return s;
}

void applyFailure(SimulationSummary& s, const RunFailure& failure) {
  s.ok = false;
  s.message = failure.message;
  s.failureTime = failure.time;
  s.interruptedBySignal = failure.signal;
  s.outputFailed = failure.outputFailed;
}

}  // namespace

SimulationSummary summaryAtStart(const RunStart& start, const RecordedOutputs& outputs, const RunFailure& failure) {
  SimulationSummary s = summaryOfOutputs(start, outputs);
  applyFailure(s, failure);
  return s;
}

SimulationSummary finishSummary(const RunStart& start, const RecordedOutputs& outputs, const ChosenIntegrator& choice,
                                const RunState& state, const std::optional<RunFailure>& failure, double span) {
  SimulationSummary s = summaryOfOutputs(start, outputs);
  s.usedKlu = state.usedKlu;
  s.maxOrder = choice.options.maxOrder;
  s.orderLimit = choice.orderLimit;
  s.integrator = choice.kind;
  s.integratorReason = choice.reason;
  s.scales = choice.scales;
  s.tolerances = choice.tolerances;
  s.integratorSwitch = state.integratorSwitch;
  s.singularCrossings = state.crossings;
  s.stats = state.totalStats();
  if (failure) applyFailure(s, *failure);
  const double modelSize = start.modelSize;
  const double velocityScale = std::max(outputs.maxSpeed, modelSize / span);
  if (s.maxPositionViolation > kWarnFraction * modelSize) {
    s.warnings.push_back("position constraints violated by up to " + formatValue(s.maxPositionViolation) +
                         ", more than 1e-3 of the model size " + formatValue(modelSize) +
                         ": the results are not accurate (tighten atol and rtol)");
  }
  if (const std::string note = outputs.largeDeformationNote(modelSize); !note.empty()) s.warnings.push_back(note);
  if (s.maxVelocityViolation > kWarnFraction * velocityScale) {
    s.warnings.push_back("velocity constraints violated by up to " + formatValue(s.maxVelocityViolation) +
                         ", more than 1e-3 of the velocity scale " + formatValue(velocityScale) +
                         ": the results are not accurate (tighten atol and rtol)");
  }
  if (s.ok && s.energyStart && s.energyEnd) {
    if (const std::optional<std::string> grown = energyGrowth(*s.energyStart, *s.energyEnd, outputs.maxKineticEnergy)) {
      // a conservative model gained energy: not a result (the rows are kept)
      s.ok = false;
      s.message = *grown;
      s.failureTime = outputs.tReached;
    }
  }
  if (s.ok) s.message = "reached t_end";
  return s;
}

std::optional<std::string> energyGrowth(double energyStart, double energyEnd, double maxKinetic) {
  const double growth = energyEnd - energyStart;
  // round-off of the energy itself: 1e3 eps of its magnitude (potential energies carry an offset)
  const double floor = kEnergyRoundOffs * std::numeric_limits<double>::epsilon() *
                       std::max(std::fabs(energyStart), std::fabs(energyEnd));
  if (!(growth > kMaxEnergyGrowthFraction * maxKinetic + floor)) return std::nullopt;
  return "the energy grew without input: the model is conservative (no drivers, dampers or non-conservative "
         "forces) but its energy went from " + fmt(energyStart, 6) + " to " + fmt(energyEnd, 6) + " J, by " +
         fmt(growth, 3) + ", more than " + fmt(kMaxEnergyGrowthFraction) + " of the largest kinetic energy " +
         fmt(maxKinetic, 3) + " J: the results are not physical (tighten rtol and atol, check tiny or huge masses "
         "and stiffnesses)";
}

}  // namespace flexmbd
