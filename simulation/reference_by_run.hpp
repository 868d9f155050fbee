/// @file
/// The reference state of a linearisation reached by a run of the model to a given time.
#pragma once

#include "analysis/linearization.hpp"
#include "simulation/simulation.hpp"

namespace flexmbd {

/// The state a run of the model with `settings` (its tStart, tolerances and integrator)
/// reaches at time `at`: positions, velocities, accelerations and multipliers of the last
/// output sample (`flexmbd modes --at`, Python's Scene.modes(at=...)).
/// @throws InputError if `at` is not after settings.tStart; SolverError if the run fails.
ReferenceState referenceStateByRun(const System& sys, const SolverSettings& settings, double at,
                                   bool progress = false);

}  // namespace flexmbd
