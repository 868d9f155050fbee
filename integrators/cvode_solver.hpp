/// @file
/// SUNDIALS CVODE (BDF, Newton with a dense difference-quotient Jacobian) behind a small
/// RAII class, with root-finding: every flag checked, exceptions never cross the C
/// callbacks (stored and rethrown), the same pattern as IdaSolver.
#pragma once

#include <memory>
#include <vector>

#include "core/types.hpp"
#include "integrators/ode_system.hpp"

namespace flexmbd {

struct CvodeOptions {
  double rtol = 1e-10;
  double atol = 1e-12;
  long maxSteps = 1000000;  ///< per call of advance()
  double maxStepSize = 0.0; ///< 0: no limit
};

struct CvodeStats {
  long steps = 0, rhsEvals = 0, rootEvals = 0, errorTestFailures = 0, nonlinearConvFailures = 0;
  double lastStepSize = 0.0;
};

class CvodeSolver {
 public:
  /// @throws InputError on bad options or sizes, SolverError if CVODE cannot be set up.
  CvodeSolver(const OdeSystem& ode, double t0, const VecX& y0, const CvodeOptions& options);
  ~CvodeSolver();
  CvodeSolver(const CvodeSolver&) = delete;
  CvodeSolver& operator=(const CvodeSolver&) = delete;

  /// Integrates towards tout (never past tout). Returns the time reached: tout, or the
  /// time of a root (then rootsFound() lists the sign changes: +1 rising, -1 falling, 0 none).
  /// @throws SolverError with CVODE's reason, the time and the last step size; an exception
  /// of the ODE's rhs() or roots() as it was thrown (an InputError stays an InputError).
  double advance(double tout);
  /// Restarts the integration at (t, y) (after a discontinuity of f's derivative).
  void reinit(double t, const VecX& y);
  const VecX& y() const { return y_; }
  bool rootFound() const { return rootFound_; }
  const std::vector<int>& rootsFound() const { return roots_; }
  /// Totals since construction (across reinit()).
  CvodeStats stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  VecX y_;
  bool rootFound_ = false;
  std::vector<int> roots_;
  CvodeStats accumulated_;  ///< counters of the integrations before the last reinit
};

}  // namespace flexmbd
