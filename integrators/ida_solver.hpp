/// @file
/// SUNDIALS IDAS (IDA with sensitivity analysis) behind a small RAII class: every flag
/// checked, exceptions never cross the C callbacks (they are stored and rethrown); forward
/// sensitivities on request (docs/sensitivities.md).
#pragma once

#include <exception>
#include <memory>
#include <string>

#include "integrators/dae_integrator.hpp"
#include "integrators/sensitivity_problem.hpp"

namespace flexmbd {

class IdaSolver final : public DaeIntegrator {
 public:
  /// y0, yp0 must be consistent (see computeConsistentState).
  /// @throws InputError on bad options, SolverError if IDA cannot be set up.
  IdaSolver(const DaeProblem& dae, double t0, const VecX& y0, const VecX& yp0,
            const IntegratorOptions& options);
  /// With forward sensitivities (staggered corrector): `sensitivity.derivatives` and
  /// `dae` must outlive the solver; s0, sp0 consistent (n x count).
  /// @throws InputError if the sizes do not match, SolverError if IDAS cannot be set up.
  IdaSolver(const DaeProblem& dae, double t0, const VecX& y0, const VecX& yp0, const IntegratorOptions& options,
            const SensitivityProblem& sensitivity);
  ~IdaSolver();
  IdaSolver(const IdaSolver&) = delete;
  IdaSolver& operator=(const IdaSolver&) = delete;

  /// Integrates to tout (never past tStop), returns the time reached (= tout).
  /// @throws SolverError with IDA's reason, the time and the last step size; an exception
  /// of the model's residual or Jacobian as it was thrown (DaeIntegrator::advance).
  double advance(double tout, double tStop) override;
  /// Current solution at the time returned by advance().
  const VecX& y() const override { return y_; }
  const VecX& yp() const override { return yp_; }
  IntegratorStats stats() const override;
  /// Sensitivities dy/dp (n x count) and their rates dy'/dp at the time returned by
  /// advance() (empty without sensitivities).
  const MatX& sensitivity() const { return s_; }
  const MatX& sensitivityRate() const { return sp_; }
  /// Sensitivity residual evaluations (calls of the sensitivity residual function).
  long sensitivityResidualEvals() const;
  bool usesKlu() const override { return usesKlu_; }
  bool solutionAtFailure(VecX& y) const override {
    if (failureState_.size() == 0) return false;
    y = failureState_;
    return true;
  }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  void startSensitivities(const SensitivityProblem& sensitivity);
  VecX y_, yp_, failureState_;
  MatX s_, sp_;
  bool usesKlu_ = false;
};

}  // namespace flexmbd
