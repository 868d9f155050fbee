/// @file
/// The highest BDF order that is stable for the damped elastic modes of a model
/// (docs/formulations.md, "BDF order and damped elastic modes").
#pragma once

#include <string>

#include "core/system.hpp"

namespace flexmbd {

/// A(alpha) stability angles of BDF orders 1..5 in degrees (index = order;
/// HairerWanner1996, Table V.2.3): a mode lambda = |lambda| e^{i (pi - theta)} is
/// stable for every step size at order k iff theta <= alpha_k. Orders 1, 2: A-stable.
inline constexpr double kBdfStabilityAngleDegrees[6] = {90.0, 90.0, 90.0, 86.03, 73.35, 51.84};

/// The limit never goes below BDF3: its sector (86.03 degrees) holds every mode with
/// zeta >= cos(86.03) = 0.07, and modes damped less than that are treated like undamped
/// ones: they keep more than exp(-2 pi 0.07) = 64 % of their amplitude per period, so
/// while excited the error test resolves them (h |lambda| small, where BDF3-5 are stable,
/// as for the undamped rods the default order 5 is used for). Order 2 was measured to
/// cost 4.6x the steps of order 3 on the damped elastic slider-crank (docs/formulations.md).
inline constexpr int kLowestLimitedOrder = 3;

/// Elastic bodies with more coordinates than this are not analysed (dense symmetric
/// eigenproblem, O(n^3): about 0.1 s at this size); their modes do not limit the order.
inline constexpr int kMaxModalAnalysisSize = 400;

struct BdfOrderLimit {
  int order = 5;             ///< highest stable order, <= the requested one
  std::string body;          ///< the body whose mode set the limit ("" if none)
  double dampingRatio = 0;   ///< that mode's damping ratio zeta
  double frequency = 0;      ///< its undamped circular frequency omega (rad/s)
  /// One line for the summary ("" if the requested order stands).
  std::string reason() const;
};

/// The highest BDF order k <= requested, and >= kLowestLimitedOrder unless requested is
/// lower, such that every elastic mode (undamped frequencies omega_i and modal damping
/// ratios zeta_i = phi_i^T D phi_i / (2 omega_i) of the body's m_ff, K_ff, D_ff,
/// mass-normalised phi_i) with zeta_i >= cos(alpha_3) lies in BDF k's stability
/// sector: zeta_i >= cos(alpha_k) (the
/// eigenvalues -zeta omega +- i omega sqrt(1 - zeta^2) (GeradinRixen) make the angle acos(zeta) with
/// the negative real axis; overdamped modes, zeta >= 1, are real). Exact for
/// proportional damping D = a M + b K (the beams' stiffness-proportional damping).
BdfOrderLimit stableBdfOrder(const System& sys, int requested);

}  // namespace flexmbd
