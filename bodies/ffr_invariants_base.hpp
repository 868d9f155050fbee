/// @file
/// What the planar and spatial invariants of a floating-frame-of-reference body share:
/// the attachment points, the mass, first moment, S-bar, m_ff, K_ff, D_ff, their checks
/// and their change of elastic coordinates. FfrInvariants (planar, bodies/ffr_invariants.hpp)
/// and FfrInvariants3d (spatial, bodies/ffr_invariants_3d.hpp) add their own inertia terms.
#pragma once

#include <string>
#include <vector>

#include "core/types.hpp"

namespace flexmbd {

/// A material point of the body where joints and forces attach (a node): undeformed
/// position u0 (body frame), u = u0 + N q_f (Doc003), and the small rotation of its cross-section
/// Ntheta q_f: one angle psi in the plane (Dim 2), three body-axis components in space
/// (Dim 3; the section's axes are (I + skew(theta)) to first order in q_f).
template <int Dim>
struct FfrPointT {
  static constexpr int kRotations = Dim == 2 ? 1 : 3;  ///< rotation components of a section
  Eigen::Matrix<double, Dim, 1> position = Eigen::Matrix<double, Dim, 1>::Zero();
  Eigen::Matrix<double, Dim, Eigen::Dynamic> shape;                ///< N, Dim x nf
  Eigen::Matrix<double, kRotations, Eigen::Dynamic> rotationShape;  ///< Ntheta, 1 x nf or 3 x nf
};

/// With u(P) = u0(P) + N(P) q_f the body-frame position of a material point P, the
/// integrals over the undeformed body that every FFR body has (Doc003):
template <int Dim>
struct FfrInvariantsBase {
  using Point = FfrPointT<Dim>;
  double mass = 0.0;                                               ///< m = int rho dV
  Eigen::Matrix<double, Dim, 1> firstMoment = Eigen::Matrix<double, Dim, 1>::Zero();  ///< int rho u0 dV
  Eigen::Matrix<double, Dim, Eigen::Dynamic> sBar;                 ///< S-bar = int rho N dV (Dim x nf; Doc003)
  // Sparse: banded for nodal beam meshes (the body's cost stays linear in its size),
  // full for modal models.
  SpMat mff;                                                       ///< m_ff = int rho N^T N dV (Doc003)
  SpMat kff;                                                       ///< stiffness under the reference conditions
  SpMat dff;                                                       ///< damping
  std::vector<Point> points;                                       ///< attachment points (nodes)

  int numElastic() const { return static_cast<int>(mff.rows()); }
  /// The elastic coordinates the point's shape and rotation shape depend on (ascending).
  static std::vector<int> support(const Point& p);

 protected:
  // The stages of validate() in the derived invariants, each an InputError naming
  // `owner` and the offending invariant.
  /// mass > 0, finite first moment.
  void validateMass(const std::string& owner) const;
  /// Sizes of m_ff, S-bar, K_ff, D_ff.
  void validateSizes(const std::string& owner) const;
  /// Finite entries of m_ff, K_ff, D_ff, S-bar.
  void validateFinite(const std::string& owner) const;
  /// Symmetric m_ff, K_ff, D_ff.
  void validateSymmetry(const std::string& owner) const;
  /// m_ff and K_ff positive definite (K_ff: no rigid mode left), D_ff positive semi-definite.
  void validateDefiniteness(const std::string& owner) const;
  /// Every point's shape and rotation shape nf columns, finite.
  void validatePoints(const std::string& owner) const;
  /// The shared invariants of `out` for q_f = P eta.
  void transformInto(const SpMat& P, FfrInvariantsBase& out) const;
};

extern template struct FfrInvariantsBase<2>;
extern template struct FfrInvariantsBase<3>;

}  // namespace flexmbd
