/// @file
/// The scene side of a run with adjoint sensitivities (docs/sensitivities.md, "Adjoint
/// sensitivities"): integral outputs named by a kind and a results column, their
/// integrands on the scene and on each parameter's perturbed scenes, and the gradients'
/// JSON for summary.json.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "sensitivity/adjoint_run.hpp"
#include "results/sensitivity_results.hpp"

namespace flexmbd {

/// An integral output of a scene, "KIND:COLUMN": KIND "integral" (int c dt),
/// "integral_square" (int c^2 dt) or "ks" ("ks:COLUMN:RHO": the Kreisselmeier-Steinhauser
/// aggregate ln(int exp(RHO c) dt / T) / RHO (KreisselmeierSteinhauser1979; PoonMartins2007),
/// a smooth maximum of c over the run, reported
/// with its gradient) of a results column c of positions and velocities: a
/// coordinate "<body>.<coord>", a velocity "<body>.<coord>_dot" or a column of the scene's
/// "outputs" (point, deflection, energy, stress). The integrand is evaluated on the scene
/// of the system it is given (the base or a perturbed one of `scenes`), so a parameter of
/// the output itself (a point's attachment) has its derivative too.
/// @throws InputError naming the output: a kind or column that does not exist, a column of
/// accelerations, reactions or joint outputs (they need the accelerations or multipliers).
IntegralOutput integralOutput(const std::string& spec, const Scene& base, const SensitivityScenes& scenes);

/// The run of `scene` with the gradients of `specs` (integralOutput) with respect to the
/// parameters of `scenes` by the adjoint method (simulateWithAdjoint). The command line and
/// Python both run this. @throws InputError: nothing was integrated.
AdjointSummary runAdjointScene(const Scene& scene, const SensitivityScenes& scenes, const std::vector<std::string>& specs,
                               const OutputCallback& onOutput);

/// summary.json's "sensitivities" of an adjoint run: {"method": "adjoint", "parameters":
/// [{"path", "value", "step"}], "integrals": {SPEC: {"value", "gradient": {PATH: dG/dp}}},
/// "backward_ok", "backward_message", "backward_steps", "recorded_again" (the run outgrew
/// its recording and was integrated once more), "backward_cpu_seconds"}.
nlohmann::json adjointJson(const AdjointSummary& summary, const SensitivityScenes& scenes);

}  // namespace flexmbd
