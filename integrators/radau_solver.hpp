/// @file
/// Radau IIA of orders 5, 9 and 13 (3, 5 and 7 stages) for the engine's implicit DAEs
/// F(t, y, y') = 0, at a fixed order or with the order chosen step by step: simplified
/// Newton on the collocation equations with the matrix transformed into one real and
/// (s-1)/2 complex systems, a stiffly filtered embedded error estimate, the predictive
/// (Gustafsson) step-size controller and continuous output from the collocation
/// polynomial. Written from the formulas of HairerWanner1996, sections IV.5, IV.8, VI.1 and
/// VII.4, and HairerWanner1999 (the variable order); the method, the order
/// choice and what is reused between steps are described in docs/formulations.md.
#pragma once

#include <memory>

#include "integrators/dae_integrator.hpp"
#include "integrators/radau_coefficients.hpp"

namespace flexmbd {

/// The orders the solver may use, as stage counts (3, 5 or 7; min <= max). {3, 3} is the
/// classic RADAU5; {3, 7} lets the solver choose per step.
struct RadauStages {
  int min = 3, max = 3, initial = 3;
};

/// Radau IIA behind the DaeIntegrator interface. Allocates nothing per step: every
/// vector, the dense LUs or the KLU objects are made in the constructor.
class RadauSolver final : public DaeIntegrator {
 public:
  /// y0, yp0 must be consistent (yp0 is the first Newton predictor).
  /// @throws InputError on bad options, SolverError if the linear solver cannot be set up.
  RadauSolver(const DaeProblem& dae, double t0, const VecX& y0, const VecX& yp0, const IntegratorOptions& options,
              RadauStages stages = {});
  ~RadauSolver() override;
  RadauSolver(const RadauSolver&) = delete;
  RadauSolver& operator=(const RadauSolver&) = delete;

  /// Integrates to tout (may step past it, never past tStop), returns tout; y() and yp()
  /// come from the collocation polynomial of the step holding tout.
  /// @throws SolverError with the reason, the time reached and the last step size; an
  /// exception of the model's residual or Jacobian as it was thrown (DaeIntegrator::advance).
  double advance(double tout, double tStop) override;
  const VecX& y() const override;
  const VecX& yp() const override;
  IntegratorStats stats() const override;
  bool usesKlu() const override;
  /// Stage count of the last accepted step.
  int stages() const;

  /// Test hook (convergence-order tests): every step has the size h (the last one before
  /// tStop shortened), the error test is skipped. A Newton failure is then an error.
  void setFixedStepSize(double h);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace flexmbd
