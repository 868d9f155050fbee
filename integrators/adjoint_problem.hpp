/// @file
/// What IDAS needs besides the DAE for adjoint sensitivities (docs/sensitivities.md,
/// "Adjoint sensitivities"; CaoLiPetzoldSerban2003): integral outputs G_k = int_{t0}^{T} g_k(t, y) dt, the
/// gradient of each integrand and the integrand of each gradient dG_k/dp.
#pragma once

#include "core/types.hpp"

namespace flexmbd {

/// Integral outputs of a run and the terms of their adjoint problems. g_k depends on the
/// positions and velocities of y (not on the multipliers: the adjoint of an index-2
/// system with an integrand in its algebraic variables needs other terminal values).
class IntegralOutputs {
 public:
  virtual ~IntegralOutputs() = default;
  /// Number of outputs.
  virtual int count() const = 0;
  /// Number of parameters.
  virtual int parameterCount() const = 0;
  /// g_k(t, y) of every output into g (count).
  virtual void integrands(double t, const double* y, double* g) = 0;
  /// dg_k/dy at (t, y) into gy (size n of the DAE; zero on the multipliers).
  virtual void integrandGradient(int k, double t, const double* y, double* gy) = 0;
  /// dg_k/dp_i - lambda^T dF/dp_i at (t, y, y') for every parameter i into out
  /// (parameterCount): the integrand of the gradient (IdasGuide, "Adjoint sensitivity
  /// analysis"), lambda the adjoint of output k (size n).
  virtual void gradientIntegrand(int k, double t, const double* y, const double* yp, const double* lambda,
                                 double* out) = 0;
};

/// The backward problems of one run, one per output: terminal values at T (consistent:
/// lambda = [0; 0; lambda_g; lambda_gv] of the GGL form, adjointTerminalValues) and the
/// tolerances of the adjoints and of the gradients' quadratures.
struct AdjointProblem {
  IntegralOutputs* outputs = nullptr;  ///< outlives the integration
  MatX lambdaT, lambdaTp;              ///< n x count: lambda(T), lambda'(T)
  MatX atolB;                          ///< n x count: absolute tolerances of the adjoints
  MatX atolQ;                          ///< parameterCount x count: of the quadratures
  /// The positions: the first entries of y, on which E = dF/dy' depends (DaeLayout::nq).
  int positions = 0;
};

/// The result of the backward integration to t0.
struct AdjointSolution {
  MatX lambda0;    ///< n x count: lambda(t0)
  MatX lambdaRate0;  ///< n x count: lambda'(t0)
  MatX integral;   ///< parameterCount x count: int_{t0}^{T} (g_p - lambda^T F_p) dt
  long steps = 0;  ///< backward steps, summed over the outputs
};

}  // namespace flexmbd
