#include "simulation/run_state.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace flexmbd {

std::string formatTime(double t) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", t);
  return buf;
}

std::string formatValue(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", x);
  return buf;
}

void addStats(IntegratorStats& total, const IntegratorStats& more) {
  total.steps += more.steps;
  total.residualEvals += more.residualEvals;
  total.jacobianEvals += more.jacobianEvals;
  total.nonlinearIterations += more.nonlinearIterations;
  total.nonlinearConvFailures += more.nonlinearConvFailures;
  total.errorTestFailures += more.errorTestFailures;
  total.linearSetups += more.linearSetups;
  total.lastStepSize = more.lastStepSize;
  total.currentTime = more.currentTime;
}

/// An output step that divides the span to within this fraction of a step gives no extra
/// output for the round-off of the division.
constexpr double kOutputCountRoundOff = 1e-9;

OutputSchedule::OutputSchedule(double t0, double tEnd, double step)
    : t0(t0), tEnd(tEnd), step(step),
      count(std::max(1L, static_cast<long>(std::ceil((tEnd - t0) / step - kOutputCountRoundOff)))) {}

double OutputSchedule::time(long k) const { return k == count ? tEnd : std::min(tEnd, t0 + k * step); }

/// The progress line appears after kProgressDelay seconds of a run, then at most every
/// kProgressInterval seconds: short runs stay silent, long ones do not flood the terminal.
constexpr double kProgressDelay = 2.0, kProgressInterval = 0.5;

ProgressReporter::ProgressReporter(bool enabled, double t0, double tEnd, std::string integrator, bool backward)
    : enabled_(enabled && isatty(STDERR_FILENO)), t0_(t0), tEnd_(tEnd), integrator_(std::move(integrator)),
      backward_(backward), start_(std::chrono::steady_clock::now()), last_(start_) {}

void ProgressReporter::update(double t, long steps) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  if (elapsed < kProgressDelay || std::chrono::duration<double>(now - last_).count() < kProgressInterval) return;
  last_ = now;
  shown_ = true;
  const double done = backward_ ? (tEnd_ - t) / (tEnd_ - t0_) : (t - t0_) / (tEnd_ - t0_);
  std::fprintf(stderr, "\r  %s: t = %.6g / %.6g (%5.1f%%), %ld steps, %.0f steps/s   ", integrator_.c_str(), t,
               backward_ ? t0_ : tEnd_, 100.0 * done, steps, steps / elapsed);
  std::fflush(stderr);
}

ProgressReporter::~ProgressReporter() {
  if (shown_) std::fprintf(stderr, "\n");
}

long RunState::totalSteps() const { return finished.steps + (integrator ? integrator->stats().steps : 0); }

IntegratorStats RunState::totalStats() const {
  IntegratorStats total = finished;
  if (integrator) addStats(total, integrator->stats());
  return total;
}

void RunState::restart(const DaeSystem& dae, double t, const VecX& y, const VecX& yp,
                       const IntegratorOptions& options) {
  integrator = makeIntegrator(kind, dae, t, y, yp, options);
  windowStart = IntegratorStats();
}

void packConsistentState(const DaeSystem& dae, const ConsistentState& state, VecX& y, VecX& yp) {
  dae.packState(state.q, state.v, state.a, state.lambda, y, yp);
}

}  // namespace flexmbd
