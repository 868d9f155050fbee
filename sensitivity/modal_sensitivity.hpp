/// @file
/// Eigenvalue sensitivities of the modal analysis (docs/modes.md, "Sensitivities of the
/// modes"): the derivative of each eigenvalue s of the reduced equations
/// Mr x'' + Cr x' + Kr x = 0 with respect to a scene parameter p, from the linearisations of
/// the systems built with p + h and p - h (the same perturbed scenes as a sensitivity run,
/// results/sensitivity_results.hpp). Sources: FoxKapoor1968 (undamped modes, the Rayleigh
/// quotient's stationarity); TisseurMeerbergen2001, sec. 3 (the quadratic eigenvalue
/// problem's left and right eigenvectors).
#pragma once

#include <array>
#include <complex>
#include <vector>

#include "analysis/linearization.hpp"
#include "integrators/sensitivity_problem.hpp"

namespace flexmbd {

/// The derivative of one mode's eigenvalue and of the modes.csv columns it gives. NaN
/// everywhere where the eigenvalue is repeated (not differentiable: a degenerate pair's
/// members may split in any direction).
struct ModeDerivative {
  std::complex<double> eigenvalue;  ///< ds/dp
  double omega = 0.0;               ///< d|s|/dp = Re(conj(s) ds/dp) / |s|
  double frequencyHz = 0.0;         ///< d|s|/dp / (2 pi)
  double dampingRatio = 0.0;        ///< d(-Re s / |s|)/dp
  bool defined = true;              ///< false: repeated eigenvalue (the fields are NaN)
};

/// Two eigenvalues closer than this fraction of their size are taken as repeated.
inline constexpr double kRepeatedEigenvalueFraction = 1e-6;

/// ds/dp of each of `modes` (computed from `red` = reduce(lin, ...)), with x and w the right
/// and left null vectors of Q(s) = s^2 Mr + s Cr + Kr (inverse iteration):
///
///     ds/dp = - w^T (s^2 dMr/dp + s dCr/dp + dKr/dp) x / (w^T (2 s Mr + Cr) x)
///
/// (the derivative of w^T Q(s(p), p) x = 0; for undamped symmetric modes w = x, s = i omega
/// and it is the Rayleigh quotient's d(omega^2)/dp = x^T (dK/dp - omega^2 dM/dp) x / x^T M x,
/// FoxKapoor1968; TisseurMeerbergen2001, sec. 3).
/// dMr/dp, dCr/dp, dKr/dp: five-point differences (stencilDerivative) of the reduced
/// matrices of `perturbed` (the linearisations at p + kStencilOffsets[j] h, each about its
/// own reference state), in red.N moved onto their null spaces (reduceNear, with the base's
/// dependent velocities), error O(h^4) + eps |K| / h. A zero eigenvalue (a rigid-body mode) has derivative 0; an
/// eigenvalue within kRepeatedEigenvalueFraction of another of `modes` is not
/// differentiable (defined false).
/// @throws InputError if a perturbed model has another number of velocities or constraints.
std::vector<ModeDerivative> modeDerivatives(const LinearizedSystem& lin, const ReducedSystem& red,
                                            const std::vector<Mode>& modes,
                                            const std::array<LinearizedSystem, kStencilPoints>& perturbed, double h);

}  // namespace flexmbd
