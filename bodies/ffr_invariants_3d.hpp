// The inertia and stiffness invariants of a spatial floating-frame-of-reference body:
// everything its equations of motion need at run time, besides the current q_f.
// Definitions: docs/spatial-flexible.md (document 003; Shabana, Dynamics of Multibody
// Systems, ch. 5, eq. 5.96-5.140 for the spatial mass matrix blocks).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "core/types.hpp"

namespace flexmbd {

/// A material point of the body where joints and forces attach (a node): undeformed
/// position u0 (body frame), u = u0 + N q_f, and the small rotation of its cross-section
/// theta = Ntheta q_f (body axes): the section's axes in the body frame are
/// (I + skew(theta)) to first order in q_f, as the element's small nodal rotations.
struct FfrPoint3d {
  Vec3 position = Vec3::Zero();
  Mat3X shape;          ///< N, 3 x nf (translation shape matrix)
  Mat3X rotationShape;  ///< Ntheta, 3 x nf
};

/// With u(P) = u0(P) + N(P) q_f the body-frame position of a material point P, all
/// integrals over the undeformed body (dV, density rho):
struct FfrInvariants3d {
  double mass = 0.0;                        ///< m = int rho dV
  Vec3 firstMoment = Vec3::Zero();          ///< int rho u0 dV
  Mat3 secondMoment = Mat3::Zero();         ///< int rho u0 u0^T dV (the inertia tensor about
                                            ///< the frame origin is tr(.) I - (.))
  Mat3X sBar;                               ///< S-bar = int rho N dV (3 x nf)
  /// positionShape[k] (3 x nf): row l = int rho u0_k N_l dV (N_l row l of N), k, l in
  /// {x, y, z}: the coupling of the undeformed geometry with the deformation.
  std::array<Mat3X, 3> positionShape;
  /// sKL[k][l] = S_kl = int rho N_k^T N_l dV (nf x nf), S_lk = S_kl^T (document 003's
  /// nine inertia shape integrals, six independent). Sparse: banded for nodal meshes,
  /// full for modal models.
  std::array<std::array<SpMat, 3>, 3> sKL;
  /// rKL[k][l] = R_kl (nf x nf, symmetric, R_lk = R_kl): the second-order part of the
  /// cross-sections' rotation in int rho u u^T dV, which gains qf^T R_kl qf (a section
  /// point moves on a circle, not along the tangent N q_f: BeamElement3d::
  /// sectionRotationMoment). Empty (0 x 0): none (invariants from other FE tools).
  std::array<std::array<SpMat, 3>, 3> rKL;
  /// hI[i] = H_i (nf x nf, symmetric): int rho u0 x u2 dV = (qf^T H_i qf / 2)_i, u2 the
  /// sections' second-order displacement (BeamElement3d::sectionRotationCoupling): the
  /// kinetic energy gains w . (qf^T H_i qf')_i. Empty: none (zero under Euler-Bernoulli).
  std::array<SpMat, 3> hI;
  SpMat mff;                                ///< m_ff = S_xx + S_yy + S_zz
  SpMat kff;                                ///< stiffness under the reference conditions
  SpMat dff;                                ///< damping
  std::vector<FfrPoint3d> points;           ///< attachment points (nodes)

  int numElastic() const { return static_cast<int>(mff.rows()); }
  /// Sizes; symmetry of m_ff, K_ff, D_ff, S_kk; S_lk = S_kl^T; positive definiteness of
  /// m_ff and K_ff; D_ff positive semi-definite; the second moment symmetric positive
  /// semi-definite with |first moment|^2 <= m tr(second moment); finite entries.
  /// @throws InputError naming `owner` and the offending invariant.
  void validate(const std::string& owner) const;
  /// rKL, hI: each absent or nf x nf, finite, symmetric; R_lk = R_kl.
  void validateSectionRotation(const std::string& owner) const;
  /// The invariants for q_f = P eta (modal reduction, change of coordinates).
  FfrInvariants3d transformed(const SpMat& P) const;
  /// The elastic coordinates the point's shape and rotation shape depend on (ascending).
  static std::vector<int> support(const FfrPoint3d& p);
};

}  // namespace flexmbd
