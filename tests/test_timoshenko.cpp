// The Timoshenko beam element: shear deformation with the
// interdependent interpolation (elements/beam_element_3d; Przemieniecki, Theory of
// Matrix Structural Analysis, sec. 5.6), validated against
//  1. its own energy: K = int (EI psi'^2 + kappa G A gamma^2 + EA u'^2 + GJ tx'^2) dx over
//     the element's shape functions (the closed-form matrix is the field's);
//  2. the cantilever tip deflection P L^3 / (3 EI) + P L / (kappa G A) (exact for end
//     loads with any number of elements);
//  3. the bending frequencies of a thick simply supported beam against the Timoshenko
//     continuum (shear and rotary inertia);
//  4. shear locking absent: a thin beam (L/h = 1000) gives the Euler-Bernoulli values.
// The body-level derivatives (finite differences, d'Alembert, power) run in
// test_ffr_body_3d for every BeamTheory.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "bodies/ffr_beam_model_3d.hpp"
#include "core/errors.hpp"
#include "elements/beam_element_2d.hpp"
#include "elements/beam_element_3d.hpp"

using namespace flexmbd;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kE = 2.1e11, kG = 8.1e10, kRho = 7850.0;

// Tolerances.
// Closed-form matrices against their quadrature: both exact, round-off of sums of
// O(10) terms of the matrix's scale.
constexpr double kMatrixTol = 1e-12;
// Static end loads: the interdependent interpolation is the exact static solution, so
// the tip deflection is exact up to the round-off of a K solve (condition ~ 1e6 here).
constexpr double kStaticTol = 1e-9;

/// Clamped (at x = 0) or pinned-pinned straight beam along x of a b x h section.
FfrBeamModel3d beam(double length, int elements, double widthY, double heightZ, BeamTheory theory,
                    ReferenceConditions3d::Type reference = ReferenceConditions3d::Type::Clamped) {
  FfrBeamOptions3d o;
  o.theory = theory;
  o.reference.type = reference;
  const BeamSection3d s = rectangularSection3d(widthY, heightZ, kE, kG, kRho);
  return FfrBeamModel3d(BeamMesh3d::straight(length, elements, s), o, "test beam");
}

/// The tip displacement (body y) of a clamped beam under a tip force P along y.
double tipDeflection(const FfrBeamModel3d& m, double P, int axis) {
  const int tip = static_cast<int>(m.mesh().nodes.size()) - 1;
  VecX F = VecX::Zero(m.basis().rows());
  F[6 * tip + axis] = P;
  const VecX f = m.basis().transpose() * F;  // generalised force B^T F
  const MatX K = MatX(m.strainEnergyHessian(VecX::Zero(m.numElastic())));
  const VecX q = K.ldlt().solve(f);
  return (m.basis() * q)[6 * tip + axis];
}

/// The lower root omega (rad/s) of the simply supported Timoshenko beam's frequency
/// equation for wave number k = n pi / L (Timoshenko, Phil. Mag. 41 (1921); with
/// w = W sin kx, psi = Psi cos kx in rho A w'' = kGA (w'' - psi'),
/// rho I psi'' = EI psi'' + kGA (w' - psi)):
///   (kGA k^2 - rho A w^2)(EI k^2 + kGA - rho I w^2) - (kGA k)^2 = 0.
double continuumFrequency(double k, double A, double I, double kappa) {
  const double kga = kappa * kG * A, ei = kE * I, ra = kRho * A, ri = kRho * I;
  const double a = ra * ri, b = -(ra * (ei * k * k + kga) + ri * kga * k * k), c = kga * ei * k * k * k * k;
  return std::sqrt((-b - std::sqrt(b * b - 4 * a * c)) / (2 * a));
}

/// The FE frequency nearest to `omega`.
double nearest(const VecX& frequencies, double omega) {
  double best = frequencies[0];
  for (double w : frequencies)
    if (std::abs(w - omega) < std::abs(best - omega)) best = w;
  return best;
}

}  // namespace

TEST(TimoshenkoElement, StiffnessIsTheEnergyOfItsShapeFunctions) {
  // e^T K e / 2 = int (EIz tz'^2 + EIy ty'^2 + kappa G A (gamma_y^2 + gamma_z^2)
  //              + EA u'^2 + GJ tx'^2) / 2 dx, tz' = v'' and -ty' = w'' (curvature rows),
  // gamma from shearStrainShape; a thick element (l / h = 1.5) so that phi ~ 1.
  const BeamSection3d s = rectangularSection3d(0.12, 0.2, kE, kG, kRho);
  const BeamElement3d el(Vec3::Zero(), Vec3(0.3, 0.0, 0.0), Vec3::UnitY(), s, "thick", BeamTheory::Timoshenko);
  const double l = el.length();
  EXPECT_GT(el.shear().y, 0.2);
  EXPECT_GT(el.shear().z, 0.5);
  using Mat12 = BeamElement3d::Mat12;
  using Row12 = BeamElement3d::Row12;
  Mat12 K = Mat12::Zero();
  const Row12 a = BeamElement3d::axialStrainShape(l), t = BeamElement3d::twistRateShape(l);
  const Row12 gy = BeamElement3d::shearStrainShapeY(l, el.shear()), gz = BeamElement3d::shearStrainShapeZ(l, el.shear());
  K += l * (s.axialStiffness() * a.transpose() * a + s.torsionStiffness() * t.transpose() * t);
  K += l * kG * s.area * (s.shearFactorY * gy.transpose() * gy + s.shearFactorZ * gz.transpose() * gz);
  // curvatures are linear: the 2-point Gauss rule is exact for their squares
  for (double xi : {0.5 - 0.5 / std::sqrt(3.0), 0.5 + 0.5 / std::sqrt(3.0)}) {
    const Row12 cy = BeamElement3d::curvatureShapeY(xi, l, el.shear());
    const Row12 cz = BeamElement3d::curvatureShapeZ(xi, l, el.shear());
    K += 0.5 * l * (s.bendingStiffnessZ() * cy.transpose() * cy + s.bendingStiffnessY() * cz.transpose() * cz);
  }
  const double scale = el.stiffness().cwiseAbs().maxCoeff();
  EXPECT_LT((K - el.stiffness()).cwiseAbs().maxCoeff(), kMatrixTol * scale);
  // the shear strain is constant along the element and the curvature is the rotation's
  // rate: v' - tz is the same at both ends, v'' = d tz / dx
  const BeamElement3d::Mat3x12 R0 = BeamElement3d::rotationShape(0.0, l, el.shear());
  const BeamElement3d::Mat3x12 R1 = BeamElement3d::rotationShape(1.0, l, el.shear());
  const Row12 g1 = BeamElement3d::slopeShapeY(1.0, l, el.shear()) - Row12(R1.row(2));
  EXPECT_LT((g1 - gy).cwiseAbs().maxCoeff(), 1e-12 * gy.cwiseAbs().maxCoeff());
  const Row12 dtz = (R1.row(2) - R0.row(2)) / l;
  const Row12 c = 0.5 * (BeamElement3d::curvatureShapeY(0.0, l, el.shear()) +
                         BeamElement3d::curvatureShapeY(1.0, l, el.shear()));  // mean of a linear row
  EXPECT_LT((dtz - c).cwiseAbs().maxCoeff(), 1e-12 * c.cwiseAbs().maxCoeff());
  // the nodal rotations are the sections' own: rotationShape is the identity at the nodes
  EXPECT_DOUBLE_EQ(R0(2, 5), 1.0);
  EXPECT_DOUBLE_EQ(R1(2, 11), 1.0);
  EXPECT_DOUBLE_EQ(R0(1, 4), 1.0);
  EXPECT_NEAR(R0(2, 1), 0.0, 1e-15);  // tz at node 1 does not depend on v1
}

TEST(TimoshenkoElement, ShearFlexibilityZeroIsRayleigh) {
  // phi -> 0 (shear stiffness without bound) recovers the Rayleigh element: same
  // stiffness and inertia. G 1e6 times larger makes phi 1e-6 times smaller.
  BeamSection3d s = rectangularSection3d(0.05, 0.08, kE, kG, kRho);
  const BeamElement3d ray(Vec3::Zero(), Vec3(0.4, 0.1, -0.2), Vec3::UnitZ(), s, "r", BeamTheory::Rayleigh);
  s.shearFactorY *= 1e6;
  s.shearFactorZ *= 1e6;
  const BeamElement3d tim(Vec3::Zero(), Vec3(0.4, 0.1, -0.2), Vec3::UnitZ(), s, "t", BeamTheory::Timoshenko);
  const double tol = 10 * std::max(tim.shear().y, tim.shear().z);  // first order in phi
  EXPECT_LT(tol, 1e-4);
  EXPECT_LT((tim.stiffness() - ray.stiffness()).cwiseAbs().maxCoeff(), tol * ray.stiffness().cwiseAbs().maxCoeff());
  EXPECT_LT((tim.massMatrix() - ray.massMatrix()).cwiseAbs().maxCoeff(), tol * ray.massMatrix().cwiseAbs().maxCoeff());
  for (int k = 0; k < 3; ++k)
    for (int m = 0; m < 3; ++m)
      EXPECT_LT((tim.sectionRotationMoment(k, m) - ray.sectionRotationMoment(k, m)).cwiseAbs().maxCoeff(),
                tol * ray.massMatrix().cwiseAbs().maxCoeff());
}

TEST(TimoshenkoElement, MissingShearFactorIsAnInputErrorNamingTheKey) {
  BeamSection3d s = rectangularSection3d(0.05, 0.08, kE, kG, kRho);
  s.shearFactorZ = 0.0;
  try {
    BeamElement3d(Vec3::Zero(), Vec3(1, 0, 0), Vec3::UnitY(), s, "body \"rod\" element 3", BeamTheory::Timoshenko);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("body \"rod\" element 3"), std::string::npos) << m;
    EXPECT_NE(m.find("shear_factor_z"), std::string::npos) << m;
  }
  // Euler-Bernoulli does not need it
  EXPECT_NO_THROW(BeamElement3d(Vec3::Zero(), Vec3(1, 0, 0), Vec3::UnitY(), s, "eb"));
  s.shearFactorY = -1.0;
  EXPECT_THROW(BeamElement3d(Vec3::Zero(), Vec3(1, 0, 0), Vec3::UnitY(), s, "eb"), InputError);
}

TEST(TimoshenkoBeam, CantileverTipDeflectionIncludesShear) {
  // delta = P L^3 / (3 EI) + P L / (kappa G A), both planes, a thick beam (L/h = 2) with
  // 1 and 4 elements; Euler-Bernoulli misses the shear part.
  const double L = 0.4, b = 0.1, h = 0.2, P = 1e5;
  const BeamSection3d s = rectangularSection3d(b, h, kE, kG, kRho);
  for (int n : {1, 4}) {
    const FfrBeamModel3d tim = beam(L, n, b, h, BeamTheory::Timoshenko);
    const FfrBeamModel3d eb = beam(L, n, b, h, BeamTheory::EulerBernoulli);
    for (int axis : {1, 2}) {
      const double EI = axis == 1 ? s.bendingStiffnessZ() : s.bendingStiffnessY();
      const double kappa = axis == 1 ? s.shearFactorY : s.shearFactorZ;
      const double bending = P * L * L * L / (3 * EI), shear = P * L / (kappa * kG * s.area);
      const double d = tipDeflection(tim, P, axis);
      EXPECT_NEAR(d, bending + shear, kStaticTol * (bending + shear)) << n << " elements, axis " << axis;
      EXPECT_NEAR(tipDeflection(eb, P, axis), bending, kStaticTol * bending);
      std::printf("[ figures ] cantilever L/h = %.0f, %d element(s), axis %d: tip %.10e m, closed form %.10e "
                  "(shear part %.1f%%)\n",
                  L / (axis == 1 ? b : h), n, axis, d, bending + shear, 100 * shear / (bending + shear));
    }
  }
}

TEST(TimoshenkoBeam, ThickBeamFrequenciesMatchTheContinuum) {
  // Simply supported thick beam, L/h = 5 in the x-y plane (h = widthY), the first three
  // bending frequencies of that plane against the continuum's lower branch, 20 and 40
  // elements. The bound: the element's shear strain is constant per element (what makes
  // it exact for end loads), while the mode's gamma varies as cos(kx); the best piecewise
  // constant approximation of cos(kx) on elements of length h has relative squared error
  // (kh)^2 / 12, so the eigenvalue error is at most the shear energy fraction (< 1) times
  // that and the frequency error (kh)^2 / 24: second order in h (Euler-Bernoulli and
  // Rayleigh elements converge at fourth order; the interdependent interpolation trades
  // that for static exactness and freedom from locking, docs/spatial-flexible.md).
  const double L = 1.0, b = 0.2, h = 0.3;
  const BeamSection3d s = rectangularSection3d(b, h, kE, kG, kRho);
  std::vector<double> errors20, errors40;
  for (int n : {20, 40}) {
    const FfrBeamModel3d m = beam(L, n, b, h, BeamTheory::Timoshenko, ReferenceConditions3d::Type::PinnedPinned);
    const VecX w = m.naturalFrequencies();
    for (int mode = 1; mode <= 3; ++mode) {
      const double k = mode * kPi / L, kh = k * L / n;
      const double exact = continuumFrequency(k, s.area, s.inertiaZ, s.shearFactorY);
      const double fe = nearest(w, exact), err = std::abs(fe - exact) / exact;
      (n == 20 ? errors20 : errors40).push_back(err);
      EXPECT_LT(err, kh * kh / 24) << n << " elements, mode " << mode;
      // Euler-Bernoulli's (n pi / L)^2 sqrt(EI / rho A) is far off at L/h = 5
      const double ebw = k * k * std::sqrt(s.bendingStiffnessZ() / (kRho * s.area));
      EXPECT_GT(ebw / exact - 1.0, 0.05 * mode);
      if (n == 40) {
        std::printf("[ figures ] thick SS beam L/h = 5, mode %d: FE (40 elements) %.6f rad/s, Timoshenko continuum "
                    "%.6f (error %.1e; 20 elements %.1e), Euler-Bernoulli %.6f\n",
                    mode, fe, exact, err, errors20[mode - 1], ebw);
      }
    }
  }
  // second-order convergence: halving h divides the error by about 4
  for (int k = 0; k < 3; ++k) EXPECT_GT(errors20[k], 3.5 * errors40[k]) << "mode " << k + 1;
}

TEST(TimoshenkoBeam, NoShearLockingInTheThinLimit) {
  // L/h = 1000: one Timoshenko element's tip deflection is Euler-Bernoulli's plus the
  // shear part 3 EI / (kappa G A L^2) ~ 1e-6 of it (a locking element would be orders
  // stiffer); the frequencies of an 8-element clamped beam equal Rayleigh's to that order.
  const double L = 10.0, b = 0.01, h = 0.01, P = 1.0;
  const FfrBeamModel3d tim = beam(L, 1, b, h, BeamTheory::Timoshenko);
  const FfrBeamModel3d eb = beam(L, 1, b, h, BeamTheory::EulerBernoulli);
  const BeamSection3d s = rectangularSection3d(b, h, kE, kG, kRho);
  const double ratio = 3 * s.bendingStiffnessZ() / (s.shearFactorY * kG * s.area * L * L);
  const double dt = tipDeflection(tim, P, 1), de = tipDeflection(eb, P, 1);
  EXPECT_LT(ratio, 1e-5);
  EXPECT_NEAR(dt / de - 1.0, ratio, kStaticTol);
  const VecX wt = beam(L, 8, b, h, BeamTheory::Timoshenko).naturalFrequencies();
  const VecX wr = beam(L, 8, b, h, BeamTheory::Rayleigh).naturalFrequencies();
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(wt[k] / wr[k], 1.0, 10 * ratio) << "mode " << k + 1;
  std::printf("[ figures ] thin cantilever L/h = 1000: Timoshenko / Euler-Bernoulli tip = 1 + %.3e (shear ratio "
              "%.3e); first frequency ratio to Rayleigh %.9f\n",
              dt / de - 1.0, ratio, wt[0] / wr[0]);
}
