/// @file
/// What every time integrator of the engine offers (IDA's BDF, Radau IIA), so that a run,
/// a benchmark or a test can pick one by name: options, statistics and the stepping call.
#pragma once

#include <memory>
#include <string>

#include "core/dae_problem.hpp"

namespace flexmbd {

enum class LinearSolverKind {
  Automatic,  ///< dense up to kDenseSizeLimit unknowns, KLU above
  Dense,      ///< SUNDIALS dense LU
  Klu,        ///< SuiteSparse KLU on the CSC pattern fixed at finalize
};
std::string toString(LinearSolverKind k);  ///< "auto", "dense", "klu".
/// "auto", "dense", "klu". @throws InputError otherwise.
LinearSolverKind parseLinearSolver(const std::string& name);

/// Unknowns up to which Automatic picks the dense solver. KLU is already faster than
/// SUNDIALS' dense LU for the 10-unknown pendulum and the 36-unknown slider-crank
/// (bench_rigid_slider_crank; figures in benchmarks/README.md), so dense is kept only
/// for the smallest systems.
inline constexpr int kDenseSizeLimit = 8;

/// The settings a DaeIntegrator is made with (from SolverSettings by the run).
struct IntegratorOptions {
  double rtol = 1e-8;  ///< relative tolerance
  /// Absolute tolerance per unknown (size n of the DAE), e.g. from absoluteTolerances()
  /// in simulation.hpp. Multipliers get a large one, so that the algebraic variables
  /// (already out of the error test) stay out of the Newton convergence test too.
  VecX atol;
  long maxSteps = 1000000;        ///< per call of advance()
  double maxStepSize = 0.0;      ///< 0: no limit
  double minStepSize = 0.0;      ///< IDA fails (IDA_ERR_FAIL/IDA_CONV_FAIL) below this
  int maxOrder = 5;              ///< highest BDF order, 1..5 (IDA only)
  double initialStepSize = 0.0;  ///< first step tried; 0: IDA's estimate from y'
  LinearSolverKind linearSolver = LinearSolverKind::Automatic;  ///< the Newton systems' solver
  bool finiteDifferenceJacobian = false;  ///< IDA's own difference quotients (dense only)
};

/// An integrator's counters (SUNDIALS' names): steps, residual and Jacobian evaluations,
/// Newton iterations and failures, error-test failures, linear solver setups; the last
/// step size and the time reached.
struct IntegratorStats {
  long steps = 0, residualEvals = 0, jacobianEvals = 0, nonlinearIterations = 0,
       nonlinearConvFailures = 0, errorTestFailures = 0, linearSetups = 0;
  double lastStepSize = 0.0, currentTime = 0.0;
};

/// The time integrators.
enum class IntegratorKind {
  Ida,     ///< SUNDIALS IDA: variable-order BDF (orders 1..5)
  Radau5,  ///< Radau IIA of order 5, three stages (integrators/radau_solver.hpp)
  Radau,   ///< Radau IIA of orders 5, 9 and 13, the order chosen per step (integrators/radau_solver.hpp)
  /// Index-3 augmented Lagrangian with projections, trapezoidal rule (order 2), stays
  /// regular at singular positions (integrators/augmented_lagrangian_integrator.hpp)
  AugmentedLagrangian,
  /// Chosen by the run from the model (simulation/integrator_choice.hpp): a setting, not
  /// an integrator (makeIntegrator refuses it).
  Automatic,
};
std::string toString(IntegratorKind k);
/// "ida", "radau", "radau5", "ali3p", "auto". @throws InputError otherwise.
IntegratorKind parseIntegrator(const std::string& name);

/// A DAE integrator started from consistent y0, y0' at t0.
class DaeIntegrator {
 public:
  virtual ~DaeIntegrator() = default;
  /// Integrates to tout (never past tStop), returns the time reached (= tout).
  /// @throws SolverError with the reason, the time and the last step size. An exception
  /// thrown by the problem's residual or Jacobian is not a solver failure: it leaves with
  /// its type and message (InputError, ModelError, std::logic_error of an assembly bug),
  /// so that the caller reports it as what it is. A residual with non-finite entries is
  /// a recoverable event of the integrator (a smaller step is tried).
  virtual double advance(double tout, double tStop) = 0;
  /// Solution at the time returned by advance().
  virtual const VecX& y() const = 0;
  virtual const VecX& yp() const = 0;
  virtual IntegratorStats stats() const = 0;
  virtual bool usesKlu() const = 0;
  /// After advance() threw SolverError: the solution y at the error's time (the last step
  /// completed), if the integrator keeps it; false if not. A restart can begin there.
  virtual bool solutionAtFailure(VecX& y) const {
    (void)y;
    return false;
  }
};

/// The integrator of the given kind. @throws InputError on bad options, SolverError if
/// it cannot be set up.
std::unique_ptr<DaeIntegrator> makeIntegrator(IntegratorKind kind, const DaeProblem& dae, double t0,
                                              const VecX& y0, const VecX& yp0, const IntegratorOptions& options);

}  // namespace flexmbd
