/// @file
/// SUNDIALS IDA behind a small RAII class: every flag checked, exceptions never cross
/// the C callbacks (they are stored and rethrown).
#pragma once

#include <exception>
#include <memory>
#include <string>

#include "integrators/dae_integrator.hpp"

namespace flexmbd {

class IdaSolver final : public DaeIntegrator {
 public:
  /// y0, yp0 must be consistent (see computeConsistentState).
  /// @throws InputError on bad options, SolverError if IDA cannot be set up.
  IdaSolver(const DaeProblem& dae, double t0, const VecX& y0, const VecX& yp0,
            const IntegratorOptions& options);
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
  bool usesKlu() const override { return usesKlu_; }
  bool solutionAtFailure(VecX& y) const override {
    if (failureState_.size() == 0) return false;
    y = failureState_;
    return true;
  }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  VecX y_, yp_, failureState_;
  bool usesKlu_ = false;
};

}  // namespace flexmbd
