// SUNDIALS IDA behind a small RAII class: every flag checked, exceptions never cross
// the C callbacks (they are stored and rethrown).
#pragma once

#include <exception>
#include <memory>
#include <string>

#include "core/dae_system.hpp"

namespace flexmbd {

enum class LinearSolverKind {
  Automatic,  ///< dense up to kDenseSizeLimit unknowns, KLU above
  Dense,      ///< SUNDIALS dense LU
  Klu,        ///< SuiteSparse KLU on the CSC pattern fixed at finalize
};
std::string toString(LinearSolverKind k);
/// "auto", "dense", "klu". @throws InputError otherwise.
LinearSolverKind parseLinearSolver(const std::string& name);

/// Unknowns up to which Automatic picks the dense solver. KLU is already faster than
/// SUNDIALS' dense LU for the 10-unknown pendulum and the 36-unknown slider-crank
/// (bench_rigid_slider_crank; figures in benchmarks/README.md), so dense is kept only
/// for the smallest systems.
inline constexpr int kDenseSizeLimit = 8;

struct IntegratorOptions {
  double rtol = 1e-8;
  double atolPosition = 1e-10;   ///< absolute tolerance of positions
  double atolVelocity = 1e-10;   ///< absolute tolerance of velocities
  /// Absolute tolerance of multipliers: large, so that the algebraic variables (already
  /// out of the error test) stay out of the Newton convergence test too.
  double atolMultiplier = 1e10;
  long maxSteps = 1000000;        ///< per call of advance()
  double maxStepSize = 0.0;      ///< 0: no limit
  double minStepSize = 0.0;      ///< IDA fails (IDA_ERR_FAIL/IDA_CONV_FAIL) below this
  int maxOrder = 5;              ///< highest BDF order, 1..5
  double initialStepSize = 0.0;  ///< first step tried; 0: IDA's estimate from y'
  LinearSolverKind linearSolver = LinearSolverKind::Automatic;
  bool finiteDifferenceJacobian = false;  ///< IDA's own difference quotients (dense only)
};

struct IntegratorStats {
  long steps = 0, residualEvals = 0, jacobianEvals = 0, nonlinearIterations = 0,
       nonlinearConvFailures = 0, errorTestFailures = 0, linearSetups = 0;
  double lastStepSize = 0.0, currentTime = 0.0;
};

class IdaSolver {
 public:
  /// y0, yp0 must be consistent (see computeConsistentState).
  /// @throws InputError on bad options, SolverError if IDA cannot be set up.
  IdaSolver(const DaeSystem& dae, double t0, const VecX& y0, const VecX& yp0,
            const IntegratorOptions& options);
  ~IdaSolver();
  IdaSolver(const IdaSolver&) = delete;
  IdaSolver& operator=(const IdaSolver&) = delete;

  /// Integrates to tout (never past tStop), returns the time reached (= tout).
  /// @throws SolverError with IDA's reason, the time and the last step size.
  double advance(double tout, double tStop);
  /// Current solution at the time returned by advance().
  const VecX& y() const { return y_; }
  const VecX& yp() const { return yp_; }
  IntegratorStats stats() const;
  bool usesKlu() const { return usesKlu_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  VecX y_, yp_;
  bool usesKlu_ = false;
};

}  // namespace flexmbd
