// Unit tests of the spatial Euler-Bernoulli beam element of the floating frame of
// reference formulation (elements/beam_element_3d, docs/spatial-flexible.md): every
// inertia invariant against a direct quadrature over the element's volume (and the
// kinetic energy of a moving, deforming element built from them), the stiffness against
// the closed-form Przemieniecki matrix, its six rigid modes at a general orientation,
// the strain energy derivatives against finite differences, the section forces of a
// loaded cantilever, nodally exact cantilever deflections, the convergence order of the
// cantilever's frequencies, the planar element reproduced in a plane, the section
// factories and the input checks.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "core/errors.hpp"
#include "elements/beam_element_2d.hpp"
#include "elements/beam_element_3d.hpp"
#include "elements/beam_section.hpp"
#include "tests/test_support.hpp"

namespace flexmbd {
namespace {

using namespace testsupport;

using Vec12 = BeamElement3d::Vec12;
using Row12 = BeamElement3d::Row12;
using Mat12 = BeamElement3d::Mat12;
using Mat3x12 = BeamElement3d::Mat3x12;

// Fixed seed: the random states are the same on every run (reproducible).
constexpr unsigned kSeed = 20250301u;
// Random states per derivative check.
constexpr int kSamples = 8;

// Element integrals against an independent quadrature: both sides are exact quadratures
// of polynomials (the element's 5-point rule, degree <= 9; the test's Golub-Welsch
// rules, whose nodes and weights carry ~1e-15 eigen-solver roundoff), so they differ by
// roundoff only: a few ulps times the ~10..100 terms summed, <~ 1e-14 of the largest
// entry compared. 1e-12 bounds that; a wrong coefficient or a missing term is an
// O(1e-2..1) relative error of the block it belongs to (each block is compared on its
// own scale).
constexpr double kQuadTol = 1e-12;
// Closed forms (written out here) vs the element: only the roundoff of a few products
// per entry, a few ulps.
constexpr double kExactTol = 1e-13;
// K r = 0 for a rigid mode r: the entries of K r cancel exactly; roundoff <= ~12 eps
// |K| |r| plus the rotation of r by T (another few eps).
constexpr double kRigidTol = 1e-13;
// Eigenvalues of the body-frame stiffness: the six rigid-mode eigenvalues are roundoff,
// <~ 20 eps lambda_max; the smallest elastic one (bending about y, 2 EIy / l for a pure
// rotation pair, against lambda_max ~ 2 EA / l) is Iy / (A l^2) ~ 1e-4 of lambda_max
// here. A threshold of 1e-10 lambda_max is six decades from either.
constexpr double kZeroEigenTol = 1e-10;
// Central differences of the strain energy: each coordinate stepped by
// kFdStepFraction * (its typical magnitude: displacements 1e-3 l, rotations 1e-2). U is
// a quartic in e: truncation h^2/6 d3U/de3 ~ 1e-10 relative of the nonlinear part,
// roundoff eps |e| / h ~ 2e-11 relative. Tolerance kFdTol relative to the largest entry
// compared (and the bending block on its own scale): a missing stiffening term is
// >= ~1e-3 relative.
constexpr double kFdStepFraction = 1e-5;
constexpr double kFdTol = 1e-7;

/// Gauss-Legendre rule with n points on [0, 1] (Golub-Welsch), independent of the
/// element's own rule.
void gaussRule(int n, std::vector<double>& xi, std::vector<double>& w) {
  MatX J = MatX::Zero(n, n);
  for (int k = 1; k < n; ++k) J(k, k - 1) = J(k - 1, k) = k / std::sqrt(4.0 * k * k - 1.0);
  const Eigen::SelfAdjointEigenSolver<MatX> es(J);
  xi.resize(n);
  w.resize(n);
  for (int k = 0; k < n; ++k) {
    xi[k] = 0.5 * (es.eigenvalues()[k] + 1.0);
    w[k] = es.eigenvectors()(0, k) * es.eigenvectors()(0, k);
  }
}

// A 3 cm (y) x 1.8 cm (z) steel bar (Iy != Iz, so swapped planes show), element of
// length 0.5 m at a general orientation in the body with a y hint not orthogonal to it.
constexpr double kWidthY = 0.03, kHeightZ = 0.018, kLength = 0.5;
const BeamSection3d kSteel = rectangularSection3d(kWidthY, kHeightZ, 2.1e11, 8.1e10, 7850.0, 1e-4);
const Vec3 kStart(0.1, -0.2, 0.3);
const Vec3 kAxis = Vec3(0.6, -0.3, 0.74).normalized();
const Vec3 kHint(0.2, 1.0, 0.5);

BeamElement3d makeElement(const BeamSection3d& s = kSteel) {
  return BeamElement3d(kStart, kStart + kLength * kAxis, kHint, s, "test element");
}

/// The point shape written out from the definition (not from the element's code):
/// centre line w_x = (1-xi) u1 + xi u2, w_y = h1 v1 + h2 tz1 + h3 v2 + h4 tz2,
/// w_z = h1 w1 - h2 ty1 + h3 w2 - h4 ty2, plus the twist tx e_x cross (0, y, z).
Mat3x12 referencePointShape(double xi, double y, double z, double l) {
  const double h1 = 1 - 3 * xi * xi + 2 * xi * xi * xi, h2 = l * (xi - 2 * xi * xi + xi * xi * xi);
  const double h3 = 3 * xi * xi - 2 * xi * xi * xi, h4 = l * (xi * xi * xi - xi * xi);
  const double tx1 = 1 - xi, tx2 = xi;
  Mat3x12 S = Mat3x12::Zero();
  //      u1       v1       w1       tx1           ty1      tz1      u2      v2       w2       tx2           ty2      tz2
  S.row(0) << 1 - xi, 0, 0, 0, 0, 0, xi, 0, 0, 0, 0, 0;
  S.row(1) << 0, h1, 0, -z * tx1, 0, h2, 0, h3, 0, -z * tx2, 0, h4;
  S.row(2) << 0, 0, h1, y * tx1, -h2, 0, 0, 0, h3, y * tx2, -h4, 0;
  return S;
}

/// A tensor Gauss rule over the element's volume (x along the element, y, z over the
/// b x h rectangle): nx x 4 x 4 points, exact for degree 2 nx - 1 in x and 7 in y, z.
struct VolumePoint {
  double xi, y, z, w;  // w includes dV = l b h dxi dy' dz'
};
std::vector<VolumePoint> volumeRule(int nx, double l) {
  std::vector<double> gx, wx, gs, ws;
  gaussRule(nx, gx, wx);
  gaussRule(4, gs, ws);
  std::vector<VolumePoint> pts;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 4; ++k)
        pts.push_back({gx[i], (gs[j] - 0.5) * kWidthY, (gs[k] - 0.5) * kHeightZ,
                       wx[i] * ws[j] * ws[k] * l * kWidthY * kHeightZ});
  return pts;
}

/// Random element coordinates of realistic magnitude: displacements ~1e-3 l, rotations ~1e-2.
Vec12 randomState(Random& rnd, double l) {
  Vec12 e;
  for (int n : {0, 6}) {
    for (int k = 0; k < 3; ++k) e[n + k] = rnd.uniform(-1e-3, 1e-3) * l;
    for (int k = 3; k < 6; ++k) e[n + k] = rnd.uniform(-1e-2, 1e-2);
  }
  return e;
}

Vec12 typicalMagnitude(double l) {
  Vec12 s;
  s << 1e-3 * l, 1e-3 * l, 1e-3 * l, 1e-2, 1e-2, 1e-2, 1e-3 * l, 1e-3 * l, 1e-3 * l, 1e-2, 1e-2, 1e-2;
  return s;
}

/// The matrix with its rows and columns of the given coordinates only (others zeroed).
Mat12 block(const Mat12& M, std::initializer_list<int> dofs) {
  Mat12 B = Mat12::Zero();
  for (int i : dofs)
    for (int j : dofs) B(i, j) = M(i, j);
  return B;
}
// Coordinates by kind (element frame): axial, twist, x-y bending (v, tz), x-z bending (w, ty).
const std::initializer_list<int> kAxialDofs = {0, 6}, kTwistDofs = {3, 9};
const std::initializer_list<int> kBendYDofs = {1, 5, 7, 11}, kBendZDofs = {2, 4, 8, 10};

// ----- inertia invariants -------------------------------------------------------------

TEST(BeamElement3d, InertiaInvariantsMatchVolumeQuadrature) {
  const BeamElement3d el = makeElement();
  const double l = el.length(), rho = kSteel.density;
  // 6 x 4 x 4 points: exact for the integrands (degree <= 7 in x, <= 2 in y and z)
  double m = 0.0;
  Vec3 first = Vec3::Zero();
  Mat3 second = Mat3::Zero();
  Mat3x12 sBar = Mat3x12::Zero(), skew = Mat3x12::Zero();
  Row12 dot = Row12::Zero();
  Mat12 sKL[3][3];
  Mat3x12 xS[3];
  for (int k = 0; k < 3; ++k) {
    xS[k].setZero();
    for (int j = 0; j < 3; ++j) sKL[k][j].setZero();
  }
  for (const VolumePoint& p : volumeRule(6, l)) {
    const Vec3 x0(p.xi * l, p.y, p.z);
    const Mat3x12 S = referencePointShape(p.xi, p.y, p.z, l);
    const double w = rho * p.w;
    m += w;
    first += w * x0;
    second += w * x0 * x0.transpose();
    sBar += w * S;
    for (int k = 0; k < 3; ++k) {
      xS[k] += w * x0[k] * S;
      for (int j = 0; j < 3; ++j) sKL[k][j] += w * S.row(k).transpose() * S.row(j);
    }
    for (int c = 0; c < 12; ++c) {
      skew.col(c) += w * x0.cross(S.col(c));
      dot[c] += w * x0.dot(S.col(c));
    }
    // the element's point shape is the definition
    expectMatrixNear(BeamElement3d::pointShape(p.xi, p.y, p.z, l), S, kExactTol, "point shape");
  }
  EXPECT_NEAR(el.mass(), m, kQuadTol * m);
  EXPECT_NEAR(el.mass(), rho * kSteel.area * l, kExactTol * m);
  expectMatrixNear(el.firstMoment(), first, kQuadTol, "first moment int rho x0 dV");
  // the diagonal of the second moment spans 5 decades: each entry on its own scale
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(el.secondMoment()(k, k), second(k, k), kQuadTol * second(k, k)) << "second moment " << k;
  }
  expectMatrixNear(el.secondMoment(), second, kQuadTol, "second moment int rho x0 x0^T dV");
  EXPECT_NEAR(el.secondMoment()(1, 1), rho * kSteel.inertiaZ * l, kExactTol * second(1, 1));
  EXPECT_NEAR(el.secondMoment()(2, 2), rho * kSteel.inertiaY * l, kExactTol * second(2, 2));
  expectMatrixNear(el.sBar(), sBar, kQuadTol, "S-bar");
  for (int k = 0; k < 3; ++k) {
    for (int j = 0; j < 3; ++j) {
      const std::string name = "S_" + std::string(1, "xyz"[k]) + std::string(1, "xyz"[j]);
      expectMatrixNear(el.sKL(k, j), sKL[k][j], kQuadTol, name);
      // the torsional inertia rho Iy, rho Iz int tx^T tx (~1e-5 of the rest) on its own scale
      expectMatrixNear(block(el.sKL(k, j), kTwistDofs), block(sKL[k][j], kTwistDofs), kQuadTol,
                       name + ", twist block", rho * kSteel.inertiaY * l);
      expectMatrixNear(el.sKL(j, k), el.sKL(k, j).transpose(), 0.0, name + " == S_lk^T (exactly)");
    }
    expectMatrixNear(el.positionShapeIntegral(k), xS[k], kQuadTol, "int rho x0_k S dV, k = " + std::to_string(k));
  }
  expectMatrixNear(el.skewPositionShapeIntegral(), skew, kQuadTol, "int rho x0~ S dV");
  expectMatrixNear(el.skewPositionShapeIntegral().row(0), skew.row(0), kQuadTol, "int rho x0~ S dV, torsion row");
  expectMatrixNear(el.positionDotShapeIntegral(), dot, kQuadTol, "int rho x0^T S dV");
  expectMatrixNear(el.massMatrix(), sKL[0][0] + sKL[1][1] + sKL[2][2], kQuadTol, "m_ff = S_xx + S_yy + S_zz");
  // the torsional mass is rho Ip l / 6 [2 1; 1 2] (a linear field over the polar moment)
  const double rIp = rho * kSteel.polarMoment() * l;
  EXPECT_NEAR(el.massMatrix()(3, 3), rIp / 3, kExactTol * rIp);
  EXPECT_NEAR(el.massMatrix()(3, 9), rIp / 6, kExactTol * rIp);
  // rigid translations carry the whole mass
  for (int k = 0; k < 3; ++k) {
    Vec12 t = Vec12::Zero();
    t[k] = t[6 + k] = 1.0;
    EXPECT_NEAR(t.dot(el.massMatrix() * t), m, kExactTol * m);
    expectMatrixNear(el.sBar() * t, m * Vec3::Unit(k), kExactTol, "S-bar of a translation");
  }
  std::printf("inertia invariants: mass %.6g kg, rho Ip l %.3e kg m^2\n", el.mass(), rIp);
}

TEST(BeamElement3d, InvariantsGiveTheKineticEnergyOfAMovingDeformingElement) {
  // The body-frame kinetic energy of the element, as the FFR body will form it from the
  // invariants (body frame at the instant aligned with the inertial frame; position R,
  // velocity Rdot, angular velocity omega; body-frame nodal coordinates q, qdot):
  //   r = R + u0 + u,  u0 = start + C x0,  u = C S T q,
  //   T = 1/2 int rho |Rdot + omega x (u0 + u) + C S T qdot|^2 dV,
  // against the same integral by the volume rule.
  Random rnd(kSeed);
  const BeamElement3d el = makeElement();
  const double l = el.length(), rho = kSteel.density;
  const Mat3& C = el.rotation();
  const Mat12& T = el.transformation();
  const Vec3& p0 = el.start();
  for (int s = 0; s < kSamples; ++s) {
    const Vec3 Rdot(rnd.uniform(-2, 2), rnd.uniform(-2, 2), rnd.uniform(-2, 2));
    const Vec3 omega(rnd.uniform(-5, 5), rnd.uniform(-5, 5), rnd.uniform(-5, 5));
    const Vec12 q = T.transpose() * randomState(rnd, l);
    const Vec12 qdot = T.transpose() * randomState(rnd, l) * 100.0;
    // direct quadrature (6 x 4 x 4 points, exact: the integrand has degree 6 in x and 2
    // in y, z)
    double Tq = 0.0;
    for (const VolumePoint& p : volumeRule(6, l)) {
      const Mat3x12 S = referencePointShape(p.xi, p.y, p.z, l);
      const Vec3 r = p0 + C * (Vec3(p.xi * l, p.y, p.z) + S * T * q);
      const Vec3 v = Rdot + omega.cross(r) + C * S * T * qdot;
      Tq += 0.5 * rho * p.w * v.squaredNorm();
    }
    // from the invariants
    const Vec12 e = T * q, ed = T * qdot;
    const double m = el.mass();
    const Vec3 sFirst = m * p0 + C * (el.firstMoment() + el.sBar() * e);  // int rho r dV (relative to R)
    // int rho r r^T dV = m p0 p0^T + p0 f^T + f p0^T + C [J + X + X^T + Q] C^T, f = C (first + S-bar e)
    Mat3 X, Q;  // X_kl = int rho x0_k (S e)_l dV, Q_kl = int rho (S e)_k (S e)_l dV
    for (int k = 0; k < 3; ++k) {
      X.row(k) = (el.positionShapeIntegral(k) * e).transpose();
      for (int j = 0; j < 3; ++j) Q(k, j) = e.dot(el.sKL(k, j) * e);
    }
    const Vec3 f = C * (el.firstMoment() + el.sBar() * e);
    const Mat3 rr = m * p0 * p0.transpose() + p0 * f.transpose() + f * p0.transpose() +
                    C * (el.secondMoment() + X + X.transpose() + Q) * C.transpose();
    const Mat3 inertia = rr.trace() * Mat3::Identity() - rr;  // int rho (r.r I - r r^T) dV
    // int rho r x (C S ed) dV = p0 x (C S-bar ed) + C [int rho x0~ S dV ed + int rho (S e) x (S ed) dV]
    Vec3 sxs;  // int rho (S e) x (S ed) dV: components e^T (S_yz - S_zy) ed, ...
    sxs << e.dot((el.sKL(1, 2) - el.sKL(2, 1)) * ed), e.dot((el.sKL(2, 0) - el.sKL(0, 2)) * ed),
        e.dot((el.sKL(0, 1) - el.sKL(1, 0)) * ed);
    const Vec3 hRel = p0.cross(C * el.sBar() * ed) + C * (el.skewPositionShapeIntegral() * ed + sxs);
    const double Ti = 0.5 * m * Rdot.squaredNorm() + Rdot.dot(omega.cross(sFirst)) + Rdot.dot(C * el.sBar() * ed) +
                      0.5 * omega.dot(inertia * omega) + omega.dot(hRel) + 0.5 * ed.dot(el.massMatrix() * ed);
    EXPECT_NEAR(Ti, Tq, kQuadTol * Tq) << "sample " << s;
    // the deformation-only parts on their own scale: int rho |S ed|^2 and the
    // rotation-deformation coupling int rho omega . (x0 x S ed) (includes the torsion row)
    double Tff = 0.0, Tcoup = 0.0, Tdot = 0.0;
    for (const VolumePoint& p : volumeRule(6, l)) {
      const Mat3x12 S = referencePointShape(p.xi, p.y, p.z, l);
      const Vec3 x0(p.xi * l, p.y, p.z);
      Tff += 0.5 * rho * p.w * (S * ed).squaredNorm();
      Tcoup += rho * p.w * (C.transpose() * omega).dot(x0.cross(S * ed));
      Tdot += rho * p.w * x0.dot(S * ed);
    }
    EXPECT_NEAR(0.5 * ed.dot(el.massMatrix() * ed), Tff, kQuadTol * Tff) << "sample " << s;
    EXPECT_NEAR((C.transpose() * omega).dot(el.skewPositionShapeIntegral() * ed), Tcoup,
                kQuadTol * std::abs(Tcoup) + 1e-300)
        << "sample " << s;
    EXPECT_NEAR(el.positionDotShapeIntegral() * ed, Tdot, kQuadTol * std::abs(Tdot)) << "sample " << s;
  }
}

TEST(BeamElement3d, TwistOnlyMotionHasThePolarInertiaOfTheSection) {
  // A uniform twist rate w about the element axis (tx = w t at both nodes): kinetic
  // energy rho Ip l w^2 / 2, angular momentum about x rho Ip l w, nothing else.
  const BeamElement3d el = makeElement();
  const double l = el.length(), rIp = kSteel.density * kSteel.polarMoment() * l;
  Vec12 ed = Vec12::Zero();
  ed[3] = ed[9] = 1.0;
  EXPECT_NEAR(0.5 * ed.dot(el.massMatrix() * ed), 0.5 * rIp, kExactTol * rIp);
  expectMatrixNear(el.skewPositionShapeIntegral() * ed, rIp * Vec3::UnitX(), kExactTol, "angular momentum of a twist");
  expectMatrixNear(el.sBar() * ed, Vec3::Zero(), 0.0, "linear momentum of a twist", 1.0);
}

// ----- stiffness ----------------------------------------------------------------------

/// The classic 12 x 12 Euler-Bernoulli space-frame stiffness (Przemieniecki, Theory of
/// Matrix Structural Analysis, 1968, eq. 5.116), written out entry by entry, dof order
/// (u1 v1 w1 tx1 ty1 tz1 u2 v2 w2 tx2 ty2 tz2).
Mat12 przemieniecki(double EA, double GJ, double EIy, double EIz, double l) {
  const double l2 = l * l, l3 = l2 * l;
  const double a = EA / l, t = GJ / l;
  const double z12 = 12 * EIz / l3, z6 = 6 * EIz / l2, z4 = 4 * EIz / l, z2 = 2 * EIz / l;
  const double y12 = 12 * EIy / l3, y6 = 6 * EIy / l2, y4 = 4 * EIy / l, y2 = 2 * EIy / l;
  Mat12 K;
  // clang-format off
  K <<  a,    0,    0,   0,   0,    0,  -a,    0,    0,   0,   0,    0,
        0,  z12,    0,   0,   0,   z6,   0, -z12,    0,   0,   0,   z6,
        0,    0,  y12,   0, -y6,    0,   0,    0, -y12,   0, -y6,    0,
        0,    0,    0,   t,   0,    0,   0,    0,    0,  -t,   0,    0,
        0,    0,  -y6,   0,  y4,    0,   0,    0,   y6,   0,  y2,    0,
        0,   z6,    0,   0,   0,   z4,   0,  -z6,    0,   0,   0,   z2,
       -a,    0,    0,   0,   0,    0,   a,    0,    0,   0,   0,    0,
        0, -z12,    0,   0,   0,  -z6,   0,  z12,    0,   0,   0,  -z6,
        0,    0, -y12,   0,  y6,    0,   0,    0,  y12,   0,  y6,    0,
        0,    0,    0,  -t,   0,    0,   0,    0,    0,   t,   0,    0,
        0,    0,  -y6,   0,  y2,    0,   0,    0,   y6,   0,  y4,    0,
        0,   z6,    0,   0,   0,   z2,   0,  -z6,    0,   0,   0,   z4;
  // clang-format on
  return K;
}

TEST(BeamElement3d, StiffnessIsTheClassicSpaceFrameMatrix) {
  const BeamElement3d el = makeElement();
  const BeamSection3d& s = kSteel;
  const double l = el.length();
  const Mat12& K = el.stiffness();
  expectMatrixNear(K, K.transpose(), 0.0, "K symmetric (exactly)");
  const Mat12 Kc = przemieniecki(s.axialStiffness(), s.torsionStiffness(), s.bendingStiffnessY(),
                                 s.bendingStiffnessZ(), l);
  // each row on its own scale: axial rows ~1e8, bending rows ~1e3..1e5
  const double worst = expectRowsNear(K, Kc, kExactTol, "K vs Przemieniecki");
  EXPECT_TRUE(((K.array() == 0.0) == (Kc.array() == 0.0)).all()) << "zero pattern";

  // independently: K = int (EA a^T a + GJ t'^T t' + EIz cy^T cy + EIy cz^T cz) dx from the
  // element's strain rows (6-point rule, exact: the integrand has degree 2)
  std::vector<double> xi, w;
  gaussRule(6, xi, w);
  Mat12 Kq = Mat12::Zero();
  const Row12 a = BeamElement3d::axialStrainShape(l), tr = BeamElement3d::twistRateShape(l);
  for (size_t g = 0; g < xi.size(); ++g) {
    const Row12 cy = BeamElement3d::curvatureShapeY(xi[g], l), cz = BeamElement3d::curvatureShapeZ(xi[g], l);
    Kq += w[g] * l *
          (s.axialStiffness() * a.transpose() * a + s.torsionStiffness() * tr.transpose() * tr +
           s.bendingStiffnessZ() * cy.transpose() * cy + s.bendingStiffnessY() * cz.transpose() * cz);
  }
  expectRowsNear(K, Kq, kQuadTol, "K vs quadrature of the strain rows");
  // the strain rows are derivatives of the shapes (central differences in xi: cubic and
  // quadratic polynomials, truncation h^2 |f'''| / 6 ~ 1e-10 and roundoff eps/h ~ 1e-11
  // relative to entries ~1/l)
  for (const double x : {0.1, 0.37, 0.8}) {
    const double h = 1e-5;
    auto d = [&](auto f) { return Row12((f(x + h) - f(x - h)) / (2 * h * l)); };
    const auto S = [&](int row) { return [&, row](double z) { return Row12(BeamElement3d::shape(z, l).row(row)); }; };
    expectMatrixNear(BeamElement3d::axialStrainShape(l), d(S(0)), 1e-9, "axial strain row");
    expectMatrixNear(BeamElement3d::slopeShapeY(x, l), d(S(1)), 1e-9, "slope row y");
    expectMatrixNear(BeamElement3d::slopeShapeZ(x, l), d(S(2)), 1e-9, "slope row z");
    expectMatrixNear(BeamElement3d::twistRateShape(l), d([](double z) { return BeamElement3d::twistShape(z); }), 1e-9,
                     "twist rate row");
    expectMatrixNear(BeamElement3d::curvatureShapeY(x, l),
                     d([&](double z) { return BeamElement3d::slopeShapeY(z, l); }), 1e-9, "curvature row y");
    expectMatrixNear(BeamElement3d::curvatureShapeZ(x, l),
                     d([&](double z) { return BeamElement3d::slopeShapeZ(z, l); }), 1e-9, "curvature row z");
  }
  // the rotations are the slopes: tz = v' and ty = -w' at the nodes
  for (const double x : {0.0, 1.0}) {
    const int n = x == 0.0 ? 0 : 6;
    EXPECT_EQ(BeamElement3d::slopeShapeY(x, l), Row12(Row12::Unit(n + 5))) << "tz = v' at xi " << x;
    EXPECT_EQ(BeamElement3d::slopeShapeZ(x, l), Row12(-Row12::Unit(n + 4))) << "ty = -w' at xi " << x;
  }
  std::printf("stiffness vs Przemieniecki: worst row-relative error %.2e\n", worst);
}

TEST(BeamElement3d, StiffnessHasExactlySixRigidModesAtAGeneralOrientation) {
  const BeamElement3d el = makeElement();
  const Mat12 Kb = el.transformation().transpose() * el.stiffness() * el.transformation();  // body frame
  const Vec3 nodes[2] = {el.start(), el.end()};
  std::vector<Vec12> modes;
  for (int k = 0; k < 3; ++k) {
    Vec12 t = Vec12::Zero();  // translation along body axis k
    t[k] = t[6 + k] = 1.0;
    modes.push_back(t);
    Vec12 r;  // small rotation phi about body axis k (about the body origin): u = phi x x_node
    const Vec3 phi = 0.01 * Vec3::Unit(k);
    for (int n = 0; n < 2; ++n) {
      r.segment<3>(6 * n) = phi.cross(nodes[n]);
      r.segment<3>(6 * n + 3) = phi;
    }
    modes.push_back(r);
  }
  const double kmax = Kb.cwiseAbs().maxCoeff();
  double worst = 0.0;
  for (const Vec12& r : modes) {
    const double res = (Kb * r).cwiseAbs().maxCoeff() / (kmax * r.cwiseAbs().maxCoeff());
    worst = std::max(worst, res);
    EXPECT_LE(res, kRigidTol) << r.transpose();
    EXPECT_LE(std::abs(el.strainEnergy(el.transformation() * r, false)), kRigidTol * kmax * r.squaredNorm());
  }
  // exact rigid translations (any size) carry no strain energy with stiffening either
  for (int k = 0; k < 3; ++k) {
    const Vec12 e = el.transformation() * (0.3 * modes[2 * k]);
    EXPECT_LE(std::abs(el.strainEnergy(e, true)), kRigidTol * kmax * e.squaredNorm()) << "translation " << k;
  }
  const Eigen::SelfAdjointEigenSolver<Mat12> es(Kb);
  const auto lambda = es.eigenvalues();
  const double lmax = lambda.maxCoeff();
  int zeros = 0;
  for (int k = 0; k < 12; ++k) {
    EXPECT_GE(lambda[k], -kZeroEigenTol * lmax) << "eigenvalue " << k;
    if (std::abs(lambda[k]) <= kZeroEigenTol * lmax) {
      ++zeros;
    } else {
      EXPECT_GE(lambda[k], 1e-7 * lmax) << "elastic eigenvalue " << k << " too close to zero";
    }
  }
  EXPECT_EQ(zeros, 6) << "eigenvalues of T^T K T: " << lambda.transpose();
  std::printf("rigid modes: worst |K T r| / (|K| |r|) = %.2e\n", worst);
}

// ----- strain energy derivatives ----------------------------------------------------

TEST(BeamElement3d, StrainEnergyDerivativesMatchFiniteDifferences) {
  Random rnd(kSeed + 1);
  const BeamElement3d el = makeElement();
  const Vec12 mag = typicalMagnitude(el.length());
  double worstG = 0.0, worstH = 0.0;
  for (const bool stiff : {false, true}) {
    for (int s = 0; s < kSamples; ++s) {
      const Vec12 e = randomState(rnd, el.length());
      const std::string what = std::string(stiff ? "stiffening" : "linear") + " sample " + std::to_string(s);
      Vec12 gFd;
      Mat12 HFd;
      for (int k = 0; k < 12; ++k) {
        const double h = kFdStepFraction * mag[k];
        Vec12 ep = e, em = e;
        ep[k] += h;
        em[k] -= h;
        gFd[k] = (el.strainEnergy(ep, stiff) - el.strainEnergy(em, stiff)) / (2 * h);
        HFd.col(k) = (el.strainEnergyGradient(ep, stiff) - el.strainEnergyGradient(em, stiff)) / (2 * h);
      }
      const Vec12 g = el.strainEnergyGradient(e, stiff);
      const Mat12 H = el.strainEnergyHessian(e, stiff);
      worstG = std::max(worstG, expectMatrixNear(g, gFd, kFdTol, what + ": gradient vs FD of U"));
      worstH = std::max(worstH, expectMatrixNear(H, HFd, kFdTol, what + ": Hessian vs FD of gradient"));
      // bending and torsion entries are ~1e-4 of the axial ones: compared on their own scale
      for (const auto& dofs : {kTwistDofs, kBendYDofs, kBendZDofs}) {
        worstH = std::max(worstH, expectMatrixNear(block(H, dofs), block(HFd, dofs), kFdTol, what + ": Hessian block"));
      }
      expectMatrixNear(H, H.transpose(), 1e-14, what + ": Hessian symmetric");
      if (!stiff) {
        EXPECT_TRUE(g == el.stiffness() * e) << what;
        EXPECT_TRUE(H == el.stiffness()) << what;
      } else {
        // the stiffening terms are O(slope^2 ~ 1e-4) against strains ~ 4e-3: present but small
        const Vec12 gl = el.strainEnergyGradient(e, false);
        EXPECT_LE((g - gl).norm(), 0.2 * gl.norm()) << what;
        EXPECT_GT((g - gl).norm(), 1e-8 * gl.norm()) << what << ": stiffening has no effect";
        // the averaged membrane strain, against its definition by a 10-point rule
        std::vector<double> xi, w;
        gaussRule(10, xi, w);
        double mean = 0.0;
        for (size_t q = 0; q < xi.size(); ++q) {
          const double vp = BeamElement3d::slopeShapeY(xi[q], el.length()).dot(e);
          const double wp = BeamElement3d::slopeShapeZ(xi[q], el.length()).dot(e);
          mean += w[q] * 0.5 * (vp * vp + wp * wp);
        }
        const double eps = BeamElement3d::axialStrainShape(el.length()).dot(e) + mean;
        EXPECT_NEAR(el.membraneStrain(e, true), eps, kQuadTol * std::abs(eps) + 1e-15 * mean) << what;
      }
    }
  }
  RecordProperty("worst_gradient_rel_error", std::to_string(worstG));
  RecordProperty("worst_hessian_rel_error", std::to_string(worstH));
  std::printf("strain energy FD: worst gradient rel error %.2e, worst Hessian rel error %.2e\n", worstG, worstH);
}

TEST(BeamElement3d, StretchedElementHessianIsStiffnessPlusGeometricStiffness) {
  // Axial stretch delta, no transverse deformation: eps_m = delta / l exactly and G e = 0,
  // so H = K + N K_g with N = EA delta / l and K_g the classic geometric stiffness
  // (Przemieniecki eq. 15.xx; 1/(30 l) [36, 3l, -36, 3l; 3l, 4l^2, -3l, -l^2; ...]) in
  // both bending planes (x-z with the ty = -w' signs); torsion and axial unchanged
  // (no Wagner term). Exact relation: roundoff tolerance.
  const BeamElement3d el = makeElement();
  const double l = el.length(), EA = kSteel.axialStiffness(), delta = 1e-3 * l, N = EA * delta / l;
  Vec12 e = Vec12::Zero();
  e[0] = 2e-4;
  e[6] = 2e-4 + delta;
  const double kg[4][4] = {{36, 3 * l, -36, 3 * l},
                           {3 * l, 4 * l * l, -3 * l, -l * l},
                           {-36, -3 * l, 36, -3 * l},
                           {3 * l, -l * l, -3 * l, 4 * l * l}};
  const int by[4] = {1, 5, 7, 11}, bz[4] = {2, 4, 8, 10};
  const double sg[4] = {1, -1, 1, -1};
  Mat12 Kg = Mat12::Zero();
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) {
      Kg(by[i], by[j]) = N / (30 * l) * kg[i][j];
      Kg(bz[i], bz[j]) = N / (30 * l) * sg[i] * sg[j] * kg[i][j];
    }
  }
  const Mat12 H = el.strainEnergyHessian(e, true), K = el.stiffness();
  for (const auto& dofs : {kBendYDofs, kBendZDofs, kTwistDofs, kAxialDofs}) {
    expectMatrixNear(block(H, dofs), block(K + Kg, dofs), kExactTol, "H block vs K + N K_g");
  }
  expectMatrixNear(H, K + Kg, kExactTol, "H vs K + N K_g (no coupling between kinds)");
}

// ----- section forces -------------------------------------------------------------------

TEST(BeamElement3d, SectionForcesOfALoadedCantileverElementFollowStatics) {
  // One element clamped at node 1, loaded at node 2 by a force F along y, along z, along
  // x and a torque Mt about x. Its exact displacement field lies in the element's space
  // (cubic v, w; linear u, tx), so the element solution is exact and the section forces
  // at every xi must be the resultants of the load beyond the section: along y
  // Q = F e_y, M = (l - x) e_x cross F e_y = F (l - x) e_z; along z Q = F e_z,
  // M = -F (l - x) e_y; N = F; Mx = Mt.
  const BeamElement3d el = makeElement();
  const double l = el.length(), F = 250.0, Mt = 40.0;
  const Mat12& K = el.stiffness();
  const std::vector<int> free = {6, 7, 8, 9, 10, 11};
  Eigen::Matrix<double, 6, 6> Kff;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) Kff(i, j) = K(free[i], free[j]);
  const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> ldlt(Kff);
  auto solve = [&](int dof, double load) {
    Eigen::Matrix<double, 6, 1> f = Eigen::Matrix<double, 6, 1>::Zero();
    f[dof - 6] = load;
    const Eigen::Matrix<double, 6, 1> x = ldlt.solve(f);
    Vec12 e = Vec12::Zero();
    e.tail<6>() = x;
    return e;
  };
  // tolerance: the solve carries cond(Kff) eps ~ 1e-16 * 1e5 relative; the forces are
  // rows of K times e: 1e-9 of the load scale bounds both.
  constexpr double kStaticsTol = 1e-9;
  const Vec12 ey = solve(7, F), ez = solve(8, F), ex = solve(6, F), et = solve(9, Mt);
  {
    const bool stiff = false;
    for (const double xi : {0.0, 0.3, 0.5, 1.0}) {
      const double arm = (1.0 - xi) * l;
      const BeamSectionForces3d fy = el.sectionForces(ey, xi, stiff), fz = el.sectionForces(ez, xi, stiff);
      const BeamSectionForces3d fx = el.sectionForces(ex, xi, stiff), ft = el.sectionForces(et, xi, stiff);
      const double tolF = kStaticsTol * F, tolM = kStaticsTol * F * l;
      EXPECT_NEAR(fy.Qy, F, tolF);
      EXPECT_NEAR(fy.Mz, F * arm, tolM);
      EXPECT_NEAR(fy.Qz, 0.0, tolF);
      EXPECT_NEAR(fy.My, 0.0, tolM);
      EXPECT_NEAR(fy.N, 0.0, tolF);
      EXPECT_NEAR(fy.Mx, 0.0, tolM);
      EXPECT_NEAR(fz.Qz, F, tolF);
      EXPECT_NEAR(fz.My, -F * arm, tolM);
      EXPECT_NEAR(fz.Qy, 0.0, tolF);
      EXPECT_NEAR(fz.Mz, 0.0, tolM);
      EXPECT_NEAR(fx.N, F, tolF);
      EXPECT_NEAR(fx.Mz, 0.0, tolM);
      EXPECT_NEAR(ft.Mx, Mt, kStaticsTol * Mt);
      EXPECT_NEAR(ft.N, 0.0, tolF);
      EXPECT_NEAR(ft.My, 0.0, tolM);
    }
  }
  // tip rotations have the signs of the convention: a +z tip load turns the section by
  // ty = -w' < 0 (about -y), a +y load by tz = v' > 0
  EXPECT_LT(ez[10], 0.0);
  EXPECT_GT(ey[11], 0.0);
  // with stiffening and a transverse deflection the axial force is EA times the averaged
  // v'^2/2: the element's v' = F x (2l - x) / (2 EIz), mean of v'^2/2 = F^2 l^4 / (15 EIz^2)
  const double EIz = kSteel.bendingStiffnessZ();
  const double meanHalfSlope2 = F * F * l * l * l * l / (15.0 * EIz * EIz);
  EXPECT_NEAR(el.sectionForces(ey, 0.4, true).N, kSteel.axialStiffness() * meanHalfSlope2,
              1e-9 * kSteel.axialStiffness() * meanHalfSlope2);
}

// ----- assembled cantilevers ------------------------------------------------------------

/// n equal elements from `origin` along `axis` (body frame), section y axis from
/// `hint`; K and M in body-frame nodal coordinates (6 per node, node i at 6 i).
struct Cantilever {
  std::vector<BeamElement3d> elements;
  MatX K, M;
};
Cantilever assemble(int n, double L, const BeamSection3d& s, const Vec3& origin, const Vec3& axis, const Vec3& hint) {
  Cantilever c;
  const int nd = 6 * (n + 1);
  c.K = MatX::Zero(nd, nd);
  c.M = MatX::Zero(nd, nd);
  for (int i = 0; i < n; ++i) {
    c.elements.emplace_back(origin + (L * i / n) * axis, origin + (L * (i + 1) / n) * axis, hint, s,
                            "element " + std::to_string(i));
    const BeamElement3d& el = c.elements.back();
    const Mat12& T = el.transformation();
    c.K.block<12, 12>(6 * i, 6 * i) += T.transpose() * el.stiffness() * T;
    c.M.block<12, 12>(6 * i, 6 * i) += T.transpose() * el.massMatrix() * T;
  }
  return c;
}

TEST(BeamElement3d, CantileverTipDeflectionsAreNodallyExact) {
  // L = 2 m, 5 elements along a general direction; clamped at node 0 (its 6 coordinates
  // removed). Loads at the tip in the beam's own axes (body-frame vectors C e_y, C e_z,
  // C e_x): exact Euler-Bernoulli solutions, reproduced at every node by Hermite /
  // linear elements with nodal loads:
  //   F e_y: v(x) = F x^2 (3L - x) / (6 EIz), rotation about e_z: F x (2L - x) / (2 EIz);
  //   F e_z: w(x) = F x^2 (3L - x) / (6 EIy), rotation about e_y: -F x (2L - x) / (2 EIy);
  //   torque Mt e_x: twist Mt x / (GJ);  F e_x: u = F x / (EA).
  const int n = 5;
  const double L = 2.0, F = 120.0, Mt = 15.0;
  const Cantilever c = assemble(n, L, kSteel, kStart, kAxis, kHint);
  const Mat3& C = c.elements.front().rotation();
  const int nf = 6 * n;
  const MatX Kff = c.K.bottomRightCorner(nf, nf);
  const Eigen::LDLT<MatX> ldlt(Kff);
  ASSERT_EQ(ldlt.info(), Eigen::Success);
  const double EIz = kSteel.bendingStiffnessZ(), EIy = kSteel.bendingStiffnessY();
  const double GJ = kSteel.torsionStiffness(), EA = kSteel.axialStiffness();
  // tolerance: the solve carries ~cond(Kff) eps of the largest displacement; cond(Kff)
  // ~ (EA / l) / (EIy / L^3) ~ 1e7 here bounds that by ~2e-9 (measured <= 7.4e-12: the
  // bound is pessimistic); 1e-8 of the largest nodal value, while a wrong section
  // constant, sign or plane is an O(1) error.
  constexpr double kNodalTol = 1e-8;
  struct Load {
    const char* name;
    Vec3 force, moment;
    std::function<Vec3(double)> disp, rot;  // exact, element axes
  };
  const std::vector<Load> loads = {
      {"F e_y", Vec3(0, F, 0), Vec3::Zero(),
       [&](double x) { return Vec3(0, F * x * x * (3 * L - x) / (6 * EIz), 0); },
       [&](double x) { return Vec3(0, 0, F * x * (2 * L - x) / (2 * EIz)); }},
      {"F e_z", Vec3(0, 0, F), Vec3::Zero(),
       [&](double x) { return Vec3(0, 0, F * x * x * (3 * L - x) / (6 * EIy)); },
       [&](double x) { return Vec3(0, -F * x * (2 * L - x) / (2 * EIy), 0); }},
      {"Mt e_x", Vec3::Zero(), Vec3(Mt, 0, 0), [](double) { return Vec3::Zero(); },
       [&](double x) { return Vec3(Mt * x / GJ, 0, 0); }},
      {"F e_x", Vec3(F, 0, 0), Vec3::Zero(), [&](double x) { return Vec3(F * x / EA, 0, 0); },
       [](double) { return Vec3::Zero(); }},
  };
  for (const Load& ld : loads) {
    VecX f = VecX::Zero(nf);
    f.segment<3>(nf - 6) = C * ld.force;
    f.segment<3>(nf - 3) = C * ld.moment;
    const VecX q = ldlt.solve(f);
    VecX exact(nf);
    for (int i = 1; i <= n; ++i) {
      const double x = L * i / n;
      exact.segment<3>(6 * (i - 1)) = C * ld.disp(x);
      exact.segment<3>(6 * (i - 1) + 3) = C * ld.rot(x);
    }
    const double scale = exact.cwiseAbs().maxCoeff();
    const double err = (q - exact).cwiseAbs().maxCoeff() / scale;
    EXPECT_LE(err, kNodalTol) << ld.name << "\nFE:\n" << q.transpose() << "\nexact:\n" << exact.transpose();
    std::printf("cantilever %s: tip %.6e (exact %.6e), max nodal rel error %.2e\n", ld.name,
                q.segment<6>(nf - 6).cwiseAbs().maxCoeff(), exact.segment<6>(nf - 6).cwiseAbs().maxCoeff(), err);
  }
  // the closed-form tip values themselves, as stated
  VecX f = VecX::Zero(nf);
  f.segment<3>(nf - 6) = C * Vec3(0, F, 0);
  EXPECT_NEAR((C.transpose() * ldlt.solve(f).segment<3>(nf - 6)).y(), F * L * L * L / (3 * EIz),
              kNodalTol * F * L * L * L / (3 * EIz));
  f.setZero();
  f.segment<3>(nf - 6) = C * Vec3(0, 0, F);
  EXPECT_NEAR((C.transpose() * ldlt.solve(f).segment<3>(nf - 6)).z(), F * L * L * L / (3 * EIy),
              kNodalTol * F * L * L * L / (3 * EIy));
  f.setZero();
  f.segment<3>(nf - 3) = C * Vec3(Mt, 0, 0);
  EXPECT_NEAR((C.transpose() * ldlt.solve(f).segment<3>(nf - 3)).x(), Mt * L / GJ, kNodalTol * Mt * L / GJ);
}

TEST(BeamElement3d, CantileverFrequenciesConvergeAtTheElementOrder) {
  // Consistent mass (m_ff = S_xx + S_yy + S_zz per element) and stiffness of a clamped
  // cantilever, L = 1 m, along the body x axis (element frame = body frame). A stocky
  // 8 x 5 cm section keeps lambda_max / lambda_1 ~ 1e6, so eigenvalue roundoff (~eps
  // lambda_max) stays ~1e-10 of the bending frequencies, three decades below the
  // smallest discretisation error measured (1.3e-7, bending with 16 elements). Continuum (Euler-Bernoulli, St Venant):
  //   bending: (beta_1 L)^2 sqrt(EI / (rho A L^4)), beta_1 L = 1.87510407;
  //   torsion: pi / (2L) sqrt(GJ / (rho Ip));  axial: pi / (2L) sqrt(E / rho).
  // Rayleigh-Ritz with consistent mass: every FE frequency is an upper bound. Errors of
  // the eigenvalue are O(h^(2(p+1-m))): Hermite cubics (p = 3, m = 2) give h^4 (ratio 16
  // per halving), linear axial and twist (p = 1, m = 1) h^2 (ratio 4).
  const double L = 1.0;
  const BeamSection3d s = rectangularSection3d(0.08, 0.05, 2.1e11, 8.1e10, 7850.0);
  const double rhoA = s.massPerLength();
  const double b1 = 1.87510407 * 1.87510407;
  const double exactBy = b1 * std::sqrt(s.bendingStiffnessZ() / (rhoA * std::pow(L, 4)));  // x-y plane, Iz
  const double exactBz = b1 * std::sqrt(s.bendingStiffnessY() / (rhoA * std::pow(L, 4)));  // x-z plane, Iy
  const double exactT = kPi / (2 * L) * std::sqrt(s.torsionStiffness() / (s.density * s.polarMoment()));
  const double exactA = kPi / (2 * L) * std::sqrt(s.youngsModulus / s.density);
  const char* names[4] = {"bending x-y", "bending x-z", "torsion", "axial"};
  const double exact[4] = {exactBy, exactBz, exactT, exactA};
  const int kinds[4][4] = {{1, 5, -1, -1}, {2, 4, -1, -1}, {3, -1, -1, -1}, {0, -1, -1, -1}};
  const std::vector<int> meshes = {4, 8, 16};
  std::vector<std::array<double, 4>> err;
  for (const int n : meshes) {
    const Cantilever c = assemble(n, L, s, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY());
    const int nf = 6 * n;
    const MatX Kff = c.K.bottomRightCorner(nf, nf), Mff = c.M.bottomRightCorner(nf, nf);
    const Eigen::GeneralizedSelfAdjointEigenSolver<MatX> es(Kff, Mff);
    ASSERT_EQ(es.info(), Eigen::Success);
    std::array<double, 4> e{};
    for (int kind = 0; kind < 4; ++kind) {
      // the lowest mode whose kinetic energy lies in this kind's coordinates (a straight
      // beam decouples the four kinds exactly)
      double omega = -1.0;
      for (int m = 0; m < nf && omega < 0; ++m) {
        const VecX phi = es.eigenvectors().col(m);
        double part = 0.0, total = phi.dot(Mff * phi);
        VecX sel = VecX::Zero(nf);
        for (int i = 0; i < n; ++i)
          for (int d : kinds[kind])
            if (d >= 0) sel[6 * i + d] = phi[6 * i + d];
        part = sel.dot(Mff * sel);
        if (part > 0.99 * total) omega = std::sqrt(es.eigenvalues()[m]);
      }
      ASSERT_GT(omega, 0.0) << names[kind] << ": no mode found";
      e[kind] = omega / exact[kind] - 1.0;
      // upper bound (less the eigenvalue roundoff ~1e-10)
      EXPECT_GT(e[kind], -1e-9) << names[kind] << ", n = " << n;
    }
    std::printf("n = %2d: rel. frequency errors bending x-y %.3e, x-z %.3e, torsion %.3e, axial %.3e\n", n, e[0],
                e[1], e[2], e[3]);
    err.push_back(e);
  }
  // observed order log2(e(n) / e(2n)) at the two finest meshes: 4 for bending, 2 for
  // torsion and axial; +-0.15 admits the pre-asymptotic h^(p+1) terms (measured within
  // 0.02 of the nominal order).
  constexpr double kOrderTol = 0.15;
  const double nominal[4] = {4.0, 4.0, 2.0, 2.0};
  for (int kind = 0; kind < 4; ++kind) {
    for (size_t k = 1; k < meshes.size(); ++k) {
      const double order = std::log2(err[k - 1][kind] / err[k][kind]);
      std::printf("%s: observed order %d -> %d elements: %.3f\n", names[kind], meshes[k - 1], meshes[k], order);
      if (k + 1 == meshes.size()) {
        EXPECT_NEAR(order, nominal[kind], kOrderTol) << names[kind];
      }
    }
  }
  // and the errors are small: Hermite elements give the fundamental to ~1e-5 with 4
  EXPECT_LT(err[0][0], 1e-4);
  EXPECT_LT(err.back()[2], 2e-3);
}

// ----- the planar element in a plane ---------------------------------------------------

TEST(BeamElement3d, ElementInAPlaneReproducesThePlanarElement) {
  // In the body x-y plane at 35 degrees, with a y hint in that plane: element z = body z.
  // Body-frame in-plane coordinates (ux, uy, thz) of both nodes (indices 0, 1, 5, 6, 7,
  // 11) against the planar element's (ux, uy, psi): mass, stiffness, S-bar, the strain
  // energy with stiffening, and no coupling to the out-of-plane coordinates.
  const double beta = 35.0 * kPi / 180.0, l = 0.4;
  const Vec2 a2(0.1, -0.2), b2 = a2 + l * Vec2(std::cos(beta), std::sin(beta));
  BeamSection s2;
  s2.area = kSteel.area;
  s2.inertia = kSteel.inertiaZ;
  s2.youngsModulus = kSteel.youngsModulus;
  s2.density = kSteel.density;
  const BeamElement2d p(a2, b2, s2, "planar");
  const BeamElement3d el(lift(a2), lift(b2), Vec3(0.3, 1.0, 0.0), kSteel, "spatial");
  expectMatrixNear(el.rotation().col(2), Vec3::UnitZ(), kExactTol, "element z = body z");
  const int in[6] = {0, 1, 5, 6, 7, 11}, out[6] = {2, 3, 4, 8, 9, 10};
  const Mat12& T = el.transformation();
  const Mat12 M3 = T.transpose() * el.massMatrix() * T, K3 = T.transpose() * el.stiffness() * T;
  const BeamElement2d::Mat6 M2 = p.transformation().transpose() * (p.sXX() + p.sYY()) * p.transformation();
  const BeamElement2d::Mat6 K2 = p.transformation().transpose() * p.stiffness() * p.transformation();
  BeamElement2d::Mat6 Min, Kin;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) {
      Min(i, j) = M3(in[i], in[j]);
      Kin(i, j) = K3(in[i], in[j]);
    }
  const double worstM = expectMatrixNear(Min, M2, kExactTol, "in-plane mass block");
  const double worstK = expectRowsNear(Kin, K2, kExactTol, "in-plane stiffness block");
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) {
      EXPECT_LE(std::abs(M3(in[i], out[j])), kExactTol * M3.cwiseAbs().maxCoeff()) << "mass coupling " << i << j;
      EXPECT_LE(std::abs(K3(in[i], out[j])), kExactTol * K3.cwiseAbs().maxCoeff()) << "stiffness coupling " << i << j;
    }
  // S-bar in the body frame, in-plane rows and columns
  const Mat3x12 sb3 = el.rotation() * el.sBar() * T;
  const BeamElement2d::Mat26 sb2 = rotation(beta) * p.sBar() * p.transformation();
  for (int r = 0; r < 2; ++r)
    for (int j = 0; j < 6; ++j) EXPECT_NEAR(sb3(r, in[j]), sb2(r, j), kExactTol * p.mass()) << r << "," << j;
  // element frame: S_xx, S_yy, S_xy in-plane blocks, and int rho x S dV
  const int ie[6] = {0, 1, 5, 6, 7, 11};
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) {
      EXPECT_NEAR(el.sKL(0, 0)(ie[i], ie[j]), p.sXX()(i, j), kExactTol * p.mass());
      EXPECT_NEAR(el.sKL(1, 1)(ie[i], ie[j]), p.sYY()(i, j), kExactTol * p.mass());
      EXPECT_NEAR(el.sKL(0, 1)(ie[i], ie[j]), p.sXY()(i, j), kExactTol * p.mass());
    }
    for (int r = 0; r < 2; ++r) EXPECT_NEAR(el.positionShapeIntegral(0)(r, ie[i]), p.sX()(r, i), kExactTol * p.mass() * l);
  }
  // strain energy (with stiffening) of in-plane states
  Random rnd(kSeed + 2);
  for (int k = 0; k < kSamples; ++k) {
    Vec12 e = randomState(rnd, l);
    for (int o : out) e[o] = 0.0;
    BeamElement2d::Vec6 e2;
    for (int i = 0; i < 6; ++i) e2[i] = e[ie[i]];
    for (const bool stiff : {false, true}) {
      const double U2 = p.strainEnergy(e2, stiff);
      EXPECT_NEAR(el.strainEnergy(e, stiff), U2, kExactTol * U2);
      EXPECT_NEAR(el.membraneStrain(e, stiff), p.membraneStrain(e2, stiff), kExactTol * std::abs(p.membraneStrain(e2, stiff)));
    }
  }
  std::printf("planar equivalence: mass block rel error %.2e, stiffness block %.2e\n", worstM, worstK);
}

// ----- sections -------------------------------------------------------------------------

TEST(BeamSection3d, FactoriesGiveTheClassicSectionConstants) {
  // Rectangle: J = k1 a b^3 with k1 tabulated by Timoshenko & Goodier (Theory of
  // Elasticity, sec. 109, table 3 digits): the series must agree to half a unit in
  // the third digit.
  const double ratios[] = {1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 10.0};
  const double k1[] = {0.141, 0.196, 0.229, 0.249, 0.263, 0.281, 0.291, 0.312};
  constexpr double kTableTol = 5e-4;
  for (int i = 0; i < 8; ++i) {
    const double b = 0.01, a = ratios[i] * b;
    for (const bool tall : {false, true}) {  // either side may be the longer one
      const BeamSection3d s = tall ? rectangularSection3d(b, a, 1, 1, 1) : rectangularSection3d(a, b, 1, 1, 1);
      EXPECT_NEAR(s.torsionConstant / (a * b * b * b), k1[i], kTableTol) << "a/b = " << ratios[i];
    }
  }
  // the thin-strip limit a b^3 / 3 (1 - 0.630 b / a) (Roark's approximation; its error
  // is O((b/a)^5), <1e-9 at a/b = 50)
  {
    const double b = 0.001, a = 0.05;
    const BeamSection3d s = rectangularSection3d(a, b, 1, 1, 1);
    EXPECT_NEAR(s.torsionConstant, a * b * b * b / 3 * (1 - 0.630249 * b / a), 1e-7 * a * b * b * b);
  }
  const BeamSection3d r = rectangularSection3d(0.03, 0.018, 2e11, 8e10, 7800.0, 1e-3);
  EXPECT_DOUBLE_EQ(r.area, 0.03 * 0.018);
  EXPECT_DOUBLE_EQ(r.inertiaZ, 0.018 * 0.03 * 0.03 * 0.03 / 12);  // int y^2 dA, y along the 3 cm side
  EXPECT_DOUBLE_EQ(r.inertiaY, 0.03 * 0.018 * 0.018 * 0.018 / 12);
  EXPECT_EQ(r.shearModulus, 8e10);
  EXPECT_EQ(r.damping, 1e-3);
  EXPECT_NO_THROW(r.validate("r"));
  const double d = 0.02;
  const BeamSection3d c = circularSection3d(d, 2e11, 8e10, 7800.0);
  EXPECT_DOUBLE_EQ(c.area, kPi * d * d / 4);
  EXPECT_DOUBLE_EQ(c.inertiaY, kPi * std::pow(d, 4) / 64);
  EXPECT_DOUBLE_EQ(c.inertiaZ, c.inertiaY);
  EXPECT_DOUBLE_EQ(c.torsionConstant, c.polarMoment());  // J = Ip = pi d^4 / 32
  EXPECT_NO_THROW(c.validate("c"));
}

// ----- input checks -------------------------------------------------------------------

TEST(BeamElement3d, RejectsBadInputNamingTheOwner) {
  const std::string owner = "body 'frame': element 7";
  const Vec3 a(0, 0, 0), b(0.5, 0, 0), hint(0, 1, 0);
  const double nan = std::nan(""), inf = std::numeric_limits<double>::infinity();
  expectInputError([&] { BeamElement3d(a, a, hint, kSteel, owner); }, {owner, "zero length"});
  expectInputError([&] { BeamElement3d(a, Vec3(1e-14, 0, 0), hint, kSteel, owner); }, {owner, "zero length"});
  expectInputError([&] { BeamElement3d(a, b, Vec3::Zero(), kSteel, owner); }, {owner, "y axis hint is zero"});
  expectInputError([&] { BeamElement3d(a, b, Vec3(-2, 0, 0), kSteel, owner); }, {owner, "parallel"});
  expectInputError([&] { BeamElement3d(a, b, Vec3(1, 1e-8, 0), kSteel, owner); }, {owner, "parallel"});
  expectInputError([&] { BeamElement3d(a, b, Vec3(0, nan, 0), kSteel, owner); }, {owner, "y axis hint"});
  expectInputError([&] { BeamElement3d(Vec3(nan, 0, 0), b, hint, kSteel, owner); }, {owner, "node coordinate"});
  expectInputError([&] { BeamElement3d(a, Vec3(0.5, inf, 0), hint, kSteel, owner); }, {owner, "node coordinate"});
  auto with = [&](auto mutate) {
    BeamSection3d s = kSteel;
    mutate(s);
    return s;
  };
  for (const double bad : {0.0, -1e-4, nan, inf}) {
    expectInputError([&] { BeamElement3d(a, b, hint, with([&](BeamSection3d& s) { s.area = bad; }), owner); },
                     {owner, "area"});
    expectInputError([&] { BeamElement3d(a, b, hint, with([&](BeamSection3d& s) { s.inertiaY = bad; }), owner); },
                     {owner, "inertia_y"});
    expectInputError([&] { BeamElement3d(a, b, hint, with([&](BeamSection3d& s) { s.inertiaZ = bad; }), owner); },
                     {owner, "inertia_z"});
    expectInputError(
        [&] { BeamElement3d(a, b, hint, with([&](BeamSection3d& s) { s.torsionConstant = bad; }), owner); },
        {owner, "torsion_constant"});
    expectInputError([&] { BeamElement3d(a, b, hint, with([&](BeamSection3d& s) { s.youngsModulus = bad; }), owner); },
                     {owner, "youngs_modulus"});
    expectInputError([&] { BeamElement3d(a, b, hint, with([&](BeamSection3d& s) { s.shearModulus = bad; }), owner); },
                     {owner, "shear_modulus"});
    expectInputError([&] { BeamElement3d(a, b, hint, with([&](BeamSection3d& s) { s.density = bad; }), owner); },
                     {owner, "density"});
  }
  expectInputError([&] { BeamElement3d(a, b, hint, with([](BeamSection3d& s) { s.damping = -1e-3; }), owner); },
                   {owner, "damping"});
  expectInputError([&] { BeamElement3d(a, b, hint, with([&](BeamSection3d& s) { s.damping = nan; }), owner); },
                   {owner, "damping"});
  // valid: zero damping, a hint at 1e-4 rad from the axis, any hint length
  EXPECT_NO_THROW(BeamElement3d(a, b, hint, with([](BeamSection3d& s) { s.damping = 0.0; }), owner));
  EXPECT_NO_THROW(BeamElement3d(a, b, Vec3(1, 1e-4, 0), kSteel, owner));
  EXPECT_NO_THROW(BeamElement3d(a, b, Vec3(0, 1e-9, 1e-9), kSteel, owner));
  // the element frame: y is the hint made orthogonal, z = x cross y, C orthonormal
  const BeamElement3d el(a, b, Vec3(0.7, 2.0, 0.0), kSteel, owner);
  expectMatrixNear(el.rotation(), Mat3::Identity(), kExactTol, "C for an axis along x with a hint in x-y");
  const BeamElement3d g = makeElement();
  expectMatrixNear(g.rotation().transpose() * g.rotation(), Mat3::Identity(), kExactTol, "C^T C");
  EXPECT_NEAR(g.rotation().determinant(), 1.0, kExactTol);
  EXPECT_GT(g.rotation().col(1).dot(kHint), 0.0);
  EXPECT_THROW(g.sKL(3, 0), std::out_of_range);
  EXPECT_THROW(g.positionShapeIntegral(-1), std::out_of_range);
}

}  // namespace
}  // namespace flexmbd
