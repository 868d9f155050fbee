/// @file
/// Stopping a run from outside (SIGINT/SIGTERM in the command line, Ctrl-C in Python)
/// without waiting for the next output row: the integrators' inner
/// loops (every residual of the model's DAE, every ALI3-P, CVODE, time-stepping and
/// kinematics step) call pollStop(), which runs the check the thread's caller installed.
#pragma once

namespace flexmbd {

/// A check that throws (RunInterrupted, simulation/simulation.hpp) to stop the run; `t` is
/// the time being computed. It must be cheap: it runs at every residual evaluation.
using StopPoll = void (*)(double t);

namespace detail {
inline thread_local StopPoll tStopPoll = nullptr;  // one per thread: runs go on in threads (Python)
}  // namespace detail

/// Runs the thread's stop check, if any. Allocates nothing.
inline void pollStop(double t) {
  if (const StopPoll p = detail::tStopPoll) p(t);
}

/// Installs `poll` for this thread for the life of the object (restoring the one before).
class StopPollScope {
 public:
  explicit StopPollScope(StopPoll poll) : previous_(detail::tStopPoll) { detail::tStopPoll = poll; }
  ~StopPollScope() { detail::tStopPoll = previous_; }
  StopPollScope(const StopPollScope&) = delete;
  StopPollScope& operator=(const StopPollScope&) = delete;

 private:
  StopPoll previous_;
};

}  // namespace flexmbd
