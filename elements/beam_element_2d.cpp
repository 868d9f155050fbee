#include "elements/beam_element_2d.hpp"

#include <cmath>

#include "core/errors.hpp"
#include "elements/beam_element_3d.hpp"

namespace flexmbd {
namespace {

// The planar element is the spatial BeamElement3d restricted to its x-y plane: its six
// coordinates (u1, v1, psi1, u2, v2, psi2) are the spatial element's (u, v, tz) at both
// nodes (psi = v' = tz), every integral and matrix the corresponding block (one element
// code for planar and spatial).
constexpr int kInPlane[6] = {0, 1, 5, 6, 7, 11};

BeamElement2d::Mat6 inPlane(const BeamElement3d::Mat12& A) {
  BeamElement2d::Mat6 B;
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) B(i, j) = A(kInPlane[i], kInPlane[j]);
  }
  return B;
}

BeamElement2d::Row6 inPlane(const BeamElement3d::Row12& r) {
  BeamElement2d::Row6 b;
  for (int j = 0; j < 6; ++j) b(j) = r(kInPlane[j]);
  return b;
}

/// Rows x, y of a spatial 3 x 12 block, in-plane columns.
BeamElement2d::Mat26 inPlane(const BeamElement3d::Mat3x12& A) {
  BeamElement2d::Mat26 B;
  for (int k = 0; k < 2; ++k) B.row(k) = inPlane(BeamElement3d::Row12(A.row(k)));
  return B;
}

/// The spatial section of a planar one: Iz = I for the x-y plane, G and kappa_y its
/// shear (Timoshenko); the out-of-plane properties (Iy, J, kappa_z) only enter
/// coordinates the planar element drops, so any valid values do (Iy = J = I, kappa_z = 1,
/// G = E / 2 where not given).
BeamSection3d planarSection3d(const BeamSection& s) {
  BeamSection3d t;
  t.area = s.area;
  t.inertiaY = t.inertiaZ = t.torsionConstant = s.inertia;
  t.youngsModulus = s.youngsModulus;
  t.shearModulus = s.shearModulus > 0.0 ? s.shearModulus : 0.5 * s.youngsModulus;
  t.density = s.density;
  t.damping = s.damping;
  t.shearFactorY = s.shearFactor;
  t.shearFactorZ = 1.0;
  return t;
}

}  // namespace

BeamElement2d::BeamElement2d(const Vec2& start, const Vec2& end, const BeamSection& section,
                             const std::string& owner, BeamTheory theory)
    : start_(start), section_(section), theory_(theory) {
  section.validate(owner);
  if (theory == BeamTheory::Timoshenko && !(section.shearModulus > 0.0)) {
    throw InputError(owner + ": a Timoshenko beam needs the section's shear_modulus, got " +
                     std::to_string(section.shearModulus));
  }
  if (theory == BeamTheory::Timoshenko && !(section.shearFactor > 0.0)) {
    throw InputError(owner + ": a Timoshenko beam needs the section's shear_factor (e.g. 5/6 for a rectangle), got " +
                     std::to_string(section.shearFactor));
  }
  for (int k = 0; k < 2; ++k) {
    requireFinite(start[k], owner + ": node coordinate");
    requireFinite(end[k], owner + ": node coordinate");
  }
  const Vec2 d = end - start;
  l_ = d.norm();
  if (!(l_ > 1e-12 * (1.0 + start.norm()))) {
    throw InputError(owner + ": element has zero length (its two nodes coincide); expected distinct nodes");
  }
  beta_ = std::atan2(d.y(), d.x());
  const Mat2 Rt = rotation(beta_).transpose();
  T_.setZero();
  T_.block<2, 2>(0, 0) = Rt;
  T_(2, 2) = 1.0;
  T_.block<2, 2>(3, 3) = Rt;
  T_(5, 5) = 1.0;

  // the spatial element along its own x axis (element frame = its frame), restricted
  const BeamElement3d el(Vec3::Zero(), Vec3(l_, 0.0, 0.0), Vec3::UnitY(), planarSection3d(section), owner, theory);
  shear_ = el.shear().y;
  mass_ = el.mass();
  sBar_ = inPlane(el.sBar());
  sX_ = inPlane(el.positionShapeIntegral(0));
  sY_ = inPlane(el.positionShapeIntegral(1));
  // the sections' own inertia and second-order rotation, where the theory turns them
  sectionMoment_ = theory == BeamTheory::EulerBernoulli ? 0.0 : el.secondMoment()(1, 1);  // rho I l
  rYY_ = inPlane(el.sectionRotationMoment(1, 1));
  sXX_ = inPlane(el.sKL(0, 0));
  sYY_ = inPlane(el.sKL(1, 1));
  sXY_ = inPlane(el.sKL(0, 1));
  K_ = inPlane(el.stiffness());
  G_ = inPlane(el.slopeIntegral());  // transverse block: the classical (1/(30 l)) [36, 3l, ...]
  Mat6 Kb = K_;  // bending: the axial entries zero
  Kb(0, 0) = Kb(3, 3) = Kb(0, 3) = Kb(3, 0) = 0.0;
  energy_ = BeamStrainEnergy<6>(axialStrainShape(l_), G_, K_, Kb, section.axialStiffness(), l_);
}

BeamElement2d::Mat26 BeamElement2d::shape(double xi, double l, double phi) {
  return inPlane(BeamElement3d::shape(xi, l, BeamShear{phi, 0.0}));
}

BeamElement2d::Row6 BeamElement2d::slopeShape(double xi, double l, double phi) {
  return inPlane(BeamElement3d::slopeShapeY(xi, l, BeamShear{phi, 0.0}));
}

BeamElement2d::Row6 BeamElement2d::curvatureShape(double xi, double l, double phi) {
  return inPlane(BeamElement3d::curvatureShapeY(xi, l, BeamShear{phi, 0.0}));
}

BeamElement2d::Row6 BeamElement2d::rotationShape(double xi, double l, double phi) {
  return inPlane(BeamElement3d::Row12(BeamElement3d::rotationShape(xi, l, BeamShear{phi, 0.0}).row(2)));  // tz
}

BeamElement2d::Row6 BeamElement2d::axialStrainShape(double l) { return inPlane(BeamElement3d::axialStrainShape(l)); }

// The strain energy: BeamStrainEnergy (elements/beam_strain_energy.hpp), shared with the
// spatial element.

double BeamElement2d::membraneStrain(const Vec6& e, bool stiffening) const {
  return energy_.membraneStrain(e, stiffening);
}

double BeamElement2d::strainEnergy(const Vec6& e, bool stiffening) const { return energy_.energy(e, stiffening); }

BeamElement2d::Vec6 BeamElement2d::strainEnergyGradient(const Vec6& e, bool stiffening) const {
  return energy_.gradient(e, stiffening);
}

BeamElement2d::Mat6 BeamElement2d::strainEnergyHessian(const Vec6& e, bool stiffening) const {
  return energy_.hessian(e, stiffening);
}

Vec2 BeamElement2d::sectionForces(const Vec6& e, double xi, bool stiffening) const {
  // N = EA eps_m (constant per element, consistent with U), M = EI kappa(xi)
  return Vec2(section_.axialStiffness() * membraneStrain(e, stiffening),
              section_.bendingStiffness() * curvatureShape(xi, l_, shear_).dot(e));
}

}  // namespace flexmbd
