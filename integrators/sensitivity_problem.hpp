/// @file
/// What IDAS needs besides the DAE for forward sensitivities (docs/sensitivities.md): the
/// derivative dF/dp of the residual with respect to each parameter, the consistent initial
/// sensitivities and how the sensitivities enter the error test.
#pragma once

#include <array>
#include <cmath>

#include "core/sparse_pattern.hpp"
#include "core/types.hpp"

namespace flexmbd {

/// Relative step of the engine's central differences: eps^(1/3) balances their truncation
/// error h^2 |f^(3)| / 6 against the round-off eps |f| / h (NocedalWright2006, sec. 8.1).
inline const double kCentralDifferenceFraction = std::cbrt(2.220446049250313e-16);

/// The step x + h - x actually taken from x (exact in floating point, so the difference
/// quotient divides by the step its points are apart; Press2007, sec. 5.7).
inline double stepTaken(double x, double h) {
  const volatile double shifted = x + h;
  return shifted - x;
}

/// The five-point central difference of the parameter derivatives (fourth order,
/// AbramowitzStegun1964, eq. 25.3.6): f'(p) = sum_j w_j f(p + o_j h) / h + h^4 f^(5) / 30,
/// with round-off sqrt(2 (8^2 + 1)) / 12 eps |f| / h = 0.95 eps |f| / h. Its points o_j h:
inline constexpr int kStencilPoints = 4;
inline constexpr std::array<double, kStencilPoints> kStencilOffsets{1.0, -1.0, 2.0, -2.0};
/// and weights w_j (the same order).
inline constexpr std::array<double, kStencilPoints> kStencilWeights{8.0 / 12.0, -8.0 / 12.0, -1.0 / 12.0, 1.0 / 12.0};

/// sum_j w_j f_j / h (AbramowitzStegun1964, eq. 25.3.6) for the values f_j = at(j) at the
/// stencil's points (a number or an Eigen vector or matrix; those allocate).
template <class Value, class At>
Value stencilDerivative(double h, At&& at) {
  Value d = (kStencilWeights[0] / h) * at(0);
  for (int j = 1; j < kStencilPoints; ++j) d += (kStencilWeights[static_cast<std::size_t>(j)] / h) * at(j);
  return d;
}

/// r += A x for A in CSC values on `pattern` (the sensitivity residual's F_y s, the
/// projection of the initial sensitivities). Allocates nothing.
inline void addPatternProduct(const SparsePattern& pattern, const double* values, const double* x, double* r) {
  const auto& cs = pattern.colStart();
  const auto& ri = pattern.rowIndex();
  for (int c = 0; c < pattern.size(); ++c) {
    const double xc = x[c];
    if (xc == 0.0) continue;
    for (int64_t k = cs[c]; k < cs[c + 1]; ++k) r[ri[k]] += values[k] * xc;
  }
}

/// r += A^T x for A in CSC values on `pattern` (the adjoint's F_y^T lambda). Allocates nothing.
inline void addPatternTransposeProduct(const SparsePattern& pattern, const double* values, const double* x, double* r) {
  const auto& cs = pattern.colStart();
  const auto& ri = pattern.rowIndex();
  for (int c = 0; c < pattern.size(); ++c) {
    double sum = 0.0;
    for (int64_t k = cs[c]; k < cs[c + 1]; ++k) sum += values[k] * x[ri[k]];
    r[c] += sum;
  }
}

/// dF/dp_i (t, y, y') of a DAE F(t, y, y', p) = 0 for each parameter p_i.
class ParameterDerivatives {
 public:
  virtual ~ParameterDerivatives() = default;
  /// Number of parameters.
  virtual int count() const = 0;
  /// dF/dp_i at (t, y, y') into dFdp (size n of the DAE). Allocates nothing.
  virtual void residualDerivative(int i, double t, const double* y, const double* yp, double* dFdp) = 0;
};

/// The forward sensitivity problem of one run: s_i = dy/dp_i solves
/// F_y s_i + F_y' s_i' + F_p_i = 0 (IdasGuide, "Forward sensitivity analysis"; HindmarshEtAl2005).
struct SensitivityProblem {
  ParameterDerivatives* derivatives = nullptr;  ///< dF/dp; outlives the integrator
  MatX s0;   ///< consistent initial sensitivities dy0/dp (n x count)
  MatX sp0;  ///< their rates dy0'/dp (n x count)
  /// Typical magnitude of each parameter (count): the sensitivity s_i enters the error
  /// test with the state's relative tolerance and absolute tolerances atolS.col(i), the
  /// state's ones divided by |scale_i| (IdasGuide, "estimated" sensitivity tolerances), so
  /// that p_i s_i is controlled like y.
  VecX scales;
  /// Absolute tolerances of the sensitivities (n x count).
  MatX atolS;
  /// The sensitivities take part in the local error test (IDASetSensErrCon). Off: the
  /// steps are those of the plain run and the sensitivities follow them uncontrolled.
  bool errorControl = true;
};

}  // namespace flexmbd
