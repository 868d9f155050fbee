// Radau IIA of order 5 (three stages) for the engine's implicit DAEs F(t, y, y') = 0:
// simplified Newton on the collocation equations with the matrix transformed into one
// real and one complex system, a stiffly filtered embedded error estimate, the
// predictive (Gustafsson) step-size controller and continuous output from the
// collocation polynomial. Written from the formulas of Hairer & Wanner, Solving Ordinary
// Differential Equations II (2nd ed.), sections IV.5, IV.8, VI.1 and VII.4; the method
// and what is reused between steps are described in docs/formulations.md.
#pragma once

#include <memory>

#include <Eigen/Core>

#include "integrators/dae_integrator.hpp"

namespace flexmbd {

/// The three-stage Radau IIA method and the quantities the solver derives from it once.
struct Radau5Coefficients {
  Eigen::Vector3d c;        ///< nodes (4 -+ sqrt 6)/10, 1 (H&W IV.5, Table 5.6)
  Eigen::Matrix3d A;        ///< Butcher matrix; the weights b are its last row (stiffly accurate)
  Eigen::Matrix3d W;        ///< A^-1: stage derivatives h Y'_i = sum_j W_ij Z_j
  /// W = T Lambda T^-1 with Lambda = [gamma 0 0; 0 alpha beta; 0 -beta alpha]: the real
  /// eigenvalue gamma and the pair alpha +- i beta of A^-1 (H&W IV.8, (8.15)-(8.16)).
  Eigen::Matrix3d T, Tinv;
  double gamma = 0.0, alpha = 0.0, beta = 0.0;
  /// Embedded error estimate: yhat_1 - y_1 = h y'_0 / gamma + sum_j d_j Z_j (H&W IV.8, (8.18)).
  Eigen::Vector3d d;
  /// Collocation polynomial: u(t0 + s h) = y0 + sum_j L_j(s) Z_j with
  /// (L_1, L_2, L_3)(s) = P^T (s, s^2, s^3) (Lagrange basis on the nodes 0, c_1, c_2, c_3).
  Eigen::Matrix3d P;
  /// Where the interpolation error factor s (s - c1)(s - c2)(s - 1) of the collocation
  /// polynomial peaks on [0, 1] (s = 0.86): the point of the dense-output error estimate.
  double sDense = 0.0;
  static const Radau5Coefficients& get();
};

/// Radau IIA (order 5) behind the DaeIntegrator interface. Allocates nothing per step:
/// every vector, the dense LU or the KLU objects are made in the constructor.
class Radau5Solver final : public DaeIntegrator {
 public:
  /// y0, yp0 must be consistent (yp0 is the first Newton predictor).
  /// @throws InputError on bad options, SolverError if the linear solver cannot be set up.
  Radau5Solver(const DaeProblem& dae, double t0, const VecX& y0, const VecX& yp0, const IntegratorOptions& options);
  ~Radau5Solver() override;
  Radau5Solver(const Radau5Solver&) = delete;
  Radau5Solver& operator=(const Radau5Solver&) = delete;

  /// Integrates to tout (may step past it, never past tStop), returns tout; y() and yp()
  /// come from the collocation polynomial of the step holding tout.
  /// @throws SolverError with the reason, the time reached and the last step size; an
  /// exception of the model's residual or Jacobian as it was thrown (DaeIntegrator::advance).
  double advance(double tout, double tStop) override;
  const VecX& y() const override;
  const VecX& yp() const override;
  IntegratorStats stats() const override;
  bool usesKlu() const override;

  /// Test hook (convergence-order tests): every step has the size h (the last one before
  /// tStop shortened), the error test is skipped. A Newton failure is then an error.
  void setFixedStepSize(double h);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace flexmbd
