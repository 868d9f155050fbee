#include "simulation/reference_by_run.hpp"

#include <string>

#include "core/errors.hpp"
#include "core/number_text.hpp"

namespace flexmbd {

ReferenceState referenceStateByRun(const System& sys, const SolverSettings& settings, double at, bool progress) {
  if (!(at > settings.tStart)) {
    throw InputError("modes: the time to linearise at must be after t_start (" + fmt(settings.tStart, 6) +
                     ") of the scene, got " + fmt(at, 6));
  }
  SolverSettings s = settings;
  s.tEnd = at;
  s.progress = progress;
  OutputSample last;
  const SimulationSummary summary = simulate(sys, s, [&](const OutputSample& sample) { last = sample; });
  if (!summary.ok) {
    throw SolverError("the simulation to t = " + fmt(at, 6) + " failed: " + summary.message, summary.tReached, 0.0);
  }
  return ReferenceState{last.t, last.q, last.v, last.a, last.lambda};
}

}  // namespace flexmbd
