/// @file
/// The inertia and stiffness invariants of a planar floating-frame-of-reference body:
/// everything its equations of motion need at run time, besides the current q_f.
/// Definitions and sign conventions: docs/flexible-bodies.md. What planar and spatial
/// invariants share: bodies/ffr_invariants_base.hpp.
#pragma once

#include <string>
#include <vector>

#include "bodies/ffr_invariants_base.hpp"

namespace flexmbd {

/// A planar attachment point: position u0, shape N (2 x nf), rotation shape Nphi (1 x nf).
using FfrPoint = FfrPointT<2>;

/// With u(x) = u0(x) + N(x) q_f the body-frame position of a material point
/// (Doc003; Shabana2005, ch. 5), all integrals over the undeformed body; besides the
/// shared mass, first moment, S-bar, m_ff = S_xx + S_yy, K_ff, D_ff and points:
struct FfrInvariants : FfrInvariantsBase<2> {
  double polarMoment = 0.0;             ///< I0 = int rho u0.u0 dV (about the frame origin)
  VecX i1;                              ///< I1 = int rho N^T u0 dV
  VecX j0;                              ///< J0 = int rho N^T S u0 dV (S: +90 degree rotation)
  SpMat sTilde;                         ///< S~ = int rho N^T S^T N dV = S_xy - S_yx (skew)
  /// R (nf x nf, symmetric; optional, empty for none): the sections' second-order
  /// rotation (Rayleigh and Timoshenko beams, BeamElement2d::sectionRotationMoment):
  /// int rho |u0 + u|^2 dV = I0 + 2 I1^T q_f + q_f^T (m_ff + R) q_f.
  SpMat rff;

  /// m_ff + R: the quadratic part of the polar moment int rho |u0 + u|^2 dV (m_ff
  /// without R).
  SpMat polarQuadratic() const;
  /// Sizes, symmetry (m_ff, K_ff, D_ff, R), skew symmetry (S~), positive definiteness
  /// (m_ff, K_ff), D_ff positive semi-definite, I0 >= |first moment|^2 / m.
  /// @throws InputError naming `owner` and the offending invariant.
  void validate(const std::string& owner) const;
  /// The invariants for q_f = P eta (modal reduction, change of coordinates).
  FfrInvariants transformed(const SpMat& P) const;
};

}  // namespace flexmbd
