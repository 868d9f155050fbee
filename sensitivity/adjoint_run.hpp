/// @file
/// A run with adjoint sensitivities (docs/sensitivities.md, "Adjoint sensitivities"): the
/// gradients of integral outputs G = int_{t0}^{T} g(t, q, v) dt (CaoLiPetzoldSerban2003) with respect to every
/// parameter from one forward run (IDAS, recorded at checkpoints) and one backward
/// integration per output, whatever the number of parameters.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "sensitivity/sensitivity_run.hpp"

namespace flexmbd {

/// One integral output: G = int_{t0}^{T} g(t, q, v) dt (CaoLiPetzoldSerban2003). The integrand is evaluated on a
/// system: the run's, or a parameter's perturbed one (g may depend on a parameter, a
/// point's attachment for example: its derivative g_p enters the gradient).
struct IntegralOutput {
  std::string name;
  std::function<double(const System& sys, double t, const VecX& q, const VecX& v)> integrand;
  /// A function of the integral reported instead of it (empty: G itself): from G, dG/dp and
  /// the run's span T - t0, the value and its gradient (a KS aggregate: ln(G / T) / rho).
  std::function<void(double span, double& value, VecX& gradient)> report;
  /// The output is the integrand's value at T, c(y(T)), not its integral (a terminal output).
  bool terminal = false;
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

/// Consistent terminal values of the adjoint for the GGL form (docs/sensitivities.md;
/// CaoLiPetzoldSerban2003) with
/// its differential part lambda_D = [lambda_q; lambda_v] given (empty: 0, an integral
/// output's E^T lambda(T) = 0): lambda_g, lambda_gv and lambda_q', lambda_v' from the
/// adjoint's differential rows and the derivatives of its algebraic rows (the hidden
/// constraints G D T^T lambda_q' + (d/dt G D T^T) lambda_q = 0, G lambda_v' + G' lambda_v = 0,
/// the rates of F_y and E along the motion by central differences; a released equation's
/// rows: its adjoint multiplier from its row).
/// @param dae the run's DAE (GGL layout)
/// @param t the time T
/// @param y, yp the forward solution at T
/// @param gy the integrand's gradient at (T, y) (size n)
/// @param lambdaD lambda_q, lambda_v at T (size nq + nv) or empty for zero
/// @returns lambda(T) and lambda'(T) as the columns of an n x 2 matrix
MatX adjointTerminalValues(const DaeSystem& dae, double t, const VecX& y, const VecX& yp, const VecX& gy,
                           const VecX& lambdaD);

/// The adjoint of a terminal output c(y(T)) at T: c_y = E^T lambda + F_A^T nu on the
/// consistent states (lambda_D meeting the adjoint's algebraic rows), so that
/// dc/dp = c_p - nu^T F_p(T) + lambda(t0)^T E s(t0) - int lambda^T F_p dt with lambda the
/// homogeneous adjoint from these terminal values (CaoLiPetzoldSerban2003 for the
/// index-2 case; docs/sensitivities.md).
struct TerminalAdjoint {
  VecX lambda, rate;  ///< lambda(T), lambda'(T)
  VecX nu;            ///< size n, zero on q and v: the constraint rows' weights
};
/// @param dae the run's DAE (GGL layout)
/// @param t the time T
/// @param y, yp the forward solution at T
/// @param cy the output's gradient in y at T (zero on the multipliers)
TerminalAdjoint terminalAdjoint(const DaeSystem& dae, double t, const VecX& y, const VecX& yp, const VecX& cy);

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
