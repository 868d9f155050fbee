/// @file
/// What a run of simulate() holds while it advances, shared by its stages
/// (simulation/run_stages.hpp, simulation/singular_crossing.hpp): the output times, the
/// integrator running with the statistics of those it replaced, the progress line, and
/// the text formats of its messages.
#pragma once

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "core/dae_system.hpp"
#include "integrators/dae_integrator.hpp"
#include "integrators/initial_conditions.hpp"
#include "simulation/simulation.hpp"

namespace flexmbd {

/// A time in a message: 10 significant digits.
std::string formatTime(double t);
/// A value in a warning: 3 significant digits.
std::string formatValue(double x);

/// Counts of `more` added to `total`; the last step size and time are those of `more`.
void addStats(IntegratorStats& total, const IntegratorStats& more);

/// The output times t0 + k dt, k = 1 .. count; the last one is exactly t_end (the
/// integrators' stop time).
struct OutputSchedule {
  /// @pre tEnd > t0, step > 0 (SolverSettings::validate).
  OutputSchedule(double t0, double tEnd, double step);
  /// Output k (1 .. count).
  double time(long k) const;
  double t0, tEnd, step;
  long count;
};

/// Progress on stderr for runs longer than a few seconds, when stderr is a terminal.
class ProgressReporter {
 public:
  /// `integrator`: the integrator chosen, named in the progress line. `backward`: t runs
  /// from tEnd to t0 (an adjoint's backward integration).
  ProgressReporter(bool enabled, double t0, double tEnd, std::string integrator, bool backward = false);
  ProgressReporter(const ProgressReporter&) = delete;
  ProgressReporter& operator=(const ProgressReporter&) = delete;
  /// Shows t and the steps taken, at most twice a second, after the first 2 s.
  void update(double t, long steps);
  /// Whether it shows anything (asked for, and stderr a terminal).
  bool enabled() const { return enabled_; }
  ~ProgressReporter();

 private:
  bool enabled_;
  double t0_, tEnd_;
  std::string integrator_;
  bool backward_;
  std::chrono::steady_clock::time_point start_, last_;
  bool shown_ = false;
};

/// What a run holds fixed once its integrator options are chosen.
struct RunContext {
  const System& sys;
  const DaeSystem& dae;
  const SolverSettings& settings;
  const IntegratorOptions& options;
  OutputSchedule outputs;
  double modelSize;   ///< System::characteristicLength()
  double startRatio;  ///< smallest/largest singular value of G at the start (1 without constraints)
  /// Where the DAE integrator stops at a singular position, the run may cross it with
  /// ALI3-P (mayCrossSingularPositions).
  bool mayCross;
};

/// What changes as a run advances: the integrator running (IDA may hand over to Radau IIA,
/// a crossing replaces it for a while), the next output, what the hand-over and the
/// crossings recorded.
struct RunState {
  IntegratorKind kind = IntegratorKind::Ida;  ///< the integrator running
  std::unique_ptr<DaeIntegrator> integrator;  ///< null during a crossing, and after one that reached t_end
  IntegratorStats finished;     ///< statistics of the integrators replaced, and of the crossings
  IntegratorStats windowStart;  ///< the integrator's statistics where the current window of steps began
  long nextOutput = 1;          ///< the next output (1 .. OutputSchedule::count)
  double regularStep = 0.0;     ///< the DAE integrator's last step size at an output: a crossing's step scale
  int restarts = 0;             ///< consecutive failures just after a crossing
  std::vector<SingularCrossing> crossings;
  std::string integratorSwitch;  ///< SimulationSummary::integratorSwitch
  bool usedKlu = false;          ///< the first integrator solves with KLU

  /// Steps of every integrator of the run so far.
  long totalSteps() const;
  /// Statistics of every integrator of the run so far.
  IntegratorStats totalStats() const;
  /// A new integrator of the running kind from the consistent (y, y') at t; its window of
  /// steps begins there. @throws as makeIntegrator.
  void restart(const DaeSystem& dae, double t, const VecX& y, const VecX& yp, const IntegratorOptions& options);
};

/// y and y' of the DAE from a consistent state (mu = 0).
void packConsistentState(const DaeSystem& dae, const ConsistentState& state, VecX& y, VecX& yp);

}  // namespace flexmbd
