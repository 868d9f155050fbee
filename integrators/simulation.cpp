#include "integrators/simulation.hpp"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <sstream>

#include "core/errors.hpp"
#include "core/system_evaluation.hpp"
#include "integrators/initial_conditions.hpp"

namespace flexmbd {
namespace {

void requireSetting(bool ok, const std::string& key, const std::string& expected, double got) {
  if (!ok) {
    std::ostringstream os;
    os << "solver." << key << ": expected " << expected << ", got " << got;
    throw InputError(os.str());
  }
}

/// Progress on stderr for runs longer than a few seconds, when stderr is a terminal.
class ProgressReporter {
 public:
  ProgressReporter(bool enabled, double t0, double tEnd)
      : enabled_(enabled && isatty(STDERR_FILENO)), t0_(t0), tEnd_(tEnd),
        start_(std::chrono::steady_clock::now()), last_(start_) {}
  void update(double t, long steps) {
    if (!enabled_) return;
    const auto now = std::chrono::steady_clock::now();
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    if (elapsed < 2.0 || std::chrono::duration<double>(now - last_).count() < 0.5) return;
    last_ = now;
    shown_ = true;
    std::fprintf(stderr, "\r  t = %.6g / %.6g (%5.1f%%), %ld steps, %.0f steps/s   ", t, tEnd_,
                 100.0 * (t - t0_) / (tEnd_ - t0_), steps, steps / elapsed);
    std::fflush(stderr);
  }
  ~ProgressReporter() {
    if (shown_) std::fprintf(stderr, "\n");
  }

 private:
  bool enabled_;
  double t0_, tEnd_;
  std::chrono::steady_clock::time_point start_, last_;
  bool shown_ = false;
};

}  // namespace

void SolverSettings::validate() const {
  requireSetting(rtol > 0.0 && std::isfinite(rtol), "rtol", "a positive number", rtol);
  requireSetting(atol > 0.0 && std::isfinite(atol), "atol", "a positive number", atol);
  if (atolVelocity) {
    requireSetting(*atolVelocity > 0.0 && std::isfinite(*atolVelocity), "atol_velocity",
                   "a positive number", *atolVelocity);
  }
  requireSetting(std::isfinite(tStart), "t_start", "a finite number", tStart);
  requireSetting(std::isfinite(tEnd) && tEnd > tStart, "t_end", "a number greater than t_start", tEnd);
  requireSetting(outputStep > 0.0 && std::isfinite(outputStep), "output_step", "a positive number",
                 outputStep);
  requireSetting(maxStepSize >= 0.0 && std::isfinite(maxStepSize), "max_step",
                 "a non-negative number (0: no limit)", maxStepSize);
  if (minStepSize) {
    requireSetting(*minStepSize >= 0.0 && std::isfinite(*minStepSize), "min_step",
                   "a non-negative number", *minStepSize);
  }
  requireSetting(maxOrder >= 1 && maxOrder <= 5, "max_order", "an integer from 1 to 5",
                 static_cast<double>(maxOrder));
  requireSetting(maxSteps > 0, "max_steps", "a positive integer", static_cast<double>(maxSteps));
}

SimulationSummary simulate(const System& sys, const SolverSettings& settings,
                           const OutputCallback& onOutput) {
  settings.validate();
  if (!sys.isFinalized()) throw InputError("simulate: the system must be finalized first");
  const std::clock_t cpuStart = std::clock();
  const double t0 = settings.tStart, tEnd = settings.tEnd;

  const ConsistentState init =
      computeConsistentState(sys, t0, sys.initialCoordinates(), sys.initialVelocities());
  const DaeSystem dae(sys, settings.formulation);
  const DaeLayout& L = dae.layout();
  VecX y0, yp0;
  dae.packState(init.q, init.v, init.a, init.lambda, y0, yp0);

  SimulationSummary summary;
  summary.initialPositionIterations = init.positionIterations;
  const bool conservative = isConservative(sys);
  auto emit = [&](double t, const VecX& y, const VecX& yp) {
    OutputSample s;
    s.t = t;
    s.q = y.segment(L.q, L.nq);
    s.v = y.segment(L.v, L.nq);
    // Accelerations and multipliers recomputed from the state (q, v): as accurate as the
    // state itself, unlike the interpolated y' (docs/formulations.md).
    (void)yp;
    computeAccelerations(sys, t, s.q, s.v, s.a, s.lambda);
    if (L.m > 0) {
      VecX g;
      evaluateConstraints(sys, s.q, t, &g, nullptr);
      summary.maxPositionViolation = std::max(summary.maxPositionViolation, g.lpNorm<Eigen::Infinity>());
      summary.maxVelocityViolation = std::max(
          summary.maxVelocityViolation, velocityConstraintResidual(sys, s.q, s.v, t).lpNorm<Eigen::Infinity>());
    }
    if (conservative) {
      const double E = kineticEnergy(sys, s.q, s.v) + potentialEnergy(sys, s.q);
      if (!summary.energyStart) summary.energyStart = E;
      summary.energyEnd = E;
    }
    summary.tReached = t;
    if (onOutput) onOutput(s);
  };
  emit(t0, y0, yp0);

  IntegratorOptions o;
  o.rtol = settings.rtol;
  o.atolPosition = settings.atol;
  o.atolVelocity = settings.atolVelocity.value_or(settings.atol);
  o.maxSteps = settings.maxSteps;
  o.maxStepSize = settings.maxStepSize;
  o.maxOrder = settings.maxOrder;
  o.minStepSize = settings.minStepSize.value_or(1e-12 * (tEnd - t0));
  o.linearSolver = settings.linearSolver;
  o.finiteDifferenceJacobian = settings.finiteDifferenceJacobian;
  IdaSolver ida(dae, t0, y0, yp0, o);
  summary.usedKlu = ida.usesKlu();

  ProgressReporter progress(settings.progress, t0, tEnd);
  // Output times t0 + k dt; the last one is exactly t_end (IDASetStopTime).
  const long nOut = std::max(1L, static_cast<long>(std::ceil((tEnd - t0) / settings.outputStep - 1e-9)));
  try {
    for (long k = 1; k <= nOut; ++k) {
      const double tout = (k == nOut) ? tEnd : std::min(tEnd, t0 + k * settings.outputStep);
      const double t = ida.advance(tout, tEnd);
      emit(t, ida.y(), ida.yp());
      progress.update(t, ida.stats().steps);
    }
  } catch (const SolverError& e) {
    summary.ok = false;
    summary.message = e.what();
    summary.failureTime = e.time();
  } catch (const std::exception& e) {
    // post-processing of an output state failed (e.g. a singular mass matrix after the
    // solution blew up): a failure of the run, reported like a solver failure
    summary.ok = false;
    summary.failureTime = ida.stats().currentTime;
    summary.message = "evaluating the outputs at t = " + std::to_string(summary.failureTime) +
                      " failed: " + e.what();
  }
  summary.stats = ida.stats();
  summary.cpuSeconds = static_cast<double>(std::clock() - cpuStart) / CLOCKS_PER_SEC;
  if (summary.ok) summary.message = "reached t_end";
  return summary;
}

}  // namespace flexmbd
