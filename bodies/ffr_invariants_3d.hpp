/// @file
/// The inertia and stiffness invariants of a spatial floating-frame-of-reference body:
/// everything its equations of motion need at run time, besides the current q_f.
/// Definitions: docs/spatial-flexible.md (Doc003; Shabana2005, ch. 5, eqs. 5.96-5.140 for the
/// spatial mass matrix blocks).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "bodies/ffr_invariants_base.hpp"

namespace flexmbd {

/// A spatial attachment point: position u0, shape N (3 x nf), rotation shape Ntheta
/// (3 x nf, body axes).
using FfrPoint3d = FfrPointT<3>;

/// With u(P) = u0(P) + N(P) q_f the body-frame position of a material point P (Doc003;
/// Shabana2005, ch. 5), all integrals over the undeformed body (dV, density rho); besides the shared mass, first
/// moment, S-bar, m_ff = S_xx + S_yy + S_zz, K_ff, D_ff and points
/// (bodies/ffr_invariants_base.hpp):
struct FfrInvariants3d : FfrInvariantsBase<3> {
  Mat3 secondMoment = Mat3::Zero();         ///< int rho u0 u0^T dV (the inertia tensor about
                                            ///< the frame origin is tr(.) I - (.): Shabana2005, eq. 5.110)
  /// positionShape[k] (3 x nf): row l = int rho u0_k N_l dV (N_l row l of N), k, l in
  /// {x, y, z}: the coupling of the undeformed geometry with the deformation.
  std::array<Mat3X, 3> positionShape;
  /// sKL[k][l] = S_kl = int rho N_k^T N_l dV (nf x nf), S_lk = S_kl^T (Doc003's
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
  /// spinStiffness[k][l] = G_kl (nf x nf, symmetric, G_lk = G_kl): the geometric stiffness
  /// of the stresses a steady spin causes, per unit w_k w_l: Q_f gains -sum_kl w_k w_l G_kl
  /// q_f (centrifugal stiffening of imported bodies: from an FE code's prestressed
  /// stiffness, FeSpinStiffening, or a SID's Oe; docs/fe-import.md). Not the spin
  /// softening, which the S_kl give. Empty (0 x 0): none (beams stiffen through their
  /// strain energy instead).
  std::array<std::array<SpMat, 3>, 3> spinStiffness;

  /// Sizes; symmetry of m_ff, K_ff, D_ff, S_kk; S_lk = S_kl^T; positive definiteness of
  /// m_ff and K_ff; D_ff positive semi-definite; the second moment symmetric positive
  /// semi-definite with |first moment|^2 <= m tr(second moment); finite entries.
  /// @throws InputError naming `owner` and the offending invariant.
  void validate(const std::string& owner) const;
  /// rKL, hI, spinStiffness: each absent or nf x nf, finite, symmetric; R_lk = R_kl,
  /// G_lk = G_kl.
  void validateSectionRotation(const std::string& owner) const;
  /// The invariants for q_f = P eta (modal reduction, change of coordinates).
  FfrInvariants3d transformed(const SpMat& P) const;
  /// The inertia loads of the frame's rigid accelerations (nf x 12): int rho N^T dV (the
  /// columns of S-bar^T, a translation) and int rho N_l^T u0_k dV (row l of
  /// positionShape[k], column 3 + 3 k + l: the linear fields W u0 of the rotation's
  /// accelerations alpha x u0 + omega x (omega x u0)). Their static responses are the
  /// inertia modes (withStaticModes, bodies/modal_reduction.hpp).
  MatX inertiaLoads() const;

 private:
  /// S_lk = S_kl^T (k < l) to 1e-10 max |m_ff|.
  void validateTransposedPairs(const std::string& owner) const;
  /// Each of `pairs` absent or nf x nf, finite, symmetric, and pairs[l][k] = pairs[k][l]
  /// (`name`: the invariant's name for the message).
  void validateSymmetricPairs(const std::array<std::array<SpMat, 3>, 3>& pairs, std::string (*name)(int, int),
                              const std::string& owner) const;
  /// The second moment symmetric positive semi-definite, m tr(J) >= |first moment|^2.
  void validateSecondMoment(const std::string& owner) const;
};

}  // namespace flexmbd
