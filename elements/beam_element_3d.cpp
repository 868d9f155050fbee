#include "elements/beam_element_3d.hpp"

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "core/errors.hpp"

namespace flexmbd {
namespace {

// 5-point Gauss-Legendre rule mapped to [0, 1]: exact up to degree 9.
constexpr std::array<double, 5> kGaussXi = {
    0.5 - 0.5 * 0.9061798459386640, 0.5 - 0.5 * 0.5384693101056831, 0.5,
    0.5 + 0.5 * 0.5384693101056831, 0.5 + 0.5 * 0.9061798459386640};
constexpr std::array<double, 5> kGaussW = {0.5 * 0.2369268850561891, 0.5 * 0.4786286704993665,
                                           0.5 * 0.5688888888888889, 0.5 * 0.4786286704993665,
                                           0.5 * 0.2369268850561891};

// A y hint within this angle (rad) of the element axis does not define the y axis.
constexpr double kParallelHint = 1e-6;

// Coordinate indices within e: per node (u, v, w, tx, ty, tz), node 2 at +6.
constexpr int kU = 0, kV = 1, kW = 2, kTx = 3, kTy = 4, kTz = 5, kNode2 = 6;

}  // namespace

BeamElement3d::BeamElement3d(const Vec3& start, const Vec3& end, const Vec3& yHint,
                             const BeamSection3d& section, const std::string& owner, BeamTheory theory)
    : start_(start), end_(end), section_(section), theory_(theory) {
  section.validate(owner);
  for (int k = 0; k < 3; ++k) {
    requireFinite(start[k], owner + ": node coordinate");
    requireFinite(end[k], owner + ": node coordinate");
    requireFinite(yHint[k], owner + ": y axis hint");
  }
  const Vec3 d = end - start;
  l_ = d.norm();
  if (!(l_ > 1e-12 * (1.0 + start.norm()))) {
    throw InputError(owner + ": element has zero length (its two nodes coincide); expected distinct nodes");
  }
  const Vec3 ex = d / l_;
  const double hint = yHint.norm();
  if (!(hint > 0.0)) {
    throw InputError(owner + ": y axis hint is zero; expected a direction not parallel to the element axis");
  }
  const Vec3 yPerp = yHint - yHint.dot(ex) * ex;  // Gram-Schmidt (GolubVanLoan2013): y = hint - (hint . x) x
  if (!(yPerp.norm() > kParallelHint * hint)) {
    throw InputError(owner + ": y axis hint is parallel to the element axis (end - start); expected a "
                             "direction across the element");
  }
  const Vec3 ey = yPerp.normalized();
  C_.col(0) = ex;
  C_.col(1) = ey;
  C_.col(2) = ex.cross(ey);  // z = x cross y
  T_.setZero();
  for (int n = 0; n < 4; ++n) T_.block<3, 3>(3 * n, 3 * n) = C_.transpose();  // e = T q (Doc003, C^ij)

  const double l = l_, rhoA = section.massPerLength();
  if (theory == BeamTheory::Timoshenko) shear_ = section.shearFlexibility(l, owner);
  const double rIy = section.density * section.inertiaY, rIz = section.density * section.inertiaZ;
  mass_ = rhoA * l;
  firstMoment_.setZero();
  secondMoment_.setZero();
  sBar_.setZero();
  for (Mat12& s : sKL_) s.setZero();
  for (Mat12& r : rKL_) r.setZero();
  for (Mat12& h : hI_) h.setZero();
  for (Mat3x12& s : xS_) s.setZero();
  G_.setZero();
  for (size_t g = 0; g < kGaussXi.size(); ++g) {
    const double xi = kGaussXi[g], w = kGaussW[g] * l, x = xi * l;  // dx = l dxi
    const Mat3x12 Sc = shape(xi, l, shear_);
    const Mat3x12 Phi = sectionRotationShape(xi, l, theory, shear_);
    const Row12 px = Phi.row(0), py = Phi.row(1), pz = Phi.row(2);  // tx, ty, tz
    firstMoment_.x() += w * rhoA * x;                     // int rho x dV
    secondMoment_(0, 0) += w * rhoA * x * x;              // int rho x^2 dV
    secondMoment_(1, 1) += w * rIz;                       // int rho y^2 dV = rho Iz l
    secondMoment_(2, 2) += w * rIy;                       // int rho z^2 dV = rho Iy l
    sBar_ += (w * rhoA) * Sc;                             // int rho S dV (y, z terms vanish)
    for (int k = 0; k < 3; ++k) {
      for (int m = k; m < 3; ++m) {
        sKL_[3 * k + m] += (w * rhoA) * Sc.row(k).transpose() * Sc.row(m);  // rho A int Sc_k^T Sc_l dx
      }
    }
    // the section's rotation phi x (0, y, z): S_x += z ty - y tz, S_y -= z tx, S_z += y tx,
    // over the section int y^2 dA = Iz, int z^2 dA = Iy, int y dA = int z dA = int yz dA = 0
    sKL_[0] += w * (rIy * py.transpose() * py + rIz * pz.transpose() * pz);  // S_xx
    sKL_[1] -= (w * rIy) * py.transpose() * px;                               // S_xy
    sKL_[2] -= (w * rIz) * pz.transpose() * px;                               // S_xz
    sKL_[4] += (w * rIy) * px.transpose() * px;                               // S_yy
    sKL_[8] += (w * rIz) * px.transpose() * px;                               // S_zz
    xS_[0] += (w * rhoA * x) * Sc;   // int rho x S dV
    xS_[1].row(0) -= (w * rIz) * pz;  // int rho y S_x dV = -rho Iz tz
    xS_[1].row(2) += (w * rIz) * px;  // int rho y S_z dV = rho Iz tx
    xS_[2].row(0) += (w * rIy) * py;  // int rho z S_x dV = rho Iy ty
    xS_[2].row(1) -= (w * rIy) * px;  // int rho z S_y dV = -rho Iy tx
    // second order, u2 = (1/2) phi~ phi~ r = (1/2) (phi (phi . r) - |phi|^2 r), r = (0, y, z):
    // J_kl += int rho (x0_k u2_l + u2_k x0_l) dV (R_kl) and int rho x0 x u2 dV (H_i)
    const auto sym = [](const Row12& a, const Row12& b) -> Mat12 {
      return 0.5 * (a.transpose() * b + b.transpose() * a);
    };
    rKL_[1] += (0.5 * w * rIz) * sym(px, py);  // R_xy: rho Iz tx ty / 2
    rKL_[2] += (0.5 * w * rIy) * sym(px, pz);  // R_xz: rho Iy tx tz / 2
    rKL_[4] -= (w * rIz) * (px.transpose() * px + pz.transpose() * pz);  // R_yy: -rho Iz (tx^2 + tz^2)
    rKL_[8] -= (w * rIy) * (px.transpose() * px + py.transpose() * py);  // R_zz: -rho Iy (tx^2 + ty^2)
    rKL_[5] += (0.5 * w * (rIy + rIz)) * sym(py, pz);                   // R_yz: rho Ip ty tz / 2
    hI_[0] += (w * (rIz - rIy)) * sym(py, pz);  // H_x: rho (Iz - Iy) ty tz
    hI_[1] += (w * rIy) * sym(px, pz);          // H_y: rho Iy tx tz
    hI_[2] -= (w * rIz) * sym(px, py);          // H_z: -rho Iz tx ty
    const Row12 by = slopeShapeY(xi, l, shear_), bz = slopeShapeZ(xi, l, shear_);
    G_ += w * (by.transpose() * by + bz.transpose() * bz);  // int (by^T by + bz^T bz) dx
  }
  // S_lk = S_kl^T and S_kk = S_kk^T exactly (the quadrature sums differ in the last bit)
  for (int k = 0; k < 3; ++k) {
    sKL_[4 * k] = (0.5 * (sKL_[4 * k] + sKL_[4 * k].transpose())).eval();
    for (int m = k + 1; m < 3; ++m) sKL_[3 * m + k] = sKL_[3 * k + m].transpose();
  }
  for (Mat12& r : rKL_) r = (0.5 * (r + r.transpose())).eval();  // symmetric exactly
  rKL_[3] = rKL_[1];  // R_lk = R_kl
  rKL_[6] = rKL_[2];
  rKL_[7] = rKL_[5];
  for (Mat12& h : hI_) h = (0.5 * (h + h.transpose())).eval();
  massMatrix_ = sKL_[0] + sKL_[4] + sKL_[8];  // m_ff = S_xx + S_yy + S_zz (Doc003)
  // x0 cross u = (y u_z - z u_y, z u_x - x u_z, x u_y - y u_x)
  skewXS_.row(0) = xS_[1].row(2) - xS_[2].row(1);
  skewXS_.row(1) = xS_[2].row(0) - xS_[0].row(2);
  skewXS_.row(2) = xS_[0].row(1) - xS_[1].row(0);
  dotXS_ = xS_[0].row(0) + xS_[1].row(1) + xS_[2].row(2);  // x0 . u

  // Stiffness, closed form (Przemieniecki1968, sec. 5.6):
  // axial EA/l, torsion GJ/l, bending EIz/((1 + phi_y) l^3), EIy/((1 + phi_z) l^3) with the
  // shear terms (4 + phi) l^2, (2 - phi) l^2 (phi = 0: Euler-Bernoulli's Hermite matrix).
  K_.setZero();
  const double ea = section.axialStiffness() / l, gj = section.torsionStiffness() / l;
  for (const auto& [dof, k] : {std::pair<int, double>{kU, ea}, std::pair<int, double>{kTx, gj}}) {
    K_(dof, dof) = K_(dof + kNode2, dof + kNode2) = k;
    K_(dof, dof + kNode2) = K_(dof + kNode2, dof) = -k;
  }
  const auto bendingMatrix = [l](double phi, int i, int j) {
    const double kb[4][4] = {{12, 6 * l, -12, 6 * l},
                             {6 * l, (4 + phi) * l * l, -6 * l, (2 - phi) * l * l},
                             {-12, -6 * l, 12, -6 * l},
                             {6 * l, (2 - phi) * l * l, -6 * l, (4 + phi) * l * l}};
    return kb[i][j] / (1.0 + phi);
  };
  // x-y plane (v, tz): the Hermite matrix as it is; x-z plane (w, ty): ty = -w', so the
  // rotation rows and columns change sign.
  const int bendY[4] = {kV, kTz, kV + kNode2, kTz + kNode2};
  const int bendZ[4] = {kW, kTy, kW + kNode2, kTy + kNode2};
  const double sign[4] = {1, -1, 1, -1};
  const double eiz = section.bendingStiffnessZ() / (l * l * l), eiy = section.bendingStiffnessY() / (l * l * l);
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) {
      K_(bendY[i], bendY[j]) = eiz * bendingMatrix(shear_.y, i, j);
      K_(bendZ[i], bendZ[j]) = eiy * sign[i] * sign[j] * bendingMatrix(shear_.z, i, j);
    }
  }
  Mat12 Kb = K_;  // bending and torsion: the axial entries zero
  Kb(kU, kU) = Kb(kU + kNode2, kU + kNode2) = Kb(kU, kU + kNode2) = Kb(kU + kNode2, kU) = 0.0;
  energy_ = BeamStrainEnergy<12>(axialStrainShape(l), G_, K_, Kb, section.axialStiffness(), l);
}

const BeamElement3d::Mat12& BeamElement3d::sKL(int k, int l) const {
  if (k < 0 || k > 2 || l < 0 || l > 2) throw std::out_of_range("BeamElement3d::sKL: k, l must be 0, 1 or 2");
  return sKL_[3 * k + l];
}

const BeamElement3d::Mat12& BeamElement3d::sectionRotationMoment(int k, int l) const {
  if (k < 0 || k > 2 || l < 0 || l > 2) {
    throw std::out_of_range("BeamElement3d::sectionRotationMoment: k, l must be 0, 1 or 2");
  }
  return rKL_[3 * k + l];
}

const BeamElement3d::Mat12& BeamElement3d::sectionRotationCoupling(int i) const {
  if (i < 0 || i > 2) throw std::out_of_range("BeamElement3d::sectionRotationCoupling: i must be 0, 1 or 2");
  return hI_[i];
}

const BeamElement3d::Mat3x12& BeamElement3d::positionShapeIntegral(int k) const {
  if (k < 0 || k > 2) throw std::out_of_range("BeamElement3d::positionShapeIntegral: k must be 0, 1 or 2");
  return xS_[k];
}

namespace {

/// The four coefficients of one bending plane's field at xi for the plane's nodal
/// coordinates (d1, r1, d2, r2) = (displacement, section rotation) at both nodes.
using PlaneRow = std::array<double, 4>;

// Shear-flexible bending of one plane (x-y: d = v, r = tz; x-z: d = w, r = -ty), the
// interdependent interpolation of Timoshenko's beam (Przemieniecki1968, sec. 5.6; Reddy1997):
// the exact static solution for end loads, phi = 12 EI / (kappa G A l^2) (phi = 0:
// the Hermite cubics of Euler-Bernoulli, r = d').
PlaneRow planeDisplacement(double xi, double l, double phi) {
  const double x2 = xi * xi, x3 = x2 * xi, f = 1.0 / (1.0 + phi);
  return {f * (1 - 3 * x2 + 2 * x3 + phi * (1 - xi)), f * l * (xi - 2 * x2 + x3 + 0.5 * phi * (xi - x2)),
          f * (3 * x2 - 2 * x3 + phi * xi), f * l * (x3 - x2 + 0.5 * phi * (x2 - xi))};
}
PlaneRow planeSlope(double xi, double l, double phi) {  // d/dx of planeDisplacement
  const double x2 = xi * xi, f = 1.0 / (1.0 + phi);
  return {f * (-6 * xi + 6 * x2 - phi) / l, f * (1 - 4 * xi + 3 * x2 + 0.5 * phi * (1 - 2 * xi)),
          f * (6 * xi - 6 * x2 + phi) / l, f * (3 * x2 - 2 * xi + 0.5 * phi * (2 * xi - 1))};
}
PlaneRow planeCurvature(double xi, double l, double phi) {  // d2/dx2 of planeDisplacement (= d r / dx)
  const double f = 1.0 / (1.0 + phi);
  return {f * (-6 + 12 * xi) / (l * l), f * (-4 + 6 * xi - phi) / l, f * (6 - 12 * xi) / (l * l),
          f * (6 * xi - 2 + phi) / l};
}
PlaneRow planeRotation(double xi, double l, double phi) {  // the section rotation r(xi)
  const double x2 = xi * xi, f = 1.0 / (1.0 + phi);
  return {f * 6 * (x2 - xi) / l, f * (1 - 4 * xi + 3 * x2 + phi * (1 - xi)), f * 6 * (xi - x2) / l,
          f * (3 * x2 - 2 * xi + phi * xi)};
}

/// A plane's row as a 12-row: x-y plane at (v, tz), x-z plane at (w, ty) with r = -ty
/// (ty = -w' under Euler-Bernoulli), so the ty entries change sign.
BeamElement3d::Row12 rowY(const PlaneRow& c) {
  BeamElement3d::Row12 r = BeamElement3d::Row12::Zero();
  r(kV) = c[0];
  r(kTz) = c[1];
  r(kV + kNode2) = c[2];
  r(kTz + kNode2) = c[3];
  return r;
}
BeamElement3d::Row12 rowZ(const PlaneRow& c) {
  BeamElement3d::Row12 r = BeamElement3d::Row12::Zero();
  r(kW) = c[0];
  r(kTy) = -c[1];
  r(kW + kNode2) = c[2];
  r(kTy + kNode2) = -c[3];
  return r;
}

}  // namespace

BeamElement3d::Mat3x12 BeamElement3d::shape(double xi, double l, const BeamShear& shear) {
  Mat3x12 S = Mat3x12::Zero();
  S(0, kU) = 1 - xi;  // w_x = (1-xi) u1 + xi u2 (Doc003)
  S(0, kU + kNode2) = xi;
  S.row(1) = rowY(planeDisplacement(xi, l, shear.y));  // w_y: v1, tz1, v2, tz2
  S.row(2) = rowZ(planeDisplacement(xi, l, shear.z));  // w_z: w1, -ty1, w2, -ty2
  return S;
}

BeamElement3d::Row12 BeamElement3d::twistShape(double xi) {
  Row12 r = Row12::Zero();
  r(kTx) = 1 - xi;  // tx = (1-xi) tx1 + xi tx2
  r(kTx + kNode2) = xi;
  return r;
}

BeamElement3d::Mat3x12 BeamElement3d::rotationShape(double xi, double l, const BeamShear& shear) {
  Mat3x12 Phi;
  Phi.row(0) = twistShape(xi);
  Phi.row(1) = -rowZ(planeRotation(xi, l, shear.z));  // ty = -r_z
  Phi.row(2) = rowY(planeRotation(xi, l, shear.y));   // tz = r_y
  return Phi;
}

BeamElement3d::Mat3x12 BeamElement3d::sectionRotationShape(double xi, double l, BeamTheory theory,
                                                           const BeamShear& shear) {
  Mat3x12 Phi = rotationShape(xi, l, shear);
  if (theory == BeamTheory::EulerBernoulli) Phi.bottomRows<2>().setZero();  // twist only
  return Phi;
}

BeamElement3d::Mat3x12 BeamElement3d::pointShape(double xi, double y, double z, double l, BeamTheory theory,
                                                 const BeamShear& shear) {
  Mat3x12 S = shape(xi, l, shear);
  const Mat3x12 Phi = sectionRotationShape(xi, l, theory, shear);
  S.row(0) += z * Phi.row(1) - y * Phi.row(2);  // phi x (0, y, z) = (z ty - y tz, -z tx, y tx)
  S.row(1) -= z * Phi.row(0);
  S.row(2) += y * Phi.row(0);
  return S;
}

BeamElement3d::Row12 BeamElement3d::axialStrainShape(double l) {
  Row12 r = Row12::Zero();
  r(kU) = -1 / l;  // u' = (u2 - u1) / l
  r(kU + kNode2) = 1 / l;
  return r;
}

BeamElement3d::Row12 BeamElement3d::twistRateShape(double l) {
  Row12 r = Row12::Zero();
  r(kTx) = -1 / l;  // tx' = (tx2 - tx1) / l
  r(kTx + kNode2) = 1 / l;
  return r;
}

BeamElement3d::Row12 BeamElement3d::slopeShapeY(double xi, double l, const BeamShear& shear) {
  return rowY(planeSlope(xi, l, shear.y));  // v'
}

BeamElement3d::Row12 BeamElement3d::slopeShapeZ(double xi, double l, const BeamShear& shear) {
  return rowZ(planeSlope(xi, l, shear.z));  // w'
}

BeamElement3d::Row12 BeamElement3d::curvatureShapeY(double xi, double l, const BeamShear& shear) {
  return rowY(planeCurvature(xi, l, shear.y));  // v'' = tz'
}

BeamElement3d::Row12 BeamElement3d::curvatureShapeZ(double xi, double l, const BeamShear& shear) {
  return rowZ(planeCurvature(xi, l, shear.z));  // w'' = -ty'
}

BeamElement3d::Row12 BeamElement3d::shearStrainShapeY(double l, const BeamShear& shear) {
  // gamma_y = v' - tz, constant (Przemieniecki1968, sec. 5.6)
  return slopeShapeY(0.0, l, shear) - rowY(planeRotation(0.0, l, shear.y));
}

BeamElement3d::Row12 BeamElement3d::shearStrainShapeZ(double l, const BeamShear& shear) {
  // gamma_z = w' + ty, constant (Przemieniecki1968, sec. 5.6)
  return slopeShapeZ(0.0, l, shear) - rowZ(planeRotation(0.0, l, shear.z));
}

// The strain energy: BeamStrainEnergy (elements/beam_strain_energy.hpp), shared with the
// planar element.

double BeamElement3d::membraneStrain(const Vec12& e, bool stiffening) const {
  return energy_.membraneStrain(e, stiffening);
}

double BeamElement3d::strainEnergy(const Vec12& e, bool stiffening) const { return energy_.energy(e, stiffening); }

BeamElement3d::Vec12 BeamElement3d::strainEnergyGradient(const Vec12& e, bool stiffening) const {
  return energy_.gradient(e, stiffening);
}

BeamElement3d::Mat12 BeamElement3d::strainEnergyHessian(const Vec12& e, bool stiffening) const {
  return energy_.hessian(e, stiffening);
}

BeamSectionForces3d BeamElement3d::sectionForces(const Vec12& e, double xi, bool stiffening) const {
  const BeamSection3d& s = section_;
  BeamSectionForces3d f;
  // section forces of beam theory (Przemieniecki1968):
  f.N = s.axialStiffness() * membraneStrain(e, stiffening);  // N = EA eps (constant, consistent with U)
  f.Mx = s.torsionStiffness() * twistRateShape(l_).dot(e);    // Mx = GJ tx'
  f.My = -s.bendingStiffnessY() * curvatureShapeZ(xi, l_, shear_).dot(e);  // My = EIy ty' = -EIy w''
  f.Mz = s.bendingStiffnessZ() * curvatureShapeY(xi, l_, shear_).dot(e);   // Mz = EIz tz' = EIz v''
  // the curvatures are linear in xi: v''' = (v''(1) - v''(0)) / l, likewise w'''
  // (Timoshenko: v'' = tz' as the shear strain is constant, and EIz tz'' = -kappa G A gamma_y)
  const double v3 = (curvatureShapeY(1.0, l_, shear_) - curvatureShapeY(0.0, l_, shear_)).dot(e) / l_;
  const double w3 = (curvatureShapeZ(1.0, l_, shear_) - curvatureShapeZ(0.0, l_, shear_)).dot(e) / l_;
  f.Qy = -s.bendingStiffnessZ() * v3;  // dMz/dx + Qy = 0 (moment balance of a slice; Przemieniecki1968)
  f.Qz = -s.bendingStiffnessY() * w3;  // dMy/dx - Qz = 0
  return f;
}

}  // namespace flexmbd
