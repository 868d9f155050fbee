#include "simulation/simulation.hpp"

#include <cmath>
#include <ctime>
#include <limits>
#include <sstream>

#include "core/errors.hpp"
#include "core/number_text.hpp"
#include "integrators/initial_conditions.hpp"
#include "simulation/integrator_choice.hpp"
#include "analysis/modal_participation.hpp"
#include "simulation/output_recorder.hpp"
#include "simulation/run_stages.hpp"
#include "simulation/run_state.hpp"
#include "simulation/singular_crossing.hpp"

namespace flexmbd {
namespace {

void requireSetting(bool ok, const std::string& key, const std::string& expected, double got) {
  if (!ok) {
    std::ostringstream os;
    os << "solver." << key << ": expected " << expected << ", got " << got;
    throw InputError(os.str());
  }
}

/// Coarsest tolerances accepted. rtol: IDA's error control at 1 % relative error already
/// gives qualitative results only. atol of positions and elastic coordinates: 1 % of the
/// model size, of angles 0.01 rad: above, the error test passes steps whose errors are as
/// large as the mechanism (atol 1e6 on a 0.45 m slider-crank: 18 steps, a constraint
/// violation of 1.87 m, status ok).
constexpr double kMaxRelativeTolerance = 1e-2;
/// Finest tolerances accepted: rtol 1e-14 (about 50 round-offs, IDA cannot meet less);
/// atol 1e-15 of the model size (positions of the size carry round-off of 1e-16 of it):
/// finer ones cannot be met and only make IDA shrink its step until max_steps. The class
/// tolerances are raised to their floors instead (classTolerances).
/// Velocity tolerances are not refused: their floor, 1e-15 of the model's speed scale, is
/// applied by classTolerances (slow modes of stiff chains use atol_velocity 1e-16,
/// tests/test_stability.cpp).
constexpr double kMinRelativeTolerance = 1e-14;
constexpr double kMinToleranceFractionOfSize = kRoundOffFractionOfSize;
constexpr double kMaxToleranceFractionOfSize = 1e-2;
constexpr double kMaxAngleTolerance = 1e-2;

/// Refuses tolerances that cannot give a meaningful result for this model.
void checkTolerancesForModel(const SolverSettings& s, double L) {
  const auto check = [&](bool ok, const std::string& key, const std::string& expected, double got) {
    if (!ok) throw InputError("solver." + key + ": expected " + expected + ", got " + formatValue(got));
  };
  check(s.rtol <= kMaxRelativeTolerance, "rtol", "at most 1e-2 (coarser gives no meaningful result)", s.rtol);
  check(s.rtol >= kMinRelativeTolerance, "rtol", "at least 1e-14 (finer is below round-off)", s.rtol);
  const double minAbs = kMinToleranceFractionOfSize * L;
  const std::string fineBound = "at least 1e-15 of the model size " + formatValue(L) + " (finer is below round-off)";
  // finer atol_angle, atol_elastic (a scene's ratio scaled by --atol) are raised to the floor (classTolerances)
  check(s.atol >= minAbs, "atol", fineBound, s.atol);
  const double maxLength = kMaxToleranceFractionOfSize * L;
  const std::string lengthBound = "at most 1e-2 of the model size " + formatValue(L) + ": " + formatValue(maxLength) +
                                  " (coarser cannot resolve the motion)";
  check(s.atol <= maxLength, "atol", lengthBound, s.atol);
  if (s.atolElastic) check(*s.atolElastic <= maxLength, "atol_elastic", lengthBound, *s.atolElastic);
  if (s.atolAngle) {
    check(*s.atolAngle <= kMaxAngleTolerance, "atol_angle", "at most 1e-2 rad (coarser cannot resolve the motion)",
          *s.atolAngle);
  } else {
    check(s.atol <= kMaxAngleTolerance, "atol", "at most 1e-2 (it is also the tolerance of angles, in rad)", s.atol);
  }
}

}  // namespace

/// Shortest run: the bound of scene numbers (1e100) inverted; below it, squares of the
/// step underflow.
constexpr double kMinTimeSpan = 1e-100;
/// Shortest run relative to |t|: steps of 1e-3 of such a span are still 1e4 round-offs of t.
constexpr double kMinRelativeSpan = 1e-9;
/// Most outputs of a run: 1e8 rows of even a one-body model are 6 GB of results.csv.
constexpr double kMaxOutputs = 1e8;

bool resolvableTimeSpan(double tStart, double tEnd) {
  const double span = tEnd - tStart;
  return span >= kMinTimeSpan && span >= kMinRelativeSpan * std::max(std::fabs(tStart), std::fabs(tEnd));
}

void SolverSettings::validate() const {
  requireSetting(rtol > 0.0 && std::isfinite(rtol), "rtol", "a positive number", rtol);
  requireSetting(atol > 0.0 && std::isfinite(atol), "atol", "a positive number", atol);
  for (const auto& [key, value] : {std::pair{"atol_velocity", atolVelocity}, std::pair{"atol_angle", atolAngle},
                                    std::pair{"atol_elastic", atolElastic}}) {
    if (value) requireSetting(*value > 0.0 && std::isfinite(*value), key, "a positive number", *value);
  }
  requireSetting(std::isfinite(tStart), "t_start", "a finite number", tStart);
  requireSetting(std::isfinite(tEnd) && tEnd > tStart, "t_end", "a number greater than t_start", tEnd);
  requireSetting(outputStep > 0.0 && std::isfinite(outputStep), "output_step", "a positive number",
                 outputStep);
  // A span the integrator can resolve: IDA refuses a stop time within round-off of t_start
  // (IDA_ILL_INPUT for t_end = 1e-300) and needs steps well above round-off of t.
  const double span = tEnd - tStart;
  requireSetting(resolvableTimeSpan(tStart, tEnd), "t_end", kTimeSpanRule, tEnd);
  requireSetting(span / outputStep <= kMaxOutputs, "output_step",
                 "at most 1e8 outputs over t_end - t_start (results.csv would not fit a disk): a larger step",
                 outputStep);
  requireSetting(maxStepSize >= 0.0 && std::isfinite(maxStepSize), "max_step",
                 "a non-negative number (0: no limit)", maxStepSize);
  if (minStepSize) {
    requireSetting(*minStepSize >= 0.0 && std::isfinite(*minStepSize), "min_step",
                   "a non-negative number", *minStepSize);
    requireSetting(*minStepSize < std::min(span, outputStep), "min_step",
                   "less than t_end - t_start and than output_step", *minStepSize);
  }
  requireSetting(initialStepSize >= 0.0 && std::isfinite(initialStepSize), "initial_step",
                 "a non-negative number (0: IDA's estimate)", initialStepSize);
  requireSetting(maxOrder >= 1 && maxOrder <= 5, "max_order", "an integer from 1 to 5",
                 static_cast<double>(maxOrder));
  requireSetting(maxSteps > 0, "max_steps", "a positive integer", static_cast<double>(maxSteps));
  requireSetting(maxTotalSteps > 0, "max_total_steps", "a positive integer", static_cast<double>(maxTotalSteps));
  if (maxStepSize > 0.0) {
    requireSetting(span / maxStepSize <= static_cast<double>(maxTotalSteps), "max_step",
                   "a step that covers t_end - t_start in at most max_total_steps (" + fmt(static_cast<double>(maxTotalSteps)) +
                       ") steps, not " + fmt(span / maxStepSize, 3) + ": a larger max_step, or 0 (no limit)",
                   maxStepSize);
  }
  if (quasiStaticAbove) {
    requireSetting(*quasiStaticAbove > 0.0 && std::isfinite(*quasiStaticAbove), "quasi_static_above",
                   "a positive circular frequency (rad/s)", *quasiStaticAbove);
  }
}

ElasticStart parseElasticStart(const std::string& name) {
  if (name == "given") return ElasticStart::Given;
  if (name == "quasi_static") return ElasticStart::QuasiStatic;
  throw InputError("solver.elastic_start: unknown elastic start '" + name + "' (expected one of: given, quasi_static)");
}

RedundantConstraints parseRedundantConstraints(const std::string& name) {
  if (name == "resolve") return RedundantConstraints::Resolve;
  if (name == "refuse") return RedundantConstraints::Refuse;
  throw InputError("solver.redundant_constraints: unknown choice '" + name + "' (expected one of: resolve, refuse)");
}

std::string toString(RedundantConstraints r) { return r == RedundantConstraints::Refuse ? "refuse" : "resolve"; }

std::string toString(ElasticStart s) { return s == ElasticStart::QuasiStatic ? "quasi_static" : "given"; }

VecX absoluteTolerances(const DaeSystem& dae, const SolverSettings& settings) {
  return absoluteTolerances(dae, classTolerances(settings, modelScales(dae.system(), settings)));
}

// The pipeline of a run: start, choose, integrate (handing over, crossing), diagnose,
// finish; the stages are in simulation/run_stages.hpp.
SimulationSummary simulate(const System& sys, const SolverSettings& settings,
                           const OutputCallback& onOutput) {
  settings.validate();
  if (!sys.isFinalized()) throw InputError("simulate: the system must be finalized first");
  checkTolerancesForModel(settings, sys.characteristicLength());
  const std::clock_t cpuStart = std::clock();
  const double t0 = settings.tStart, tEnd = settings.tEnd;

  // start: the consistent state (the elastic one quasi-static if asked), what it
  // corrected, the first output; the modal content of the flexible bodies at every output
  std::string elasticStart;
  // redundant constraints: refused, or released where they are found dependent
  ReleasedEquations released;
  released.detect = settings.redundantConstraints == RedundantConstraints::Resolve;
  const ConsistentState init = elasticStartState(
      sys, settings, computeConsistentState(sys, t0, sys.initialCoordinates(), sys.initialVelocities(), released),
      elasticStart);
  const DaeSystem dae(sys, settings.formulation, defaultStabilisationMetric(sys), init.released);
  const RunStart start = startRun(dae, init, t0);
  ModalParticipation participation(sys);
  const OutputCallback recordParticipation = [&](const OutputSample& s) {  // outlives the recorder
    participation.add(s.q, s.v);
    if (onOutput) onOutput(s);
  };
  OutputRecorder recorder(sys, start.modelSize, recordParticipation, dae.releasedEquations());
  if (const std::optional<RunFailure> stop = recordInitialOutput(recorder, dae.layout(), start, t0)) {
    return summaryAtStart(start, recorder.recorded(), *stop);
  }

  // choose: the integrator (simulation/integrator_choice.hpp) and its tolerances by
  // coordinate class from the model's scales at the start
  const ModelScales scales = modelScales(sys, init.v, t0, tEnd);
  const ChosenIntegrator choice = chooseIntegratorOptions(sys, dae, settings, &scales);
  const RunContext ctx{sys,
                       dae,
                       settings,
                       choice.options,
                       OutputSchedule(t0, tEnd, settings.outputStep),
                       start.modelSize,
                       start.startRatio,
                       mayCrossSingularPositions(sys, settings, choice.kind)};
  RunState state = startIntegrator(ctx, start, choice.kind);

  // integrate output by output, handing over and crossing; diagnose an early end
  ProgressReporter progress(settings.progress, t0, tEnd, toString(choice.kind));
  const std::optional<RunFailure> failure = integrateAndDiagnose(ctx, state, recorder, progress);

  // finish
  SimulationSummary summary = finishSummary(start, recorder.recorded(), choice, state, failure, tEnd - t0);
  summary.elasticStart = elasticStart;
  for (const int r : dae.releasedEquations()) summary.redundantConstraints.push_back(sys.describeEquation(r));
  summary.modalParticipation = participation.result();
  for (const std::string& w : participation.warnings()) summary.warnings.push_back(w);
  if (!choice.warning.empty()) summary.warnings.push_back(choice.warning);
  summary.cpuSeconds = static_cast<double>(std::clock() - cpuStart) / CLOCKS_PER_SEC;
  return summary;
}

SimulationSummary simulateKeepingFailures(const System& sys, const SolverSettings& settings,
                                          const OutputCallback& onOutput) {
  const std::clock_t start = std::clock();
  double lastDone = std::numeric_limits<double>::quiet_NaN();
  const auto cpu = [&] { return static_cast<double>(std::clock() - start) / CLOCKS_PER_SEC; };
  try {
    return simulate(sys, settings, [&](const OutputSample& sample) {
      onOutput(sample);
      lastDone = sample.t;
    });
  } catch (const InputError&) {  // includes ModelError
    throw;
  } catch (const SolverError& e) {
    SimulationSummary summary;
    summary.ok = false;
    summary.message = e.what();
    summary.tReached = e.time();
    summary.stats.lastStepSize = e.stepSize();
    summary.cpuSeconds = cpu();
    return summary;
  } catch (const std::exception& e) {
    SimulationSummary summary;
    summary.ok = false;
    summary.message = e.what();
    summary.tReached = lastDone;
    summary.cpuSeconds = cpu();
    return summary;
  }
}

}  // namespace flexmbd
