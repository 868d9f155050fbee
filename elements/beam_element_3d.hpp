/// @file
/// Spatial beam element (Euler-Bernoulli, Rayleigh or Timoshenko) of the floating frame of reference formulation
/// (Doc003; Shabana2005, ch. 5-6; Przemieniecki1968, sec. 5.6). docs/spatial-flexible.md.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>

#include "core/types.hpp"
#include "elements/beam_section.hpp"
#include "elements/beam_strain_energy.hpp"

namespace flexmbd {

/// Section forces of a spatial beam at one cross-section, element frame: the resultant
/// force and moment that the part beyond the section (larger x) exerts on the part
/// before it, i.e. the stress resultants on the face with outward normal +x
/// (Przemieniecki1968).
struct BeamSectionForces3d {
  double N = 0.0;   ///< axial force EA eps_m, N (tension > 0; constant per element)
  double Qy = 0.0;  ///< shear force along y, N: -dMz/dx = -EIz v''' (constant per element)
  double Qz = 0.0;  ///< shear force along z, N: +dMy/dx = -EIy w''' (constant per element)
  double Mx = 0.0;  ///< torque GJ tx', N m (constant per element)
  double My = 0.0;  ///< bending moment about y, N m: EIy ty' = -EIy w'' (linear in xi)
  double Mz = 0.0;  ///< bending moment about z, N m: EIz tz' = EIz v'' (linear in xi)
};

/// Two nodes; per node six coordinates. Element frame: origin at `start`, x axis along
/// end - start, y axis the `yHint` made orthogonal to x, z = x cross y; C (3 x 3,
/// `rotation()`) has these axes, in the body frame, as its columns, so x_body = start + C x_el.
///
/// Coordinates. Body-frame nodal coordinates q (12): per node (ux, uy, uz, thx, thy, thz),
/// displacement and small rotation about the body axes. Element coordinates (12)
///   e = [u1 v1 w1 tx1 ty1 tz1  u2 v2 w2 tx2 ty2 tz2] = T q,
/// T = blockdiag(C^T, C^T, C^T, C^T) (`transformation()`, constant; Doc003's C^ij):
/// u, v, w displacements along the element's x, y, z; tx twist, ty, tz small rotations
/// about the element's y and z axes (ty = -dw/dx, tz = dv/dx).
///
/// Field (xi = x / l, element frame): centre line S_c(xi) e (3 x 12, `shape()`; Doc003's
/// S in each bending plane; Przemieniecki1968, sec. 5.6),
///   w_x = (1-xi) u1 + xi u2,
///   w_y = h1 v1 + h2 tz1 + h3 v2 + h4 tz2,
///   w_z = h1 w1 - h2 ty1 + h3 w2 - h4 ty2,
///   h1 = 1 - 3xi^2 + 2xi^3, h2 = l (xi - 2xi^2 + xi^3), h3 = 3xi^2 - 2xi^3, h4 = l (xi^3 - xi^2),
/// twist tx(xi) = (1-xi) tx1 + xi tx2 (`twistShape()`). Under BeamTheory::Timoshenko the
/// bending fields are the interdependent interpolation of the shear-flexible beam
/// (`BeamShear`, phi = 12 EI / (kappa G A l^2); phi = 0 gives the cubics above): the
/// nodal ty, tz are then the sections' own rotations, not the slopes, the shear strain
/// gamma = v' - tz is constant along the element and the stiffness is Przemieniecki's
/// shear-deformable matrix (Przemieniecki1968, sec. 5.6; exact for end loads, free of shear
/// locking as l / h grows).
/// A material point (x, y, z) of the
/// element (y, z in the section) moves by
///   u = S(x, y, z) e = S_c e + tx e_x cross (0, y, z) = S_c e + (0, -z tx, y tx)  (`pointShape()`).
/// The rotation of the section by the twist is kept (it gives the torsional inertia
/// rho Ip int tx^2 dx, without which the torsional mass would vanish). The axial
/// displacement -y v' - z w' of the section's points by the bending slopes (the rotary
/// inertia of bending) is kept under BeamTheory::Rayleigh and neglected under
/// Euler-Bernoulli (the default), as in the planar BeamElement2d (centre-line field
/// only), so a spatial Euler-Bernoulli element in a plane has exactly the planar
/// element's inertia. Timoshenko keeps the sections' rotation as Rayleigh does, by
/// their own rotation. Warping is neglected.
///
/// Everything constant is computed once, at construction: along x by 5-point
/// Gauss-Legendre quadrature (exact to degree 9; the integrands here reach 6), over the
/// section analytically (int dA = A, int y dA = int z dA = int yz dA = 0, int y^2 dA = Iz,
/// int z^2 dA = Iy). All inertia integrals are in the ELEMENT frame with origin at the
/// start node, over the element's volume; x0 = (x, y, z) is a point's undeformed position
/// in that frame. Indices k, l in {0, 1, 2} stand for x, y, z. No allocation after
/// construction; every method is const.
class BeamElement3d {
 public:
  using Vec12 = Eigen::Matrix<double, 12, 1>;
  using Row12 = Eigen::Matrix<double, 1, 12>;
  using Mat12 = Eigen::Matrix<double, 12, 12>;
  using Mat3x12 = Eigen::Matrix<double, 3, 12>;

  /// @throws InputError naming `owner` if a coordinate is not finite, the element has zero
  /// length, `yHint` is zero, not finite, or within 1e-6 rad of the element axis, or the
  /// section is invalid.
  BeamElement3d(const Vec3& start, const Vec3& end, const Vec3& yHint, const BeamSection3d& section,
                const std::string& owner, BeamTheory theory = BeamTheory::EulerBernoulli);

  double length() const { return l_; }                     ///< l, m
  const Vec3& start() const { return start_; }              ///< start node, body frame (element origin)
  const Vec3& end() const { return end_; }                  ///< end node, body frame
  const BeamSection3d& section() const { return section_; }
  BeamTheory theory() const { return theory_; }
  /// phi_y, phi_z of a Timoshenko element (BeamSection3d::shearFlexibility); zero otherwise.
  const BeamShear& shear() const { return shear_; }
  /// C (3 x 3): columns = element x, y, z axes in the body frame; x_body = start + C x_el.
  const Mat3& rotation() const { return C_; }
  /// T (12 x 12, constant) = blockdiag(C^T, C^T, C^T, C^T): body-frame nodal coordinates
  /// q -> element coordinates e = T q (Doc003, C^ij).
  const Mat12& transformation() const { return T_; }

  // ----- shape functions (element frame, xi = x / l) ------------------------------
  // `shear`: the element's shear flexibility (`shear()`); zero, the default, for
  // Euler-Bernoulli and Rayleigh elements.
  /// Centre-line shape S_c(xi) (3 x 12): w = S_c e, as in the class comment.
  static Mat3x12 shape(double xi, double l, const BeamShear& shear = {});
  /// Twist tx(xi) = twistShape(xi) e (1 x 12): (1-xi) at tx1, xi at tx2.
  static Row12 twistShape(double xi);
  /// The cross-section's small rotation (tx, ty, tz)(xi) = rotationShape e (3 x 12,
  /// element axes): the twist, and the bending rotations ty = -w', tz = v' (Timoshenko:
  /// the interpolated section rotations). What a joint on the section turns with.
  static Mat3x12 rotationShape(double xi, double l, const BeamShear& shear = {});
  /// The section rotation of the inertia field phi(xi) = Phi e (3 x 12): rotationShape
  /// under Rayleigh and Timoshenko; under Euler-Bernoulli the twist only (rows y, z
  /// zero: its field does not turn the sections by the slopes).
  static Mat3x12 sectionRotationShape(double xi, double l, BeamTheory theory, const BeamShear& shear = {});
  /// Point shape S(xi, y, z) (3 x 12): S_c(xi) e + phi(xi) x (0, y, z), y, z in the
  /// section: S_c + rows (z ty - y tz, -z tx, y tx) (ty = tz = 0 under Euler-Bernoulli).
  static Mat3x12 pointShape(double xi, double y, double z, double l,
                            BeamTheory theory = BeamTheory::EulerBernoulli, const BeamShear& shear = {});
  /// d w_x / dx (1 x 12, constant): the axial strain row a.
  static Row12 axialStrainShape(double l);
  /// d tx / dx (1 x 12, constant): the twist rate row.
  static Row12 twistRateShape(double l);
  /// d w_y / dx and d w_z / dx (1 x 12): the slope rows (Euler-Bernoulli: tz(xi), -ty(xi)).
  static Row12 slopeShapeY(double xi, double l, const BeamShear& shear = {});
  static Row12 slopeShapeZ(double xi, double l, const BeamShear& shear = {});
  /// d2 w_y / dx2 = tz' and d2 w_z / dx2 = -ty' (1 x 12): the curvature rows.
  static Row12 curvatureShapeY(double xi, double l, const BeamShear& shear = {});
  static Row12 curvatureShapeZ(double xi, double l, const BeamShear& shear = {});
  /// The shear strains gamma_y = v' - tz and gamma_z = w' + ty (1 x 12, constant along
  /// the element; zero rows for shear = 0; Przemieniecki1968, sec. 5.6).
  static Row12 shearStrainShapeY(double l, const BeamShear& shear);
  static Row12 shearStrainShapeZ(double l, const BeamShear& shear);

  // ----- inertia shape integrals (element frame, origin at the start node) -------
  double mass() const { return mass_; }                       ///< m = int rho dV = rho A l, kg
  const Vec3& firstMoment() const { return firstMoment_; }    ///< int rho x0 dV = (m l / 2, 0, 0), kg m
  /// int rho x0 x0^T dV (3 x 3), kg m^2 = diag(m l^2 / 3, rho Iz l, rho Iy l). Not the
  /// inertia tensor: that is tr(J) I - J of this J (Shabana2005, eq. 5.110).
  const Mat3& secondMoment() const { return secondMoment_; }
  /// S-bar = int rho S dV (3 x 12), kg (Doc003; the twist term integrates to zero).
  const Mat3x12& sBar() const { return sBar_; }
  /// S_kl = int rho S_k^T S_l dV (12 x 12), kg, S_k = row k of the point shape S (Doc003);
  /// S_lk = S_kl^T. S_yy and S_zz carry the torsional inertia rho Iy, rho Iz int tx^T tx.
  /// @throws std::out_of_range unless 0 <= k, l <= 2.
  const Mat12& sKL(int k, int l) const;
  /// m_ff of the element = S_xx + S_yy + S_zz = int rho S^T S dV (12 x 12, kg; Doc003): the
  /// consistent mass matrix in element coordinates (body frame: T^T m_ff T).
  const Mat12& massMatrix() const { return massMatrix_; }
  /// int rho x0_k S dV (3 x 12), kg m: row l is int rho x0_k S_l dV, the coupling of the
  /// undeformed position to the deformation. @throws std::out_of_range unless 0 <= k <= 2.
  const Mat3x12& positionShapeIntegral(int k) const;
  /// int rho x0~ S dV (3 x 12), kg m: int rho x0 cross (S e) dV = this * e. Row 0 is
  /// int rho (y S_z - z S_y) dV = rho Ip int tx dx (torsion), rows 1, 2 the bending terms.
  const Mat3x12& skewPositionShapeIntegral() const { return skewXS_; }
  /// int rho x0^T S dV (1 x 12), kg m: int rho x0 . (S e) dV = this * e.
  const Row12& positionDotShapeIntegral() const { return dotXS_; }
  /// R_kl (12 x 12, symmetric; R_lk = R_kl), kg: the second-order change of
  /// int rho x x^T dV by the rotation of the cross-sections, e^T R_kl e. A section
  /// turned by phi (sectionRotationShape) moves its points on circles, u = (R(phi) - 1) r:
  /// to second order u2 = (1/2) phi~ phi~ r beside the first-order phi x r of
  /// pointShape(). Over the section int rho (x0 u2^T + u2 x0^T) dA gives (sym as below)
  ///   R_yy = -rho Iz int (tx^2 + tz^2), R_zz = -rho Iy int (tx^2 + ty^2), R_xx = 0,
  ///   R_xy = rho Iz int tx ty / 2, R_xz = rho Iy int tx tz / 2, R_yz = rho Ip int ty tz / 2;
  /// under Euler-Bernoulli (ty = tz = 0) R_yy = -rho Iz int tx^T tx dx,
  /// R_zz = -rho Iy int tx^T tx dx, others zero,
  /// so the polar moment (J_yy + J_zz of a shaft along x) does not change by the twist
  /// and a section's second moments turn with it (Iz cos^2 + Iy sin^2). Without it a
  /// spinning shaft loses torsional stiffness Omega^2 rho Ip per length.
  /// The body adds it to int rho u u^T dV only (its rotational inertia); the first-order
  /// field S is unchanged. @throws std::out_of_range unless 0 <= k, l <= 2.
  const Mat12& sectionRotationMoment(int k, int l) const;
  /// H_i (12 x 12, symmetric), kg m^2: int rho (x0 x u2)_i dV = e^T H_i e / 2, the
  /// angular momentum coupling of the second-order rotation (the body's kinetic energy
  /// gains w . (e^T H_i e')_i). Zero under Euler-Bernoulli (twist alone moves a section's
  /// points radially: x0 x u2 integrates to zero); under Rayleigh
  ///   H_x = rho (Iz - Iy) sym(ty, tz), H_y = rho Iy sym(tx, tz), H_z = -rho Iz sym(tx, ty),
  /// sym(a, b) = int (a^T b + b^T a) / 2 dx. @throws std::out_of_range unless 0 <= i <= 2.
  const Mat12& sectionRotationCoupling(int i) const;

  // ----- stiffness and strain energy (element frame) -----------------------------
  /// Linear stiffness K (12 x 12), the classic Przemieniecki matrix (Przemieniecki1968,
  /// sec. 5.6): axial EA/l, torsion
  /// GJ/l, bending EIz/l^3 (x-y plane: v, tz) and EIy/l^3 (x-z plane: w, ty, with
  /// ty = -w'); Timoshenko: the shear-deformable bending blocks (factor 1/(1 + phi),
  /// (4 + phi) l^2 and (2 - phi) l^2 on the rotations), e^T K e / 2 = int (EI psi'^2 +
  /// kappa G A gamma^2) / 2 dx. Body frame: T^T K T. Damping D = section().damping K.
  const Mat12& stiffness() const { return K_; }
  /// G = int_0^l (by^T by + bz^T bz) dx (12 x 12, constant), by, bz = slope rows: the
  /// slope integral of the membrane strain, (1/2) int (v'^2 + w'^2) dx = e^T G e / 2;
  /// EA eps G is the geometric stiffness of the axial force.
  const Mat12& slopeIntegral() const { return G_; }

  /// Strain energy, J: U(e) = EA l eps^2 / 2 + int (EIz v''^2 + EIy w''^2 + GJ tx'^2) / 2 dx,
  /// with the membrane strain eps = u' (linear model: U = e^T K e / 2) or, with geometric
  /// stiffening, the element-averaged second-order strain
  ///   eps_m = u' + (1/2l) int_0^l (v'^2 + w'^2) dx = a e + e^T G e / (2l)
  /// (constant along the element; locking-free: the pointwise u' + (v'^2 + w'^2)/2
  /// cannot vanish in bending with a linear u and cubic v, w and locks coarse meshes,
  /// StolarskiBelytschko1982; docs/flexible-bodies.md). The second-order twist (Wagner) term
  /// is not included.
  double strainEnergy(const Vec12& e, bool stiffening) const;
  /// dU/de (12) and d2U/de2 (12 x 12): K e and K for the linear model.
  Vec12 strainEnergyGradient(const Vec12& e, bool stiffening) const;
  Mat12 strainEnergyHessian(const Vec12& e, bool stiffening) const;
  /// Membrane strain (dimensionless): u' (linear) or the averaged eps_m (stiffening).
  double membraneStrain(const Vec12& e, bool stiffening) const;
  /// Section forces at xi in [0, 1] (BeamSectionForces3d for the sign conventions).
  BeamSectionForces3d sectionForces(const Vec12& e, double xi, bool stiffening) const;

 private:
  Vec3 start_, end_;
  double l_ = 0.0;
  BeamSection3d section_;
  Mat3 C_;
  Mat12 T_;
  double mass_ = 0.0;
  Vec3 firstMoment_;
  Mat3 secondMoment_;
  Mat3x12 sBar_;
  std::array<Mat12, 9> sKL_;  // S_kl at index 3 k + l
  std::array<Mat12, 9> rKL_;  // R_kl at index 3 k + l (sectionRotationMoment)
  std::array<Mat12, 3> hI_;   // H_i (sectionRotationCoupling)
  BeamTheory theory_ = BeamTheory::EulerBernoulli;
  BeamShear shear_;  // zero unless Timoshenko
  Mat12 massMatrix_;
  std::array<Mat3x12, 3> xS_;  // int rho x0_k S dV
  Mat3x12 skewXS_;
  Row12 dotXS_;
  Mat12 K_;
  Mat12 G_;  // int (by^T by + bz^T bz) dx
  BeamStrainEnergy<12> energy_;
};

}  // namespace flexmbd
