/// @file
/// A run with adjoint sensitivities (docs/sensitivities.md, "Adjoint sensitivities"): the
/// gradients of integral outputs G = int_{t0}^{T} g(t, q, v) dt with respect to every
/// parameter from one forward run (IDAS, recorded at checkpoints) and one backward
/// integration per output, whatever the number of parameters.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "integrators/sensitivity_run.hpp"

namespace flexmbd {

/// One integral output: G = int_{t0}^{T} g(t, q, v) dt. The integrand is evaluated on a
/// system: the run's, or a parameter's perturbed one (g may depend on a parameter, a
/// point's attachment for example: its derivative g_p enters the gradient).
struct IntegralOutput {
  std::string name;
  std::function<double(const System& sys, double t, const VecX& q, const VecX& v)> integrand;
  /// A function of the integral reported instead of it (empty: G itself): from G, dG/dp and
  /// the run's span T - t0, the value and its gradient (a KS aggregate: ln(G / T) / rho).
  std::function<void(double span, double& value, VecX& gradient)> report;
};

/// The value and gradient of one integral output.
struct IntegralGradient {
  std::string name;
  double value = 0.0;  ///< G: the forward quadrature of g
  VecX gradient;       ///< dG/dp per parameter
};

/// A run with adjoint sensitivities: the forward run's summary and, when it reached t_end,
/// the gradients.
struct AdjointSummary {
  SimulationSummary run;  ///< its cpuSeconds: the whole, the backward integration included
  std::vector<IntegralGradient> outputs;  ///< empty if the run or the backward integration failed
  bool backwardOk = false;
  std::string backwardMessage;  ///< why the backward integration failed ("" if it did not)
  long backwardSteps = 0;       ///< backward steps, summed over the outputs
  bool recordedAgain = false;   ///< the run outgrew its recording and was recorded once more
  double backwardCpuSeconds = 0.0;
};

/// Consistent terminal values of the adjoint of an integral output at T for the GGL form
/// (docs/sensitivities.md): lambda_q = lambda_v = 0 (E^T lambda(T) = 0), and lambda_g,
/// lambda_gv with lambda_q', lambda_v' from the adjoint's differential rows and the
/// derivatives of its algebraic rows (the hidden constraints G D T^T lambda_q' = 0,
/// G lambda_v' = 0; a released equation's rows: its adjoint multiplier 0).
/// @param dae the run's DAE (GGL layout)
/// @param t the time T
/// @param y, yp the forward solution at T
/// @param gy the integrand's gradient at (T, y) (size n)
/// @returns lambda(T) and lambda'(T) as the columns of an n x 2 matrix
MatX adjointTerminalValues(const DaeSystem& dae, double t, const VecX& y, const VecX& yp, const VecX& gy);

/// Steps between IDAS's checkpoints of the forward run (the backward integration
/// recomputes and stores the steps of one interval at a time: memory ~ this many states).
inline constexpr long kStepsPerCheckpoint = 200;

/// The run of `sys` (IDA, GGL form) with the gradients of `outputs` with respect to
/// `parameters` by the adjoint method. `onOutput` gets every output as in a plain run. The
/// run records itself for the backward pass in a store of `recordingStoreSteps` steps (0:
/// sized by a pilot over the first 5 % of the run); a run that outgrows it is recorded once
/// more from t0. A failure of the forward run or of the backward integration is reported
/// in the summary (rows kept), not thrown.
/// @throws InputError: no parameter or output, a formulation other than GGL, settings
/// sensitivityRunSettings refuses, a parameter that changes the structure.
AdjointSummary simulateWithAdjoint(const System& sys, const std::vector<SensitivityParameter>& parameters,
                                   const std::vector<IntegralOutput>& outputs, const SolverSettings& settings,
                                   const OutputCallback& onOutput, long recordingStoreSteps = 0);

}  // namespace flexmbd
