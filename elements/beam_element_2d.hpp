/// @file
/// Planar beam element (Euler-Bernoulli, Rayleigh or Timoshenko) of the floating frame of reference formulation
/// (Doc003; Shabana2005, ch. 6-7).
#pragma once

#include <Eigen/Core>

#include "core/types.hpp"
#include "elements/beam_section.hpp"
#include "elements/beam_strain_energy.hpp"

namespace flexmbd {

/// Two nodes; per node three coordinates in the element frame: axial displacement,
/// transverse displacement, slope. The element lies along its own x axis from `start`
/// to `end` (body frame); its intermediate element frame is parallel to it, so the
/// constant transformation from body-frame nodal displacements (ux, uy, psi) to element
/// coordinates is T = diag(R(beta)^T, 1, R(beta)^T, 1) (Doc003, C^ij).
///
/// Everything constant is computed once, at construction, as the x-y restriction of the
/// spatial BeamElement3d along the element's axis (its coordinates u, v, tz; one element
/// code for planar and spatial): 5-point Gauss-Legendre quadrature, exact for
/// polynomials up to degree 9 (the integrands here reach 6). The strain energy is
/// BeamStrainEnergy, shared with the spatial element.
class BeamElement2d {
 public:
  using Vec6 = Eigen::Matrix<double, 6, 1>;
  using Row6 = Eigen::Matrix<double, 1, 6>;
  using Mat6 = Eigen::Matrix<double, 6, 6>;
  using Mat26 = Eigen::Matrix<double, 2, 6>;

  /// @throws InputError naming `owner` if the element has zero length or the section
  /// is invalid (Timoshenko: without shear modulus and shear factor).
  BeamElement2d(const Vec2& start, const Vec2& end, const BeamSection& section,
                const std::string& owner, BeamTheory theory = BeamTheory::EulerBernoulli);

  double length() const { return l_; }
  double angle() const { return beta_; }  ///< of the element axis in the body frame
  const Vec2& start() const { return start_; }
  const BeamSection& section() const { return section_; }
  BeamTheory theory() const { return theory_; }
  /// phi = 12 EI / (kappa G A l^2) of a Timoshenko element (Przemieniecki1968, sec. 5.6;
  /// the spatial element's BeamShear::y); 0 otherwise.
  double shear() const { return shear_; }
  /// Body-frame nodal displacements -> element coordinates (6 x 6, constant).
  const Mat6& transformation() const { return T_; }

  /// Shape functions S(xi), xi = x / l (Doc003; `phi` = shear(): Timoshenko's
  /// interdependent interpolation, BeamElement3d; phi = 0):
  ///   w_x = [1-xi, 0, 0, xi, 0, 0] e,
  ///   w_y = [0, 1-3xi^2+2xi^3, l(xi-2xi^2+xi^3), 0, 3xi^2-2xi^3, l(xi^3-xi^2)] e.
  static Mat26 shape(double xi, double l, double phi = 0.0);
  /// d w_y / dx (slope), d2 w_y / dx2 (curvature), d w_x / dx (axial strain) rows.
  static Row6 slopeShape(double xi, double l, double phi = 0.0);
  static Row6 curvatureShape(double xi, double l, double phi = 0.0);
  static Row6 axialStrainShape(double l);
  /// The section rotation psi(xi) (1 x 6): the slope v' (phi = 0), Timoshenko's
  /// interpolated rotation otherwise. What a joint on the section turns with.
  static Row6 rotationShape(double xi, double l, double phi = 0.0);

  // ----- inertia shape integrals, element frame (Doc003) -------------------------
  double mass() const { return mass_; }           ///< rho A l
  const Mat26& sBar() const { return sBar_; }     ///< S-bar = int rho S dV
  const Mat26& sX() const { return sX_; }         ///< int rho x S dV (x along the element)
  const Mat6& sXX() const { return sXX_; }        ///< S_xx = int rho S_x^T S_x dV
  const Mat6& sYY() const { return sYY_; }        ///< S_yy = int rho S_y^T S_y dV
  const Mat6& sXY() const { return sXY_; }        ///< S_xy = int rho S_x^T S_y dV
  /// int rho y S dV (y across the element; zero for Euler-Bernoulli, whose field is the
  /// centre line's): row x = -rho I int psi under Rayleigh and Timoshenko, which turn the
  /// sections by psi (S_x gains -y psi).
  const Mat26& sY() const { return sY_; }
  /// int rho y^2 dV = rho I l: the sections' own second moment (Rayleigh, Timoshenko;
  /// zero for Euler-Bernoulli).
  double sectionMoment() const { return sectionMoment_; }
  /// R = -rho I int psi^T psi dx (6 x 6): the second-order change of int rho |u0 + u|^2 dV
  /// by the sections' rotation (points on circles; BeamElement3d::sectionRotationMoment's
  /// R_yy in the plane); zero for Euler-Bernoulli.
  const Mat6& sectionRotationMoment() const { return rYY_; }
  /// Linear stiffness (axial EA/l and Hermite bending EI/l^3 blocks), element frame.
  const Mat6& stiffness() const { return K_; }

  /// G = int_0^l b^T b dx, b = slopeShape (constant 6 x 6; transverse block only): the
  /// slope-shape integral of the membrane strain, (1/2) int v'^2 dx = e^T G e / 2.
  const Mat6& slopeIntegral() const { return G_; }

  /// Strain energy U(e) = EA l eps^2 / 2 + int EI kappa^2 / 2 dx with the membrane strain
  /// eps = u' (linear model) or, with geometric stiffening, the element-averaged
  /// second-order strain eps_m = u' + (1/2l) int_0^l v'^2 dx = a e + e^T G e / (2l)
  /// (constant along the element). The pointwise u' + v'^2/2 cannot vanish in bending
  /// with a linear u and a cubic v and locks coarse meshes (membrane locking,
  /// StolarskiBelytschko1982; docs/flexible-bodies.md); the averaged strain is the standard remedy.
  double strainEnergy(const Vec6& e, bool stiffening) const;
  /// dU/de and d2U/de2 (for the linear model: K e and K).
  Vec6 strainEnergyGradient(const Vec6& e, bool stiffening) const;
  Mat6 strainEnergyHessian(const Vec6& e, bool stiffening) const;
  /// Membrane strain: u' (linear) or the averaged eps_m (stiffening), as above.
  double membraneStrain(const Vec6& e, bool stiffening) const;
  /// Axial force N = EA eps (constant along the element) and bending moment M = EI kappa
  /// at xi (Przemieniecki1968).
  Vec2 sectionForces(const Vec6& e, double xi, bool stiffening) const;

 private:
  Vec2 start_;
  double l_ = 0.0, beta_ = 0.0;
  BeamSection section_;
  BeamTheory theory_ = BeamTheory::EulerBernoulli;
  double shear_ = 0.0;
  Mat6 T_;
  double mass_ = 0.0, sectionMoment_ = 0.0;
  Mat26 sBar_, sX_, sY_;
  Mat6 sXX_, sYY_, sXY_, K_, rYY_;
  Mat6 G_;  // int b^T b dx
  BeamStrainEnergy<6> energy_;
};

}  // namespace flexmbd
