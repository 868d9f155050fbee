/// @file
/// What IDAS needs besides the DAE for forward sensitivities (docs/sensitivities.md): the
/// derivative dF/dp of the residual with respect to each parameter, the consistent initial
/// sensitivities and how the sensitivities enter the error test.
#pragma once

#include <cmath>

#include "core/sparse_pattern.hpp"
#include "core/types.hpp"

namespace flexmbd {

/// Relative step of the engine's central differences: eps^(1/3) balances their truncation
/// error h^2 |f^(3)| / 6 against the round-off eps |f| / h (Nocedal & Wright 2006, sec. 8.1).
inline const double kCentralDifferenceFraction = std::cbrt(2.220446049250313e-16);

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
/// F_y s_i + F_y' s_i' + F_p_i = 0 (IDAS guide, "Forward sensitivity analysis").
struct SensitivityProblem {
  ParameterDerivatives* derivatives = nullptr;  ///< dF/dp; outlives the integrator
  MatX s0;   ///< consistent initial sensitivities dy0/dp (n x count)
  MatX sp0;  ///< their rates dy0'/dp (n x count)
  /// Typical magnitude of each parameter (count): the sensitivity s_i enters the error
  /// test with the state's relative tolerance and absolute tolerances atolS.col(i), the
  /// state's ones divided by |scale_i| (IDAS guide, "estimated" sensitivity tolerances), so
  /// that p_i s_i is controlled like y.
  VecX scales;
  /// Absolute tolerances of the sensitivities (n x count).
  MatX atolS;
  /// The sensitivities take part in the local error test (IDASetSensErrCon). Off: the
  /// steps are those of the plain run and the sensitivities follow them uncontrolled.
  bool errorControl = true;
};

}  // namespace flexmbd
