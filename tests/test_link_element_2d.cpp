// Unit tests of the link element (eqs. 5-15 of source document 000), of the assembled
// linkage's derivatives, and of the closed-form four-bar reference used by the
// validation tests (tests/four_bar_reference.hpp).
#include <gtest/gtest.h>

#include <cmath>

#include "core/errors.hpp"
#include "linkage/link_element_2d.hpp"
#include "linkage/linkage_2d.hpp"
#include "tests/four_bar_reference.hpp"

using namespace flexmbd;
using Vec6 = LinkElement2d::Vec6;
using Vec3 = LinkElement2d::Vec3;

namespace {

// Central differences with step h have truncation error ~h^2 f'''/6 and round-off
// ~1e-16/h; h = 1e-6 on O(1) data gives ~1e-10, so 1e-8 is a safe bound.
constexpr double kFdStep = 1e-6;
constexpr double kFdTolerance = 1e-8;
// Quantities computed in two algebraically equal ways: a few ulps of O(1..100) data.
constexpr double kRoundOff = 1e-12;

Vec6 sampleCoordinates() {
  Vec6 x;
  x << 0.3, -0.2, 0.9, 1.1, 0.7, 0.6;  // a deformed state: l != l0, end angles != chord
  return x;
}

}  // namespace

TEST(LinkElement2d, DeformationsOfARigidPositionVanish) {
  const double l0 = 2.5, beta = 2.0;
  const LinkElement2d e(l0, "rod");
  Vec6 x;
  x << 1.0, -1.0, beta + 2 * M_PI, 1.0 + l0 * std::cos(beta), -1.0 + l0 * std::sin(beta), beta - 2 * M_PI;
  // End angles differing from the chord by whole turns are the same orientation.
  EXPECT_LT(e.deformations(x).cwiseAbs().maxCoeff(), kRoundOff);
}

TEST(LinkElement2d, DeformationsMatchEq5To7) {
  const LinkElement2d e(1.2, "link");
  const Vec6 x = sampleCoordinates();
  const double l = std::hypot(0.8, 0.9), beta = std::atan2(0.9, 0.8);
  const Vec3 eps = e.deformations(x);
  EXPECT_NEAR(eps[0], l - 1.2, kRoundOff);
  EXPECT_NEAR(eps[1], (0.9 - beta) * 1.2, kRoundOff);
  EXPECT_NEAR(eps[2], (beta - 0.6) * 1.2, kRoundOff);
}

TEST(LinkElement2d, JacobianMatchesFiniteDifferences) {
  const LinkElement2d e(1.2, "link");
  const Vec6 x = sampleCoordinates();
  const LinkElement2d::Mat36 D = e.jacobian(x);
  for (int j = 0; j < 6; ++j) {
    Vec6 xp = x, xm = x;
    xp[j] += kFdStep;
    xm[j] -= kFdStep;
    const Vec3 fd = (e.deformations(xp) - e.deformations(xm)) / (2 * kFdStep);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(D(i, j), fd[i], kFdTolerance) << "row " << i << " col " << j;
  }
}

TEST(LinkElement2d, JacobianAtARigidPositionIsEq15) {
  const double l0 = 3.0, beta0 = -0.7;
  const LinkElement2d e(l0, "link");
  Vec6 x;
  x << 0.5, 0.25, beta0, 0.5 + l0 * std::cos(beta0), 0.25 + l0 * std::sin(beta0), beta0;
  EXPECT_LT((e.jacobian(x) - LinkElement2d::linearisedMatrix(beta0, l0)).cwiseAbs().maxCoeff(), kRoundOff);
}

TEST(LinkElement2d, SecondDerivativeMatchesFiniteDifferencesOfTheJacobian) {
  const LinkElement2d e(1.2, "link");
  const Vec6 x = sampleCoordinates();
  Vec6 dx;
  dx << 0.4, -1.0, 0.3, -0.2, 0.5, 0.8;
  // d/ds [D(x + s dx) dx] at s = 0 = dx^T H dx.
  const Vec3 fd = (e.jacobian(x + kFdStep * dx) * dx - e.jacobian(x - kFdStep * dx) * dx) / (2 * kFdStep);
  const Vec3 an = e.secondDerivative(x, dx);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(an[i], fd[i], kFdTolerance) << "component " << i;
}

TEST(LinkElement2d, RejectsZeroAndNonFiniteLengths) {
  EXPECT_THROW(LinkElement2d(0.0, "rod"), InputError);
  EXPECT_THROW(LinkElement2d(-1.0, "rod"), InputError);
  EXPECT_THROW(LinkElement2d(std::nan(""), "rod"), InputError);
  try {
    LinkElement2d(0.0, "rod");
  } catch (const InputError& err) {
    EXPECT_NE(std::string(err.what()).find("link 'rod'"), std::string::npos) << err.what();
  }
}

/// A linkage with every kind of node (a slider on an inclined line, a free and a fixed
/// node) at a deformed state: its assembled D and (dD/dalpha) X' against differences.
TEST(Linkage2d, AssembledDerivativesMatchFiniteDifferences) {
  Linkage2d l;
  l.addFixedNode("A", {0, 0});
  l.addFreeNode("B", {1, 0.2});
  l.addSliderNode("C", {2.5, 0.4}, {2, 1});
  l.addLink("crank", "A", "B");
  l.addLink("rod", "B", "C", 1.7);
  l.addLinkAngleInput("alpha", "crank");
  l.finalize();
  ASSERT_EQ(l.numCoordinates(), 7);  // B: 2, C: 1, two links x 2 end angles
  ASSERT_EQ(l.mobility(), 1);
  VecX X = l.initialCoordinates();
  X += VecX::LinSpaced(X.size(), 0.05, -0.1);  // away from the rigid position
  const MatX D = l.jacobian(X);
  for (int j = 0; j < X.size(); ++j) {
    VecX xp = X, xm = X;
    xp[j] += kFdStep;
    xm[j] -= kFdStep;
    const VecX fd = (l.deformations(xp) - l.deformations(xm)) / (2 * kFdStep);
    EXPECT_LT((D.col(j) - fd).cwiseAbs().maxCoeff(), kFdTolerance) << "column " << j;
  }
  const VecX dX = VecX::LinSpaced(X.size(), 1.0, -0.5);
  const VecX fd = (l.jacobian(X + kFdStep * dX) * dX - l.jacobian(X - kFdStep * dX) * dX) / (2 * kFdStep);
  EXPECT_LT((l.secondDerivative(X, dX) - fd).cwiseAbs().maxCoeff(), kFdTolerance);
}

// ----- the closed-form four-bar reference ------------------------------------------

namespace {
constexpr double kA = 30, kB = 60, kC = 80, kD = 100;  // source document 000, example 2
}

TEST(FourBarReference, PositionClosesTheLoop) {
  for (double th = 0.0; th < 2 * M_PI; th += 0.1) {
    const auto s = reference::fourBar(kA, kB, kC, kD, th);
    EXPECT_NEAR(std::hypot(s.x - kA * std::cos(th), s.y - kA * std::sin(th)), kB, kRoundOff * 100);
    EXPECT_NEAR(std::hypot(s.x - kD, s.y), kC, kRoundOff * 100);
  }
  EXPECT_NEAR(reference::fourBar(kA, kB, kC, kD, 0.0).x, 45.0, kRoundOff * 100);  // by hand
  EXPECT_GT(reference::fourBar(kA, kB, kC, kD, 0.0).y, 0.0);                      // upper branch
}

/// Velocity and acceleration against differences of the closed-form position, with a
/// crank speed and acceleration (the wd terms).
TEST(FourBarReference, VelocityAndAccelerationMatchDifferencesOfPosition) {
  // theta(t) = th0 + w t + wd t^2 / 2; differences in t with h = 1e-4: truncation
  // h^2 |x'''| / 6 ~ 1e-7 on cm-sized data, round-off 1e-14 / h^2 = 1e-6 for the second
  // difference: bounds 1e-6 (velocity) and 1e-4 (acceleration), relative to ~100.
  const double w = 1.3, wd = -0.4, h = 1e-4;
  for (double th0 = 0.05; th0 < 2 * M_PI; th0 += 0.3) {
    auto at = [&](double t) { return reference::fourBar(kA, kB, kC, kD, th0 + w * t + 0.5 * wd * t * t); };
    const auto s = reference::fourBar(kA, kB, kC, kD, th0, w, wd);
    const auto p = at(h), m = at(-h), z = at(0);
    EXPECT_NEAR(s.vx, (p.x - m.x) / (2 * h), 1e-6);
    EXPECT_NEAR(s.vy, (p.y - m.y) / (2 * h), 1e-6);
    EXPECT_NEAR(s.ax, (p.x - 2 * z.x + m.x) / (h * h), 1e-4);
    EXPECT_NEAR(s.ay, (p.y - 2 * z.y + m.y) / (h * h), 1e-4);
  }
}
