/// @file
/// A whole run: consistent initialisation, time integration with output at a fixed step
/// and exactly at the end time, statistics and constraint drift.
#pragma once

#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/dae_system.hpp"
#include "integrators/dae_integrator.hpp"
#include "simulation/tolerances.hpp"
#include "analysis/modal_participation.hpp"

namespace flexmbd {

/// How the elastic coordinates start (docs/formulations.md): as given (default: undeformed
/// and at rest relative to the frame, or the scene's values), or with the fast modes at
/// their quasi-static deflection and rate (analysis/quasi_static_start.hpp).
enum class ElasticStart { Given, QuasiStatic };
/// "given", "quasi_static". @throws InputError otherwise.
ElasticStart parseElasticStart(const std::string& name);
std::string toString(ElasticStart s);  ///< The scene's name of s ("given", "quasi_static").

/// What a run does with constraint equations that depend on the others (a redundant
/// joint, docs/formulations.md): release them and integrate with the independent ones
/// (default), or refuse the model as a ModelError naming them.
enum class RedundantConstraints { Resolve, Refuse };
/// "resolve", "refuse". @throws InputError otherwise.
RedundantConstraints parseRedundantConstraints(const std::string& name);
std::string toString(RedundantConstraints r);  ///< The scene's name of r ("resolve", "refuse").

/// How a run integrates: the solver object of a scene (docs/scene-format.md, "Solver";
/// the same names in snake_case), the time span and output step, tolerances, the
/// integrator and its limits. The defaults are those of a scene that omits the key.
struct SolverSettings {
  /// The DAE formulation (index-2 GGL by default; docs/formulations.md).
  Formulation formulation = Formulation::Ggl;
  /// Automatic: chosen from the model at the start (chooseIntegrator,
  /// simulation/integrator_choice.hpp); the choice and its reason are in the summary.
  IntegratorKind integrator = IntegratorKind::Automatic;
  ElasticStart elasticStart = ElasticStart::Given;  ///< how the elastic coordinates start
  /// QuasiStatic: the modes above this circular frequency (rad/s) start quasi-statically.
  /// Unset: the Nyquist frequency of the output step, pi / outputStep.
  std::optional<double> quasiStaticAbove;
  double rtol = 1e-8;  ///< relative tolerance of the integrator
  /// Absolute tolerances by coordinate class (simulation/tolerances.hpp): frame
  /// positions (m); unset classes default relative to atol and the model's sizes
  /// (classTolerances): angles atol / L, velocities atol / (1 s), elastic coordinates
  /// atol; velocities of angles and elastic coordinates: their class's tolerance
  /// times atolVelocity / atol. overrideTolerances changes rtol/atol keeping the ratios.
  double atol = 1e-10;
  std::optional<double> atolVelocity;  ///< velocities of frame positions (m/s); unset: atol / (1 s)
  std::optional<double> atolAngle;     ///< angles (rad); unset: atol / L
  std::optional<double> atolElastic;   ///< elastic coordinates; unset: atol
  double tStart = 0.0;      ///< start time (s)
  double tEnd = 1.0;        ///< end time (s); the last output is exactly there
  double outputStep = 0.01; ///< interval of the outputs (s)
  double maxStepSize = 0.0;       ///< 0: no limit
  /// Smallest step IDA may take before it reports failure (a lock-up or a singularity
  /// shrinks the step without bound). Unset: 1e-12 (t_end - t_start), at most 1e-12 s.
  std::optional<double> minStepSize;
  long maxSteps = 1000000;        ///< per output interval
  long maxTotalSteps = 10000000;  ///< of the whole run (1e7: 2 to 15 CPU-minutes of small models)
  /// Highest BDF order (1..5). Orders 1 and 2 are A-stable: undamped high-frequency
  /// modes cannot force small steps for stability (docs/formulations.md).
  int maxOrder = 5;
  /// First step size tried (0: IDA's estimate, h0 ~ 1 / |y'| in the error weights).
  double initialStepSize = 0.0;
  /// Dense LU or sparse KLU for the Newton systems; Automatic: from the model's size
  /// (kDenseSizeLimit).
  LinearSolverKind linearSolver = LinearSolverKind::Automatic;
  /// IDA's own difference quotients (dense only) instead of the analytic Jacobian.
  bool finiteDifferenceJacobian = false;
  bool progress = true;           ///< progress on stderr for long runs (if a terminal)
  /// Where IDA or Radau stop at a singular position of the mechanism (the constraint
  /// Jacobian loses rank: change points, dead centres), cross it with the augmented
  /// Lagrangian integrator (ALI3-P) and restart after it. Off: such a run stops there.
  bool crossSingular = true;
  /// What to do with dependent constraint equations (a redundant joint).
  RedundantConstraints redundantConstraints = RedundantConstraints::Resolve;
  /// @throws InputError naming the solver key that is out of range.
  void validate() const;
};

/// True if t_end - t_start is a span the integrators (IDA, Radau IIA, CVODE) can resolve:
/// kTimeSpanRule. One rule for every scene format with a time span.
bool resolvableTimeSpan(double tStart, double tEnd);
/// The rule of resolvableTimeSpan, as the messages state it.
constexpr const char* kTimeSpanRule =
    "t_end - t_start >= 1e-100 and >= 1e-9 max(|t_start|, |t_end|) (a span the integrator can resolve)";

/// Absolute tolerance of every unknown of the DAE for these settings: per coordinate
/// class (frame positions, angles, elastic coordinates) and their velocities, the
/// defaults from the model's scales at its consistent initial state (classTolerances);
/// multipliers out of the error and convergence tests.
VecX absoluteTolerances(const DaeSystem& dae, const SolverSettings& settings);

/// One output instant: positions, velocities, accelerations, multipliers.
struct OutputSample {
  double t = 0.0;  ///< time (s)
  ///@{
  /// Coordinates q (nq, System::coordinateOffset), velocities v and accelerations a (nv,
  /// System::velocityOffset), constraint multipliers lambda (m, System::constraintOffset).
  VecX q, v, a, lambda;
  ///@}
};

/// The largest change the consistent initialisation made to one body's given initial
/// coordinates (positions and elastic coordinates in length units, angles in rad).
struct InitialCorrection {
  std::string body;        ///< the body's name
  double position = 0.0;   ///< max over its position and elastic coordinates of |q - q_given|
  double angle = 0.0;      ///< max over its angle coordinates of |q - q_given|
  std::string coordinate;  ///< the coordinate changed most (relative to its threshold)
  ///@{
  double given = 0.0, corrected = 0.0;  ///< that coordinate before and after
  ///@}
  std::string constraint;  ///< the joint or driver most violated by the given values on this body
  double residual = 0.0;   ///< its largest |g| at the given values
};

/// A singular position crossed by the augmented Lagrangian integrator.
struct SingularCrossing {
  double tFailure = 0.0;  ///< where the DAE integrator stopped
  double tStart = 0.0;    ///< the output the crossing started from
  double tEnd = 0.0;      ///< where the DAE integrator restarted (conditioning regained)
  long steps = 0;         ///< ALI3-P steps of the crossing
};

/// What a run did (simulate()): whether it reached the end, where and why it stopped if
/// not, the integrator's statistics, constraint drift, energy, the tolerances used and
/// the warnings about the results. The command line writes it as summary.json.
struct SimulationSummary {
  bool ok = true;        ///< the run reached tEnd
  std::string message;   ///< "" or why the run stopped (time, step size, the solver's reason)
  double tReached = 0.0;           ///< time of the last output passed to onOutput
  double failureTime = 0.0;        ///< where IDA stopped, if !ok
  IntegratorStats stats;  ///< steps, function and Jacobian evaluations, failures
  double cpuSeconds = 0.0;  ///< CPU time of the run (s)
  double maxPositionViolation = 0.0;  ///< max over outputs of max |g(q, t)|
  double maxVelocityViolation = 0.0;  ///< max over outputs of max |G v + g_t|
  ///@{
  /// Total energy at the start and at the end, only if the model is conservative.
  std::optional<double> energyStart, energyEnd;
  ///@}
  bool usedKlu = false;  ///< the sparse linear solver (KLU) was used
  int maxOrder = 5;              ///< highest BDF order IDA was allowed (settings, stability limit)
  std::string orderLimit;        ///< why it is below the settings' max_order ("" if it is not)
  int initialPositionIterations = 0;  ///< Newton iterations of the consistent initial positions
  double modelSize = 1.0;        ///< System::characteristicLength(): the scale of the warnings
  ModelScales scales;            ///< the model's sizes the default class tolerances follow
  ClassTolerances tolerances;    ///< the tolerances the run used, by coordinate class
  std::vector<InitialCorrection> initialCorrections;  ///< bodies the initialisation moved
  /// Results that may not mean what they seem: large initial corrections, constraint
  /// violations beyond a fraction of the model size (one line each).
  std::vector<std::string> warnings;
  int interruptedBySignal = 0;   ///< the signal that stopped the run (RunInterrupted), or 0
  bool outputFailed = false;     ///< the run stopped because its results could not be written
  /// Singular positions crossed (crossSingular); their steps are counted in `stats` too.
  std::vector<SingularCrossing> singularCrossings;
  /// "at t = ... from ida to radau5: N error-test failures in the last M steps" when IDA
  /// rejected nearly every step and Radau IIA took the rest of the run; "" otherwise.
  std::string integratorSwitch;
  /// The integrator the run started with (settings.integrator, or the automatic choice)
  /// and why (one line: "given in the settings", or what chooseIntegrator measured).
  IntegratorKind integrator = IntegratorKind::Ida;
  std::string integratorReason;  ///< why that integrator (see integrator)
  /// The quasi-static elastic start made (one line), or "" when the elastic state was as given.
  std::string elasticStart;
  /// Per flexible body (at most 400 elastic coordinates): the largest amplitude and energy
  /// of each mode over the outputs and the modes that carry the motion.
  std::vector<BodyParticipation> modalParticipation;
  /// The constraint equations released as dependent on the others (redundant constraints
  /// resolved), each named as "joint 'F' (revolute, equation 4)"; their reactions, and
  /// those of the equations they depend on, are the minimum-norm ones.
  std::vector<std::string> redundantConstraints;
};

/// A value of the results (state, energy, reaction, output) that is inf or NaN: the run
/// stops before the row that holds it (never `ok` with non-finite results).
struct NonFiniteResult : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// The results cannot be written (disk full, file size limit): the run stops, the rows
/// written before stay complete.
struct OutputWriteError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Thrown by an output callback after it wrote its row when the run must stop (SIGINT,
/// SIGTERM): the summary says "interrupted" with the time reached.
struct RunInterrupted : std::runtime_error {
  /// @param message the summary's message. @param signal the signal that stopped the run.
  RunInterrupted(const std::string& message, int signal) : std::runtime_error(message), signal(signal) {}
  int signal;  ///< SIGINT, SIGTERM, ...
};

/// Called at t0 and at every output time (also the last one reached before a failure).
using OutputCallback = std::function<void(const OutputSample&)>;

/// Runs the system from its initial values. Input and model errors (including failed
/// assembly) throw InputError/ModelError before any output; a solver failure mid-run
/// returns ok = false with the time, step size and IDA's reason in `message`, after
/// the samples up to the failure were passed to `onOutput`.
SimulationSummary simulate(const System& sys, const SolverSettings& settings,
                           const OutputCallback& onOutput);

/// simulate(), with every failure after the input was accepted returned as a failed
/// summary instead of thrown: a SolverError (at initialisation too: its time and step
/// size), or any other std::exception from the run or from `onOutput` (results that
/// cannot be written, a non-finite value: t_reached is the time of the last output
/// `onOutput` completed, NaN if none). InputError and ModelError still throw (the model
/// could not be set up, nothing was integrated). Used by the command line and the
/// Python module, so both report failures alike.
SimulationSummary simulateKeepingFailures(const System& sys, const SolverSettings& settings,
                                          const OutputCallback& onOutput);

}  // namespace flexmbd
