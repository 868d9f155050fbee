/// @file
/// The stages of a run (simulate in simulation/simulation.cpp reads as their pipeline):
///   start      the consistent initial state, the corrections it made, the first output;
///   choose     the integrator's options (tolerances, BDF order limit, min step);
///   integrate  output by output, handing IDA over to Radau IIA when it is trapped and
///              crossing singular positions (simulation/singular_crossing.hpp);
///   diagnose   the message of a run that stopped early;
///   finish     the summary and its warnings.
#pragma once

#include <exception>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "integrators/initial_conditions.hpp"
#include "simulation/output_recorder.hpp"
#include "simulation/run_state.hpp"
#include "simulation/tolerances.hpp"

namespace flexmbd {

// --- start -------------------------------------------------------------------------

/// What the start of a run found: the packed consistent state and what the
/// initialisation changed.
struct RunStart {
  VecX y0, yp0;                ///< the DAE's consistent initial values
  int positionIterations = 0;  ///< Newton iterations of the position projection
  double modelSize = 1.0;      ///< System::characteristicLength(): the scale of the warnings
  std::vector<InitialCorrection> corrections;  ///< bodies the initialisation moved
  std::vector<std::string> warnings;           ///< corrections beyond the warning thresholds, one line each
  double startRatio = 1.0;  ///< smallest/largest singular value of G at the start (1 without constraints)
};

/// Stage "start": packs the consistent state `init` (computeConsistentState at t0 from
/// the system's initial values), lists the initial corrections and warns of those above
/// 1e-3 of the model size or 1e-3 rad, measures the conditioning of G.
/// @pre the system of `dae` is finalized.
RunStart startRun(const DaeSystem& dae, const ConsistentState& init, double t0);

/// The largest correction per body of the consistent initialisation, with the joint or
/// driver most violated on that body by the given values; bodies not moved are left out.
/// @pre given and corrected have numCoordinates() entries.
std::vector<InitialCorrection> initialCorrections(const System& sys, double t0, const VecX& given,
                                                  const VecX& corrected, double modelSize);

/// How a run ended if not at t_end.
struct RunFailure {
  std::string message;
  double time = 0.0;          ///< SimulationSummary::failureTime
  int signal = 0;             ///< the signal that interrupted the run, or 0
  bool outputFailed = false;  ///< the results could not be written
};

/// The first output, at t0. @return the failure if the callback stopped the run
/// (RunInterrupted, OutputWriteError). @throws InputError if the initial state is not
/// finite (the scene's values overflow); other exceptions of the output pass through.
std::optional<RunFailure> recordInitialOutput(OutputRecorder& recorder, const DaeLayout& layout,
                                              const RunStart& start, double t0);

// --- choose ------------------------------------------------------------------------

/// The integrator a run starts with, its options, and why its BDF order is limited.
struct ChosenIntegrator {
  /// The integrator the run starts with: settings.integrator, or the automatic choice
  /// (chooseIntegrator, simulation/integrator_choice.hpp), never Automatic.
  IntegratorKind kind = IntegratorKind::Ida;
  std::string reason;  ///< why this integrator (one line)
  IntegratorOptions options;
  std::string orderLimit;  ///< why options.maxOrder is below settings.maxOrder ("" if it is not)
  std::string warning;     ///< IntegratorChoice::warning: for summary.json's warnings ("" if none)
  ModelScales scales;          ///< the model's sizes the default class tolerances follow
  ClassTolerances tolerances;  ///< the absolute tolerances by coordinate class (options.atol)
};

/// Stage "choose": the integrator (chooseIntegrator: as given, or chosen from the model
/// with its energy weights of elastic velocities), tolerances by coordinate class
/// (absoluteTolerances), IDA's highest BDF
/// order lowered where damped elastic modes lie outside the stable sectors of BDF4/5
/// (GGL and index 3; stableBdfOrder), min_step (default defaultMinStepSize).
/// @pre settings validated; dae built on sys.
/// `scales`: the model's scales at the consistent initial state (modelScales(sys, v0, t0,
/// t_end)); null: modelScales(sys, settings), at the scene's initial velocities.
ChosenIntegrator chooseIntegratorOptions(const System& sys, const DaeSystem& dae, const SolverSettings& settings,
                                         const ModelScales* scales = nullptr);

/// Default min_step: 1e-12 of the span, at most 1e-12 s.
double defaultMinStepSize(const SolverSettings& settings);

// --- integrate and hand over -------------------------------------------------------

/// The run's state at its start: the chosen integrator from the consistent initial
/// values. @throws as makeIntegrator.
RunState startIntegrator(const RunContext& ctx, const RunStart& start, IntegratorKind kind);

/// The running integrator's steps and error-test failures since its window began.
struct StepWindow {
  long steps = 0, errorTestFailures = 0;
  /// Long enough to judge (kTrapWindow steps): then the window is judged and begins anew.
  bool complete() const;
};
StepWindow stepWindow(const IntegratorStats& now, const IntegratorStats& windowStart);

/// Stage "hand over", the decision: IDA is caught in the order-1 trap (at least 80 % of
/// a complete window of steps failed the error test) and outputs remain after the one
/// at t. Not with IDA's difference-quotient Jacobian (dense, not offered by Radau IIA).
/// @return the reason ("at t = ... from ida to radau5: N error-test failures in the last
/// M steps"), or nullopt: keep the integrator.
std::optional<std::string> shouldHandOver(IntegratorKind kind, const StepWindow& window, bool outputsRemain,
                                          bool finiteDifferenceJacobian, double t);

/// Stage "hand over", the action: Radau IIA takes the rest of the run from a consistent
/// state at the output `last` (just recorded at the integrator's time); the statistics of
/// IDA go to state.finished. @throws as computeConsistentState and makeIntegrator.
void handOverToRadau(const RunContext& ctx, RunState& state, const OutputSample& last, const std::string& reason);

/// Stage "integrate to the next output": the running integrator to output
/// state.nextOutput, which is recorded; then the hand-over decision on its window of
/// steps. @pre state.integrator is set, state.nextOutput <= ctx.outputs.count.
/// The run took more steps than SolverSettings::maxTotalSteps (not a SolverError: no
/// crossing is tried); reported with the time reached, rows kept, exit 1.
struct StepBudgetExceeded : std::runtime_error {
  StepBudgetExceeded(const std::string& message, double time) : std::runtime_error(message), time_(time) {}
  double time() const { return time_; }

 private:
  double time_;
};

/// @throws StepBudgetExceeded when the run's steps exceed settings.maxTotalSteps.
void requireStepBudget(const RunContext& ctx, const RunState& state, double t);

/// @throws SolverError if the integrator fails, StepBudgetExceeded; what the output
/// throws passes through.
void integrateToNextOutput(const RunContext& ctx, RunState& state, OutputRecorder& recorder,
                           ProgressReporter& progress);

/// The loop: every output left, crossing the singular positions where the integrator
/// fails at one (planCrossing). @throws what ends the run early: SolverError,
/// CrossingFailure, the output's exceptions.
void integrateOutputs(const RunContext& ctx, RunState& state, OutputRecorder& recorder, ProgressReporter& progress);

/// The loop of a run that stays on its integrator (the sensitivity runs on IDAS: no
/// hand-over to Radau IIA, no crossing): every output left, each recorded; what ends the run
/// early, diagnosed (diagnoseFailure). @return nullopt if t_end was reached.
std::optional<RunFailure> integrateOnOneIntegrator(const RunContext& ctx, RunState& state, OutputRecorder& recorder,
                                                   ProgressReporter& progress);

// --- diagnose ----------------------------------------------------------------------

/// What the diagnosis of a failure looks at.
struct FailureContext {
  const System& sys;
  const RecordedOutputs& outputs;
  double modelSize;
  double startRatio;  ///< RunStart::startRatio
  /// The running integrator's current time; none during a crossing or after it.
  std::optional<double> integratorTime;
  const std::vector<int>* released = nullptr;  ///< the DAE's released equations (none if null)
};

/// Stage "diagnose": the failure that ended a run early, with its message: the solver's
/// reason with the divergence report or the singularity diagnosis, an interrupt, a write
/// error, a non-finite output, an output that could not be evaluated.
/// @throws the error itself if it is not a failure of the run: an InputError found during
/// the run (not a ModelError), a std::logic_error (an assembly bug), or an exception not
/// derived from std::exception.
RunFailure diagnoseFailure(const std::exception_ptr& error, const FailureContext& ctx);

/// "; the solution diverged: a coordinate reached ... at t = ..., ... times the model
/// size ..." when `largest` exceeds kDivergedSize times the model size; "" otherwise.
std::string divergenceReport(double largest, double modelSize, double t);

/// integrateOutputs, its failure diagnosed. @return nullopt if t_end was reached.
/// @throws as diagnoseFailure.
std::optional<RunFailure> integrateAndDiagnose(const RunContext& ctx, RunState& state, OutputRecorder& recorder,
                                               ProgressReporter& progress);

// --- finish ------------------------------------------------------------------------

/// The summary of a run that ended at its first output: what the start and the outputs
/// recorded, the failure.
SimulationSummary summaryAtStart(const RunStart& start, const RecordedOutputs& outputs, const RunFailure& failure);

/// Stage "finish": the summary of a run that integrated: what the start, the choice, the
/// integrators and the outputs recorded, the failure if any ("reached t_end" if none),
/// and warnings of constraint violations beyond 1e-3 of the model size (positions) or of
/// the velocity scale (velocities: the largest speed output, at least the model size
/// over the span). cpuSeconds is left to the caller.
SimulationSummary finishSummary(const RunStart& start, const RecordedOutputs& outputs, const ChosenIntegrator& choice,
                                const RunState& state, const std::optional<RunFailure>& failure, double span);

/// The failure message of a conservative run whose energy grew from energyStart to
/// energyEnd by more than kMaxEnergyGrowthFraction of maxKinetic (its largest kinetic
/// energy at an output); nullopt if it did not.
std::optional<std::string> energyGrowth(double energyStart, double energyEnd, double maxKinetic);

}  // namespace flexmbd
