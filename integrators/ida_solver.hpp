/// @file
/// SUNDIALS IDAS (IDA with sensitivity analysis) behind a small RAII class: every flag
/// checked, exceptions never cross the C callbacks (they are stored and rethrown); forward
/// sensitivities on request (docs/sensitivities.md).
#pragma once

#include <exception>
#include <functional>
#include <memory>
#include <string>

#include "integrators/adjoint_problem.hpp"
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
  /// With the integrals of `outputs` as forward quadratures (outside the error test: they
  /// follow the state's steps) and, if `stepsPerCheckpoint` > 0, recording for adjoint
  /// sensitivities (IDAS: one checkpoint every `stepsPerCheckpoint` steps, the BDF's own
  /// interpolating polynomials between the steps; see checkpoints()). `outputs` and `dae`
  /// must outlive the solver; a recording DAE must provide its rate Jacobian product
  /// (DaeProblem::providesRateJacobianProduct).
  /// @throws InputError if it does not, SolverError if IDAS cannot be set up.
  IdaSolver(const DaeProblem& dae, double t0, const VecX& y0, const VecX& yp0, const IntegratorOptions& options,
            IntegralOutputs& outputs, long stepsPerCheckpoint);
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
  /// The integrals of the outputs from t0 to the time returned by advance() (empty without).
  VecX integrals() const;
  /// Checkpoints IDAS has stored (recording): 1 while the run has taken fewer steps than
  /// stepsPerCheckpoint. IDAS 6.4 recomputes each interval between checkpoints in the
  /// backward integration and overruns its step store when the recomputation takes more
  /// steps than the first pass did (SUNDIALS issue 49; measured here from the second
  /// checkpoint on: a restored checkpoint takes a fresh Jacobian, the first pass an older
  /// one). The recomputation from the first checkpoint repeats the first pass exactly, so
  /// a recording is safe with one checkpoint (simulateWithAdjoint records in segments).
  int checkpoints() const { return checkpoints_; }
  /// After the recording reached T: integrates the adjoints of `problem` (one backward
  /// problem per output, terminal values at T) back to t0, with the quadratures of the
  /// gradients (docs/sensitivities.md, "Adjoint sensitivities"). Each backward problem's
  /// Newton matrix is -J(-cj_B)^T (the term of dE/dt left out).
  /// `progress` (if given) gets the time of each backward residual evaluation and the
  /// backward steps taken so far (it does not change the integration).
  /// @throws SolverError with IDAS's reason and the time; an exception of a callback as
  /// it was thrown; std::logic_error without recording.
  AdjointSolution integrateAdjoint(const AdjointProblem& problem, double t0,
                                   const std::function<void(double t, long steps)>& progress = {});
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
  void startQuadratures(IntegralOutputs& outputs, long stepsPerCheckpoint);
  VecX y_, yp_, failureState_;
  double t_ = 0.0;  ///< the time returned by the last advance()
  int checkpoints_ = 0;
  MatX s_, sp_;
  bool usesKlu_ = false;
};

}  // namespace flexmbd
