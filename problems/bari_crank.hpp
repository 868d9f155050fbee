// Simeon's flexible slider crank (Bari IVP test set "crank"; B. Simeon, Math. Modelling
// of Systems 2 (1996) 1-18), hand-coded from the published formulation: the yardstick
// the engine's model of the same mechanism (examples/bari_slider_crank.json) is timed
// against, integrated by the same integrators in the same process. Definition, constants
// and reference: shared/benchmarks/simeon-slider-crank.md, benchmarks/README.md.
#pragma once

#include <array>

#include "core/dae_problem.hpp"

namespace flexmbd::bari {

/// Published reference at t = 0.1 (test set): positions phi2, x3, q1..q4.
inline constexpr double kEndTime = 0.1;
inline constexpr std::array<double, 6> kReferencePositions = {
    -0.3311734988256260,   0.1697373328427860,    1.893192899613509e-4,
    2.375751249879174e-5,  -5.323896770569702e-6, -8.363313279112129e-6};
/// Published reference velocities phi2', x3' at t = 0.1.
inline constexpr double kReferenceRodAngularVelocity = 60.25346755138369;
inline constexpr double kReferenceSliderVelocity = -8.753116326670527;

/// scd = -log10 of the largest relative error of the six positions (test-set measure).
double significantDigits(const std::array<double, 6>& positions);

/// The test set's index-2 formulation, 24 unknowns y = (p, q | p', q' | w | lambda) with
/// p = (phi1, phi2, x3), q = (q1..q4):  (p, q)' = v,  v' = w,  M(p, q) w - f(p, q, v) +
/// G^T lambda = 0,  G v - (0, 0, Omega) = 0. The Jacobian is exact (forward-mode automatic
/// differentiation of the residual, fixed size, no allocation).
class HandCodedCrank final : public DaeProblem {
 public:
  static constexpr int kSize = 24;
  HandCodedCrank();

  int size() const override { return kSize; }
  const SparsePattern& pattern() const override { return pattern_; }
  /// p, q, p', q' in the error test; w and lambda algebraic (as the classic codes' runs).
  VecX differentialIds() const override;
  using DaeProblem::jacobian;
  using DaeProblem::residual;
  void residual(double t, const double* y, const double* yp, double* F, DaeScratch& scratch) const override;
  void jacobian(double t, const double* y, const double* yp, double cj, JacobianSink& J,
                DaeScratch& scratch) const override;

  /// Consistent initial values at t = 0 (shared/benchmarks/simeon-slider-crank.md).
  static void initialValues(VecX& y0, VecX& yp0);
  /// Positions phi2, x3, q1..q4 of a state y.
  static std::array<double, 6> positions(const VecX& y);

 private:
  SparsePattern pattern_;
};

}  // namespace flexmbd::bari
