// The inertia and stiffness invariants of a planar floating-frame-of-reference body:
// everything its equations of motion need at run time, besides the current q_f.
// Definitions and sign conventions: docs/flexible-bodies.md.
#pragma once

#include <string>
#include <vector>

#include "core/types.hpp"

namespace flexmbd {

/// A material point of the body where joints and forces attach (a node): undeformed
/// position u0 (body frame), u = u0 + N q_f, cross-section rotation psi = Nphi q_f.
struct FfrPoint {
  Vec2 position = Vec2::Zero();
  Mat2X shape;          ///< N, 2 x nf (translation shape matrix)
  RowVecX rotationShape;  ///< Nphi, 1 x nf
};

/// With u(x) = u0(x) + N(x) q_f the body-frame position of a material point
/// (document 003; Shabana ch. 5), all integrals over the undeformed body:
struct FfrInvariants {
  double mass = 0.0;                    ///< m = int rho dV
  Vec2 firstMoment = Vec2::Zero();      ///< int rho u0 dV
  double polarMoment = 0.0;             ///< I0 = int rho u0.u0 dV (about the frame origin)
  Mat2X sBar;                           ///< S-bar = int rho N dV (2 x nf)
  VecX i1;                              ///< I1 = int rho N^T u0 dV
  VecX j0;                              ///< J0 = int rho N^T S u0 dV (S: +90 degree rotation)
  // Sparse: banded for nodal beam meshes (the body's cost stays linear in its size),
  // full for modal models.
  SpMat mff;                            ///< m_ff = int rho N^T N dV = S_xx + S_yy
  SpMat sTilde;                         ///< S~ = int rho N^T S^T N dV = S_xy - S_yx (skew)
  SpMat kff;                            ///< stiffness under the reference conditions
  SpMat dff;                            ///< damping
  std::vector<FfrPoint> points;         ///< attachment points (nodes)

  int numElastic() const { return static_cast<int>(mff.rows()); }
  /// Sizes, symmetry (m_ff, K_ff, D_ff), skew symmetry (S~), positive definiteness
  /// (m_ff, K_ff), D_ff positive semi-definite, I0 >= |first moment|^2 / m.
  /// @throws InputError naming `owner` and the offending invariant.
  void validate(const std::string& owner) const;
  /// The invariants for q_f = P eta (modal reduction, change of coordinates).
  FfrInvariants transformed(const SpMat& P) const;
  /// The elastic coordinates the point's shape depends on (ascending).
  static std::vector<int> support(const FfrPoint& p);
};

}  // namespace flexmbd
