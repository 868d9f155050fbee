#include "elements/beam_element_2d.hpp"

#include <array>
#include <cmath>

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

}  // namespace

BeamElement2d::BeamElement2d(const Vec2& start, const Vec2& end, const BeamSection& section,
                             const std::string& owner)
    : start_(start), section_(section) {
  section.validate(owner);
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

  const double rhoA = section.massPerLength(), l = l_;
  mass_ = rhoA * l;
  sBar_.setZero();
  sX_.setZero();
  sXX_.setZero();
  sYY_.setZero();
  sXY_.setZero();
  for (size_t g = 0; g < kGaussXi.size(); ++g) {
    const double xi = kGaussXi[g], w = kGaussW[g] * rhoA * l;  // dx = l dxi
    const Mat26 S = shape(xi, l);
    sBar_ += w * S;
    sX_ += w * xi * l * S;
    sXX_ += w * S.row(0).transpose() * S.row(0);
    sYY_ += w * S.row(1).transpose() * S.row(1);
    sXY_ += w * S.row(0).transpose() * S.row(1);
  }
  // Euler-Bernoulli stiffness (closed form): axial EA/l, bending EI/l^3 (Hermite cubics).
  const double ea = section.axialStiffness() / l, ei = section.bendingStiffness() / (l * l * l);
  K_.setZero();
  K_(0, 0) = K_(3, 3) = ea;
  K_(0, 3) = K_(3, 0) = -ea;
  const int b[4] = {1, 2, 4, 5};
  const double kb[4][4] = {{12, 6 * l, -12, 6 * l},
                           {6 * l, 4 * l * l, -6 * l, 2 * l * l},
                           {-12, -6 * l, 12, -6 * l},
                           {6 * l, 2 * l * l, -6 * l, 4 * l * l}};
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) K_(b[i], b[j]) = ei * kb[i][j];
  }
  Kb_ = K_;
  Kb_(0, 0) = Kb_(3, 3) = Kb_(0, 3) = Kb_(3, 0) = 0.0;
  // Slope-shape integral G = int_0^l b^T b dx (degree 4: the 5-point rule is exact);
  // its transverse block is the classical geometric stiffness (1/(30 l)) [36, 3l, ...].
  G_.setZero();
  for (size_t g = 0; g < kGaussXi.size(); ++g) {
    const Row6 bg = slopeShape(kGaussXi[g], l);
    G_ += (kGaussW[g] * l) * bg.transpose() * bg;
  }
}

BeamElement2d::Mat26 BeamElement2d::shape(double xi, double l) {
  const double x2 = xi * xi, x3 = x2 * xi;
  Mat26 S;
  S << 1 - xi, 0, 0, xi, 0, 0,  //
      0, 1 - 3 * x2 + 2 * x3, l * (xi - 2 * x2 + x3), 0, 3 * x2 - 2 * x3, l * (x3 - x2);
  return S;
}

BeamElement2d::Row6 BeamElement2d::slopeShape(double xi, double l) {
  Row6 r;
  r << 0, (-6 * xi + 6 * xi * xi) / l, 1 - 4 * xi + 3 * xi * xi, 0, (6 * xi - 6 * xi * xi) / l,
      3 * xi * xi - 2 * xi;
  return r;
}

BeamElement2d::Row6 BeamElement2d::curvatureShape(double xi, double l) {
  Row6 r;
  r << 0, (-6 + 12 * xi) / (l * l), (-4 + 6 * xi) / l, 0, (6 - 12 * xi) / (l * l), (6 * xi - 2) / l;
  return r;
}

BeamElement2d::Row6 BeamElement2d::axialStrainShape(double l) {
  Row6 r;
  r << -1 / l, 0, 0, 1 / l, 0, 0;
  return r;
}

// Membrane locking and the averaged membrane strain: Stolarski & Belytschko, "Membrane
// locking and reduced integration for curved elements", J. Appl. Mech. 49 (1982);
// Crisfield, Non-linear Finite Element Analysis of Solids and Structures vol. 1 (1991).
// With a = axialStrainShape, G = int b^T b dx and d = a^T + G e / l:

double BeamElement2d::membraneStrain(const Vec6& e, bool stiffening) const {
  const double du = axialStrainShape(l_).dot(e);
  if (!stiffening) return du;
  return du + 0.5 * e.dot(G_ * e) / l_;  // eps_m = a e + e^T G e / (2l)
}

double BeamElement2d::strainEnergy(const Vec6& e, bool stiffening) const {
  if (!stiffening) return 0.5 * e.dot(K_ * e);
  const double eps = membraneStrain(e, true);
  // U = EA l eps_m^2 / 2 + e^T K_b e / 2 (int EI kappa^2 / 2 dx)
  return 0.5 * section_.axialStiffness() * l_ * eps * eps + 0.5 * e.dot(Kb_ * e);
}

BeamElement2d::Vec6 BeamElement2d::strainEnergyGradient(const Vec6& e, bool stiffening) const {
  if (!stiffening) return K_ * e;
  const double eps = membraneStrain(e, true);
  const Vec6 d = axialStrainShape(l_).transpose() + G_ * e / l_;  // d eps_m / de
  // dU/de = EA l eps_m d + K_b e
  return (section_.axialStiffness() * l_ * eps) * d + Kb_ * e;
}

BeamElement2d::Mat6 BeamElement2d::strainEnergyHessian(const Vec6& e, bool stiffening) const {
  if (!stiffening) return K_;
  const double EA = section_.axialStiffness(), eps = membraneStrain(e, true);
  const Vec6 d = axialStrainShape(l_).transpose() + G_ * e / l_;
  // d2U/de2 = EA l d d^T + EA eps_m G (geometric stiffness, N = EA eps_m) + K_b
  return (EA * l_) * d * d.transpose() + (EA * eps) * G_ + Kb_;
}

Vec2 BeamElement2d::sectionForces(const Vec6& e, double xi, bool stiffening) const {
  // N = EA eps_m (constant per element, consistent with U), M = EI kappa(xi)
  return Vec2(section_.axialStiffness() * membraneStrain(e, stiffening),
              section_.bendingStiffness() * curvatureShape(xi, l_).dot(e));
}

}  // namespace flexmbd
