// Unit tests of the planar Euler-Bernoulli beam element of the floating frame of
// reference formulation (elements/beam_element_2d): the inertia shape integrals and
// the stiffness against their closed forms (document 003; Shabana, Dynamics of
// Multibody Systems, ch. 6), the rigid-body modes of the stiffness, the strain energy
// derivatives (with and without geometric stiffening) against central finite
// differences, the geometric stiffness of an axially stretched element, the section
// forces and the input checks.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "core/errors.hpp"
#include "elements/beam_element_2d.hpp"
#include "elements/beam_section.hpp"
#include "tests/test_support.hpp"

namespace flexmbd {
namespace {

using namespace testsupport;

using Vec6 = BeamElement2d::Vec6;
using Row6 = BeamElement2d::Row6;
using Mat6 = BeamElement2d::Mat6;
using Mat26 = BeamElement2d::Mat26;

// Fixed seed: the random states are the same on every run (reproducible).
constexpr unsigned kSeed = 20240611u;
// Random states per derivative check.
constexpr int kSamples = 8;

// Closed forms vs the element's matrices: the element integrates polynomials of degree
// <= 6 with a 5-point Gauss rule (exact to degree 9), so the only error is roundoff of
// ~5 products per entry: a few ulps, <= ~1e-15 relative to the largest entry.
// 1e-13 bounds that; a wrong coefficient is an O(1e-2..1) relative error.
constexpr double kExactTol = 1e-13;
// K e = 0 for a rigid mode: K e sums entries of magnitude |K| |e| that cancel exactly;
// roundoff <= ~6 eps |K| |e| ~ 1e-15 |K| |e|.
constexpr double kRigidTol = 1e-13;
// Eigenvalues of K: the three rigid-mode eigenvalues are roundoff, |lambda| <~ 10 eps
// lambda_max; the smallest elastic one is pure bending (slopes -a, +a), 2 EI/l, against
// lambda_max = 2 EA/l: I/(A l^2) = 5.2e-5 here, i.e. 8.3e-6 lambda_max. A zero
// threshold of 1e-10 lambda_max is five decades from either.
constexpr double kZeroEigenTol = 1e-10;

// Central differences of the strain energy. Each coordinate is stepped by
// h_k = kFdStepFraction * (its typical magnitude): displacements ~1e-3 l, slopes ~1e-2.
// U is a polynomial of degree 4 in e: the truncation error of the central difference
// of dU/de is h^2/6 d3U/de3, relative (h/|e|)^2 ~ 1e-10 of the nonlinear part; the
// roundoff error is ~ eps U / h, relative eps |e| / h ~ 2e-11 of the gradient.
constexpr double kFdStepFraction = 1e-5;
// Tolerance of the analytic gradient and Hessian against those differences, relative
// to the largest entry compared: measured <= 1.3e-11; 1e-7 leaves a wide margin while
// a missing term of the stiffening (v'^2/2 ~ 5e-5 against strains ~ 1e-3) or a wrong
// factor is >= ~1e-3 relative (dropping eps b^T b from the Hessian was checked to fail).
constexpr double kFdTol = 1e-7;

/// Gauss-Legendre rule with n points on [0, 1] (Golub-Welsch: eigenvalues of the
/// Jacobi matrix of the Legendre polynomials), independent of the element's own rule.
void gaussRule(int n, std::vector<double>& xi, std::vector<double>& w) {
  MatX J = MatX::Zero(n, n);
  for (int k = 1; k < n; ++k) J(k, k - 1) = J(k - 1, k) = k / std::sqrt(4.0 * k * k - 1.0);
  const Eigen::SelfAdjointEigenSolver<MatX> es(J);
  xi.resize(n);
  w.resize(n);
  for (int k = 0; k < n; ++k) {
    xi[k] = 0.5 * (es.eigenvalues()[k] + 1.0);
    w[k] = es.eigenvectors()(0, k) * es.eigenvectors()(0, k);  // 2 v0^2 / 2 on [0, 1]
  }
}

// A 1 cm x 1 cm steel bar, element of length 0.4 m at 35 degrees in the body frame.
constexpr double kLength = 0.4;
const BeamSection kSteel = rectangularSection(0.01, 0.01, 2.1e11, 7850.0, 1e-4);

BeamElement2d makeElement(const BeamSection& s = kSteel, double l = kLength) {
  const Vec2 start(0.1, -0.2);
  const double beta = 35.0 * kPi / 180.0;
  return BeamElement2d(start, start + l * Vec2(std::cos(beta), std::sin(beta)), s, "test element");
}

/// Random element coordinates of realistic magnitude: displacements ~1e-3 l, slopes ~1e-2.
Vec6 randomState(Random& rnd, double l) {
  Vec6 e;
  for (int k : {0, 1, 3, 4}) e[k] = rnd.uniform(-1e-3, 1e-3) * l;
  for (int k : {2, 5}) e[k] = rnd.uniform(-1e-2, 1e-2);
  return e;
}

/// Typical magnitude of each coordinate (for the finite-difference steps).
Vec6 typicalMagnitude(double l) {
  Vec6 s;
  s << 1e-3 * l, 1e-3 * l, 1e-2, 1e-3 * l, 1e-3 * l, 1e-2;
  return s;
}

Vec6 fdGradient(const std::function<double(const Vec6&)>& f, const Vec6& e, const Vec6& mag) {
  Vec6 g;
  for (int k = 0; k < 6; ++k) {
    const double h = kFdStepFraction * mag[k];
    Vec6 ep = e, em = e;
    ep[k] += h;
    em[k] -= h;
    g[k] = (f(ep) - f(em)) / (2.0 * h);
  }
  return g;
}

Mat6 fdJacobian(const std::function<Vec6(const Vec6&)>& f, const Vec6& e, const Vec6& mag) {
  Mat6 J;
  for (int k = 0; k < 6; ++k) {
    const double h = kFdStepFraction * mag[k];
    Vec6 ep = e, em = e;
    ep[k] += h;
    em[k] -= h;
    J.col(k) = (f(ep) - f(em)) / (2.0 * h);
  }
  return J;
}

/// The matrix with the axial rows and columns (0, 3) zeroed: the bending entries are
/// ~1e-4 of the axial ones, so they are compared on their own scale.
Mat6 bendingBlock(Mat6 M) {
  for (int i : {0, 3})
    for (int j = 0; j < 6; ++j) M(i, j) = M(j, i) = 0.0;
  return M;
}

// ----- inertia shape integrals --------------------------------------------------------

TEST(BeamElement2d, MassAndShapeIntegralsMatchClosedForms) {
  const BeamElement2d el = makeElement();
  const double l = el.length(), rhoA = kSteel.density * kSteel.area, m = rhoA * l;
  EXPECT_NEAR(l, kLength, 1e-15);
  EXPECT_NEAR(el.angle(), 35.0 * kPi / 180.0, 1e-15);
  EXPECT_NEAR(el.mass(), m, kExactTol * m);

  Mat26 sBar;
  sBar << 0.5, 0, 0, 0.5, 0, 0,  //
      0, 0.5, l / 12, 0, 0.5, -l / 12;
  expectMatrixNear(el.sBar(), m * sBar, kExactTol, "S-bar");

  // int rho x S dx = rho A l^2 int_0^1 xi S(xi) dxi:
  //   int xi (1-xi) = 1/6, int xi^2 = 1/3; int xi (1-3xi^2+2xi^3) = 3/20,
  //   int xi l (xi-2xi^2+xi^3) = l/30, int xi (3xi^2-2xi^3) = 7/20, int xi l (xi^3-xi^2) = -l/20.
  Mat26 sX;
  sX << 1.0 / 6, 0, 0, 1.0 / 3, 0, 0,  //
      0, 3.0 / 20, l / 30, 0, 7.0 / 20, -l / 20;
  expectMatrixNear(el.sX(), m * l * sX, kExactTol, "S_X = int rho x S");

  Mat6 sxx = Mat6::Zero();
  sxx(0, 0) = sxx(3, 3) = 2.0 / 6;
  sxx(0, 3) = sxx(3, 0) = 1.0 / 6;
  expectMatrixNear(el.sXX(), m * sxx, kExactTol, "S_xx (axial consistent mass)");

  const double cm[4][4] = {{156, 22 * l, 54, -13 * l},
                           {22 * l, 4 * l * l, 13 * l, -3 * l * l},
                           {54, 13 * l, 156, -22 * l},
                           {-13 * l, -3 * l * l, -22 * l, 4 * l * l}};
  const int b[4] = {1, 2, 4, 5};
  Mat6 syy = Mat6::Zero();
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) syy(b[i], b[j]) = cm[i][j] / 420.0;
  expectMatrixNear(el.sYY(), m * syy, kExactTol, "S_yy (classical consistent mass)");

  // S_xy = int rho S_x^T S_y: rows 0, 3 (axial shapes 1-xi, xi) times the Hermite
  // shapes: int (1-xi) H = [7/20, l/20, 3/20, -l/30], int xi H = [3/20, l/30, 7/20, -l/20];
  // rows 1, 2, 4, 5 and columns 0, 3 are zero.
  Mat6 sxy = Mat6::Zero();
  const double r0[4] = {7.0 / 20, l / 20, 3.0 / 20, -l / 30};
  const double r3[4] = {3.0 / 20, l / 30, 7.0 / 20, -l / 20};
  for (int j = 0; j < 4; ++j) {
    sxy(0, b[j]) = r0[j];
    sxy(3, b[j]) = r3[j];
  }
  expectMatrixNear(el.sXY(), m * sxy, kExactTol, "S_xy");
  // the zero pattern exactly (not merely small)
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) {
      if (sxy(i, j) == 0.0) {
        EXPECT_EQ(el.sXY()(i, j), 0.0) << "S_xy(" << i << "," << j << ")";
      }
    }
  }
  // consistency: a rigid translation carries the whole mass
  Vec6 tx, ty;
  tx << 1, 0, 0, 1, 0, 0;
  ty << 0, 1, 0, 0, 1, 0;
  EXPECT_NEAR(tx.dot(el.sXX() * tx), m, kExactTol * m);
  EXPECT_NEAR(ty.dot(el.sYY() * ty), m, kExactTol * m);
}

TEST(BeamElement2d, ShapeIntegralsAreIndependentOfPlacementAndLength) {
  // The element-frame integrals depend only on l and rho A, not on the start or angle.
  for (const double l : {0.05, 0.4, 3.0}) {
    const BeamElement2d a(Vec2(0, 0), Vec2(l, 0), kSteel, "a");
    const BeamElement2d b(Vec2(-2.0, 5.0), Vec2(-2.0, 5.0) + l * Vec2(std::cos(2.5), std::sin(2.5)), kSteel, "b");
    expectMatrixNear(a.sBar(), b.sBar(), kExactTol, "S-bar");
    expectMatrixNear(a.sYY(), b.sYY(), kExactTol, "S_yy");
    expectMatrixNear(a.stiffness(), b.stiffness(), kExactTol, "K");
    // transformation: body-frame displacements (ux, uy, psi) -> element coordinates
    Mat6 T = Mat6::Zero();
    const double c = std::cos(2.5), s = std::sin(2.5);
    for (int n : {0, 3}) {
      T(n, n) = c;
      T(n, n + 1) = s;
      T(n + 1, n) = -s;
      T(n + 1, n + 1) = c;
      T(n + 2, n + 2) = 1;
    }
    expectMatrixNear(b.transformation(), T, kExactTol, "T = diag(R^T, 1, R^T, 1)");
  }
}

// ----- stiffness ----------------------------------------------------------------------

TEST(BeamElement2d, StiffnessMatchesClosedFormAndQuadrature) {
  const BeamElement2d el = makeElement();
  const double l = el.length(), EA = kSteel.youngsModulus * kSteel.area, EI = kSteel.youngsModulus * kSteel.inertia;
  const Mat6& K = el.stiffness();
  expectMatrixNear(K, K.transpose(), 0.0, "K symmetric (exactly)");

  Mat6 Kc = Mat6::Zero();
  Kc(0, 0) = Kc(3, 3) = EA / l;
  Kc(0, 3) = Kc(3, 0) = -EA / l;
  const double kb[4][4] = {{12, 6 * l, -12, 6 * l},
                           {6 * l, 4 * l * l, -6 * l, 2 * l * l},
                           {-12, -6 * l, 12, -6 * l},
                           {6 * l, 2 * l * l, -6 * l, 4 * l * l}};
  const int b[4] = {1, 2, 4, 5};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) Kc(b[i], b[j]) = EI / (l * l * l) * kb[i][j];
  // compare the blocks separately: the bending entries are ~1e-4 of the axial ones
  expectMatrixNear(K, Kc, kExactTol, "K (whole)");
  expectMatrixNear(bendingBlock(K), bendingBlock(Kc), kExactTol, "K bending block");

  // independently: K = int (EA a^T a + EI c^T c) dx with the element's own strain
  // rows, by a 6-point Gauss rule (exact: the integrand has degree 2)
  std::vector<double> xi, w;
  gaussRule(6, xi, w);
  Mat6 Kq = Mat6::Zero();
  for (size_t g = 0; g < xi.size(); ++g) {
    const Row6 a = BeamElement2d::axialStrainShape(l), c = BeamElement2d::curvatureShape(xi[g], l);
    Kq += w[g] * l * (EA * a.transpose() * a + EI * c.transpose() * c);
  }
  // (the independent rule's nodes and weights carry ~1e-15 eigen-solver roundoff)
  expectMatrixNear(bendingBlock(K), bendingBlock(Kq), 1e-12, "K bending block vs quadrature of EI c^T c");
  expectMatrixNear(K, Kq, 1e-12, "K vs quadrature");

  // the strain rows are the derivatives of the shape functions: d/dx of row 1 of S
  // (slope) and of the slope (curvature), checked by central differences in xi
  for (const double x : {0.1, 0.37, 0.8}) {
    const double h = 1e-5;
    const Row6 slopeFd = (BeamElement2d::shape(x + h, l).row(1) - BeamElement2d::shape(x - h, l).row(1)) / (2 * h * l);
    const Row6 curvFd = (BeamElement2d::slopeShape(x + h, l) - BeamElement2d::slopeShape(x - h, l)) / (2 * h * l);
    const Row6 axialFd = (BeamElement2d::shape(x + h, l).row(0) - BeamElement2d::shape(x - h, l).row(0)) / (2 * h * l);
    // cubic/quadratic polynomials: central difference exact up to h^2 |f'''| / 6 and
    // roundoff eps / h ~ 2e-11, relative to entries of order 1/l
    expectMatrixNear(BeamElement2d::slopeShape(x, l), slopeFd, 1e-9, "slope shape");
    expectMatrixNear(BeamElement2d::curvatureShape(x, l), curvFd, 1e-9, "curvature shape");
    expectMatrixNear(BeamElement2d::axialStrainShape(l), axialFd, 1e-9, "axial strain shape");
  }
}

TEST(BeamElement2d, StiffnessHasExactlyTheThreeRigidModes) {
  const BeamElement2d el = makeElement();
  const double l = el.length();
  const Mat6& K = el.stiffness();
  Vec6 axial, transverse, rotation;
  axial << 1, 0, 0, 1, 0, 0;
  transverse << 0, 1, 0, 0, 1, 0;
  const double a = 0.013;  // small rotation v = a x: v1 = 0, slope a, v2 = a l
  rotation << 0, 0, a, 0, a * l, a;
  const double kmax = K.cwiseAbs().maxCoeff();
  for (const Vec6& e : {axial, transverse, rotation, Vec6(0.3 * axial - 2.0 * transverse + 5.0 * rotation)}) {
    EXPECT_LE((K * e).cwiseAbs().maxCoeff(), kRigidTol * kmax * e.cwiseAbs().maxCoeff()) << e.transpose();
    EXPECT_LE(std::abs(el.strainEnergy(e, false)), kRigidTol * kmax * e.squaredNorm());
  }
  // with stiffening, the exact rigid translations (any size) have no strain energy
  for (const Vec6& e : {Vec6(0.2 * axial), Vec6(-0.4 * transverse)}) {
    EXPECT_LE(std::abs(el.strainEnergy(e, true)), kRigidTol * kmax * e.squaredNorm());
  }
  const Eigen::SelfAdjointEigenSolver<Mat6> es(K);
  const auto lambda = es.eigenvalues();
  const double lmax = lambda.maxCoeff();
  int zeros = 0;
  for (int k = 0; k < 6; ++k) {
    EXPECT_GE(lambda[k], -kZeroEigenTol * lmax) << "eigenvalue " << k;
    if (std::abs(lambda[k]) <= kZeroEigenTol * lmax) ++zeros;
    else EXPECT_GE(lambda[k], 1e-8 * lmax) << "elastic eigenvalue " << k << " too close to zero";
  }
  EXPECT_EQ(zeros, 3) << "eigenvalues of K: " << lambda.transpose();
}

// ----- strain energy derivatives ----------------------------------------------------

TEST(BeamElement2d, StrainEnergyDerivativesMatchFiniteDifferences) {
  Random rnd(kSeed);
  const BeamElement2d el = makeElement();
  const Vec6 mag = typicalMagnitude(el.length());
  double worstG = 0.0, worstH = 0.0;
  for (const bool stiff : {false, true}) {
    for (int s = 0; s < kSamples; ++s) {
      const Vec6 e = randomState(rnd, el.length());
      const std::string what = std::string(stiff ? "stiffening" : "linear") + " sample " + std::to_string(s);
      const Vec6 g = el.strainEnergyGradient(e, stiff);
      const Vec6 gFd = fdGradient([&](const Vec6& x) { return el.strainEnergy(x, stiff); }, e, mag);
      worstG = std::max(worstG, expectMatrixNear(g, gFd, kFdTol, what + ": gradient vs FD of U"));
      const Mat6 H = el.strainEnergyHessian(e, stiff);
      const Mat6 HFd = fdJacobian([&](const Vec6& x) { return el.strainEnergyGradient(x, stiff); }, e, mag);
      worstH = std::max(worstH, expectMatrixNear(H, HFd, kFdTol, what + ": Hessian vs FD of gradient"));
      // the Hessian's bending block alone (its entries are ~1e-4 of the axial ones)
      expectMatrixNear(bendingBlock(H), bendingBlock(HFd), kFdTol, what + ": Hessian bending block vs FD");
      expectMatrixNear(H, H.transpose(), 1e-14, what + ": Hessian symmetric");
      if (!stiff) {
        // the linear model: gradient == K e, Hessian == K, energy == e^T K e / 2, exactly
        EXPECT_TRUE(g == el.stiffness() * e) << what;
        EXPECT_TRUE(H == el.stiffness()) << what;
        EXPECT_DOUBLE_EQ(el.strainEnergy(e, false), 0.5 * e.dot(el.stiffness() * e));
      } else {
        // U(linear) and U(stiffening) differ by the O(v'^2) terms only: here
        // v'^2/2 <~ 1.5e-4 against eps ~ 5e-3, so the gradient changes by <~ 10%
        const Vec6 gl = el.strainEnergyGradient(e, false);
        EXPECT_LE((g - gl).norm(), 0.2 * gl.norm()) << what;
        EXPECT_GT((g - gl).norm(), 1e-8 * gl.norm()) << what << ": stiffening has no effect";
      }
    }
  }
  RecordProperty("worst_gradient_rel_error", std::to_string(worstG));
  RecordProperty("worst_hessian_rel_error", std::to_string(worstH));
  std::printf("strain energy FD: worst gradient rel error %.2e, worst Hessian rel error %.2e\n", worstG, worstH);
}

TEST(BeamElement2d, StiffeningWithoutTransverseDeformationIsLinear) {
  // v = 0: eps = u' exactly, so U, dU/de and the axial part of the Hessian are those of
  // the linear model (the Hessian adds EA eps int b^T b: the geometric stiffness, below).
  const BeamElement2d el = makeElement();
  const double l = el.length();
  for (const double u1 : {0.0, -3e-4, 2e-4}) {
    for (const double u2 : {1e-4, -5e-4, 4e-3}) {
      Vec6 e;
      e << u1 * l, 0, 0, u2 * l, 0, 0;
      const Vec6 gl = el.strainEnergyGradient(e, false), gs = el.strainEnergyGradient(e, true);
      // the stiffening quadrature sums 5 weights (exact sum l): a few ulps of EA/l |e|
      expectMatrixNear(gs, gl, kExactTol, "gradient, pure axial state");
      EXPECT_NEAR(el.strainEnergy(e, true), el.strainEnergy(e, false), kExactTol * el.strainEnergy(e, false));
    }
  }
  // equal end displacements: a rigid translation, no strain at all: Hessian == K
  Vec6 e;
  e << 2e-4, 0, 0, 2e-4, 0, 0;
  expectMatrixNear(el.strainEnergyHessian(e, true), el.stiffness(), kExactTol, "Hessian, rigid axial translation");
}

// Geometric stiffness of the classical (Przemieniecki) beam: (N / (30 l)) [36, 3l, ...]
// on the transverse dofs (1, 2, 4, 5), N = EA delta / l.
Mat6 classicalGeometricStiffness(double N, double l) {
  const double kg[4][4] = {{36, 3 * l, -36, 3 * l},
                           {3 * l, 4 * l * l, -3 * l, -l * l},
                           {-36, -3 * l, 36, -3 * l},
                           {3 * l, -l * l, -3 * l, 4 * l * l}};
  const int b[4] = {1, 2, 4, 5};
  Mat6 G = Mat6::Zero();
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) G(b[i], b[j]) = N / (30.0 * l) * kg[i][j];
  return G;
}

TEST(BeamElement2d, StretchedElementHessianContainsGeometricStiffness) {
  // With the averaged membrane strain eps_m = a e + e^T G e / (2l), G = int b^T b dx,
  // d2U/de2 = EA l d d^T + EA eps_m G + K_b, d = a^T + G e / l. At a purely axial state
  // (u2 - u1 = delta, v = 0): eps_m = delta/l exactly and G e = 0, so
  // H = K + (EA delta / l) int b^T b dx, and int b^T b dx is
  // the classical geometric stiffness matrix (1/(30 l))[36, 3l, ...]. The relation is
  // therefore not only first order in delta but exact (no delta^2 term: eps is linear
  // in u), and the tolerance is roundoff: each entry is a 5-point quadrature sum of
  // terms <= max(|K_b|, |K_g|), error <= ~10 eps of that: 1e-13 relative to the larger.
  const BeamElement2d el = makeElement();
  const double l = el.length(), EA = kSteel.youngsModulus * kSteel.area;
  const Mat6& K = el.stiffness();
  for (const double u1 : {0.0, 3e-4 * l}) {
    for (const double delta : {1e-3 * l, -5e-4 * l, 2e-3 * l}) {
      Vec6 e;
      e << u1, 0, 0, u1 + delta, 0, 0;
      const Mat6 H = el.strainEnergyHessian(e, true);
      const Mat6 G = classicalGeometricStiffness(EA * delta / l, l);
      const double floor = std::max(bendingBlock(K).cwiseAbs().maxCoeff(), G.cwiseAbs().maxCoeff());
      // the geometric part is comparable to the bending part here (ratio ~ 1..4), so
      // it is measured, not lost in the roundoff of the bending entries
      EXPECT_GT(G.cwiseAbs().maxCoeff(), 0.3 * std::abs(K(1, 1)));
      const std::string what = "delta = " + std::to_string(delta) + ", u1 = " + std::to_string(u1);
      // transverse block (the axial block is compared below on its own, ~1e4 times larger, scale)
      expectMatrixNear(bendingBlock(H - K), G, kExactTol, what + ": H_vv - K_b == (EA delta/l) K_g", floor);
      // axial block unchanged, no axial-transverse coupling at v = 0
      EXPECT_LE(std::abs(H(0, 0) - K(0, 0)), kExactTol * K(0, 0));
      EXPECT_LE(std::abs(H(0, 3) - K(0, 3)), kExactTol * K(0, 0));
      for (int i : {0, 3})
        for (int j : {1, 2, 4, 5}) EXPECT_LE(std::abs(H(i, j)), kExactTol * K(0, 0)) << what;
    }
  }
  // Adding a small transverse deformation of amplitude s changes the vv block by
  // EA (G e)(G e)^T / l + EA (e^T G e / 2l) G (the averaged membrane strain, G = int
  // b^T b dx: the d d^T and eps_m G terms): exactly quadratic in s, so halving s divides
  // the deviation by 4 (up to roundoff of the subtraction, ~1e-13 |K_b| / deviation
  // ~ 1e-8 here).
  Vec6 shape;
  shape << 0, 0.3, 1.0, 0, -0.2, 0.6;  // slopes ~ s, displacements ~ s l
  shape[1] *= l;
  shape[4] *= l;
  const double delta = 1e-3 * l;
  auto deviation = [&](double s) {
    Vec6 e = s * shape;
    e[3] += delta;
    const Mat6 H = el.strainEnergyHessian(e, true);
    const Mat6 Hvv0 = K + classicalGeometricStiffness(EA * delta / l, l);
    double d = 0.0;
    for (int i : {1, 2, 4, 5})
      for (int j : {1, 2, 4, 5}) d = std::max(d, std::abs(H(i, j) - Hvv0(i, j)));
    return d;
  };
  const double d1 = deviation(2e-3), d2 = deviation(1e-3);
  EXPECT_NEAR(d1 / d2, 4.0, 1e-5) << "deviation " << d1 << ", " << d2;
  // and it is a small (second-order) correction: ~ v'^2 / eps ~ 1e-2 of K_g
  EXPECT_LT(d2, 0.05 * classicalGeometricStiffness(EA * delta / l, l).cwiseAbs().maxCoeff());
}

// ----- section forces -------------------------------------------------------------------

TEST(BeamElement2d, SectionForcesOfStretchAndConstantCurvature) {
  const BeamElement2d el = makeElement();
  const double l = el.length(), EA = kSteel.youngsModulus * kSteel.area, EI = kSteel.youngsModulus * kSteel.inertia;
  // pure axial stretch: N = EA delta / l, M = 0, whatever the stiffening
  const double delta = 1e-3 * l;
  Vec6 e;
  e << 2e-4, 0, 0, 2e-4 + delta, 0, 0;
  for (const bool stiff : {false, true}) {
    for (const double xi : {0.0, 0.21, 0.5, 1.0}) {
      const Vec2 f = el.sectionForces(e, xi, stiff);
      EXPECT_NEAR(f.x(), EA * delta / l, kExactTol * EA * delta / l) << "xi " << xi;
      EXPECT_EQ(f.y(), 0.0) << "xi " << xi;
    }
  }
  // constant curvature v = kappa x^2 / 2 (exact in the cubic Hermite field): nodal
  // values v1 = 0, v1' = 0, v2 = kappa l^2 / 2, v2' = kappa l; plus a rigid motion
  // (translation and small rotation) that must not change the moment.
  const double kappa = 0.05;  // 1/m: radius 20 m
  Vec6 bend;
  bend << 0, 0, 0, 0, 0.5 * kappa * l * l, kappa * l;
  Vec6 rigid;
  const double a = 0.004;
  rigid << 1e-4, -2e-4, a, 1e-4, -2e-4 + a * l, a;
  for (const Vec6& ee : {bend, Vec6(bend + rigid)}) {
    for (const double xi : {0.0, 0.13, 0.5, 0.77, 1.0}) {
      const Vec2 lin = el.sectionForces(ee, xi, false), nl = el.sectionForces(ee, xi, true);
      // the curvature row sums ~4 terms of size kappa: roundoff ~ eps EI kappa
      EXPECT_NEAR(lin.y(), EI * kappa, 1e-12 * EI * kappa) << "xi " << xi;
      EXPECT_NEAR(nl.y(), EI * kappa, 1e-12 * EI * kappa) << "xi " << xi;
      EXPECT_NEAR(lin.x(), 0.0, 1e-12 * EA * kappa * l) << "xi " << xi;
      if (ee == bend) {
        // with stiffening the membrane strain is the element average of v'^2/2 =
        // (kappa x)^2 / 2: kappa^2 l^2 / 6, the same at every section
        EXPECT_NEAR(nl.x(), EA * kappa * kappa * l * l / 6.0, 1e-12 * EA * kappa * kappa * l * l) << "xi " << xi;
      }
    }
  }
}

// ----- input checks -------------------------------------------------------------------

TEST(BeamElement2d, RejectsBadInputNamingTheOwner) {
  const std::string owner = "body 'rod': element 3";
  expectInputError([&] { BeamElement2d(Vec2(1, 2), Vec2(1, 2), kSteel, owner); }, {owner, "zero length"});
  expectInputError([&] { BeamElement2d(Vec2(1, 2), Vec2(1 + 1e-14, 2), kSteel, owner); }, {owner, "zero length"});
  const Vec2 a(0, 0), b(0.5, 0);
  auto with = [&](auto mutate) {
    BeamSection s = kSteel;
    mutate(s);
    return s;
  };
  const double nan = std::nan("");
  for (const double bad : {0.0, -1e-4, nan}) {
    expectInputError([&] { BeamElement2d(a, b, with([&](BeamSection& s) { s.area = bad; }), owner); }, {owner, "area"});
    expectInputError([&] { BeamElement2d(a, b, with([&](BeamSection& s) { s.inertia = bad; }), owner); },
                     {owner, "inertia"});
    expectInputError([&] { BeamElement2d(a, b, with([&](BeamSection& s) { s.youngsModulus = bad; }), owner); },
                     {owner, "youngs_modulus"});
    expectInputError([&] { BeamElement2d(a, b, with([&](BeamSection& s) { s.density = bad; }), owner); },
                     {owner, "density"});
  }
  expectInputError([&] { BeamElement2d(a, b, with([](BeamSection& s) { s.damping = -1e-3; }), owner); },
                   {owner, "damping"});
  expectInputError([&] { BeamElement2d(a, b, with([&](BeamSection& s) { s.damping = nan; }), owner); },
                   {owner, "damping"});
  expectInputError([&] { BeamElement2d(Vec2(nan, 0), b, kSteel, owner); }, {owner, "node coordinate"});
  // zero damping and tiny but positive values are valid
  EXPECT_NO_THROW(BeamElement2d(a, b, with([](BeamSection& s) { s.damping = 0.0; }), owner));
  EXPECT_NO_THROW(BeamElement2d(a, Vec2(1e-6, 0), kSteel, owner));
}

}  // namespace
}  // namespace flexmbd
