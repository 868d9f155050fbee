// Unit tests of the components against closed forms and invariants: the rigid-body
// mass matrix and kinetic energy, input checks, constraint values at hand-built
// configurations, the rank check and the consistent initial state of a slider-crank,
// and the build-phase rules of System.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "bodies/rigid_body_2d.hpp"
#include "builders/planar_builders.hpp"
#include "core/dae_system.hpp"
#include "core/errors.hpp"
#include "core/system.hpp"
#include "core/system_evaluation.hpp"
#include "core/time_law.hpp"
#include "integrators/initial_conditions.hpp"
#include "joints/drivers.hpp"
#include "joints/prismatic_joint.hpp"
#include "tests/test_support.hpp"

namespace flexmbd {
namespace {

using namespace testsupport;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// Fixed seed: the random configurations are the same on every run (reproducible).
constexpr unsigned kSeed = 4242u;
// Random configurations per case: enough to visit every quadrant of the angles.
constexpr int kSamples = 8;
// Closed-form identities evaluated with a few dozen floating-point operations on
// numbers of order 1..10: rounding errors ~1e-15..1e-14 relative. 1e-12 bounds them
// while any formula error is O(1).
constexpr double kRoundoffTol = 1e-12;
// Required accuracy of the projected positions (the brief of computeConsistentState:
// Newton stops at 1e-13 (1 + |q|_inf) ~ 4e-13 here).
constexpr double kPositionTol = 1e-12;
// Velocity and acceleration levels come from dense LU solves of a well-conditioned
// 9+9 augmented system (condition ~1e2..1e3): residuals ~ cond * eps * scale ~ 1e-13
// relative. 1e-10 relative bounds that with margin; wrong equations are O(1).
constexpr double kSolveTol = 1e-10;
// Positions/velocities/accelerations of the projected slider-crank against the closed
// form: the state satisfies the constraints to kPositionTol, amplified by the
// kinematic sensitivity of the slider (<= ~10 for l2 / l1 = 2 away from dead
// centres) and by the velocity / acceleration solves: 1e-9 is safe.
constexpr double kClosedFormTol = 1e-9;

RigidBodyProperties randomProperties(Random& rnd) {
  RigidBodyProperties p;
  p.mass = rnd.uniform(0.5, 5.0);
  p.inertia = rnd.uniform(0.1, 2.0);
  p.com = Vec2(rnd.uniform(0.3, 1.2), rnd.uniform(-0.8, -0.2));  // off the frame origin
  return p;
}

/// Rotation by theta, written out (independent of core/types.hpp).
Vec2 rotate(double theta, const Vec2& u) {
  return Vec2(std::cos(theta) * u.x() - std::sin(theta) * u.y(),
              std::sin(theta) * u.x() + std::cos(theta) * u.y());
}

/// Expects `f` to throw exactly an error of type E whose message contains every needle.
template <class E>
void expectThrowsMentioning(const std::function<void()>& f, const std::vector<std::string>& needles,
                            const std::string& what) {
  try {
    f();
    ADD_FAILURE() << what << ": nothing thrown";
  } catch (const E& e) {
    const std::string msg = e.what();
    for (const auto& n : needles) {
      EXPECT_NE(msg.find(n), std::string::npos) << what << ": message '" << msg << "' lacks '" << n << "'";
    }
  } catch (const std::exception& e) {
    ADD_FAILURE() << what << ": wrong exception type: " << e.what();
  }
}

// =====================================================================================
// RigidBody2d
// =====================================================================================

TEST(RigidBody2d, MassMatrixIsSymmetricPositiveDefiniteWithTranslationalBlockMI) {
  Random rnd(kSeed);
  for (int s = 0; s < kSamples; ++s) {
    const RigidBodyProperties p = randomProperties(rnd);
    const RigidBody2d body("link", p, FrameState2d{});
    const VecX q = rnd.frame();
    const MatX M = body.massMatrix(q);
    ASSERT_EQ(M.rows(), 3);
    ASSERT_EQ(M.cols(), 3);
    EXPECT_TRUE(M == M.transpose()) << "sample " << s << ":\n" << M;
    const Eigen::SelfAdjointEigenSolver<MatX> eig(M);
    EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0) << "sample " << s << ":\n" << M;
    EXPECT_EQ(Eigen::LLT<MatX>(M).info(), Eigen::Success) << "sample " << s;
    // translational block m I, the sum of the point masses
    EXPECT_EQ(M(0, 0), p.mass);
    EXPECT_EQ(M(1, 1), p.mass);
    EXPECT_EQ(M(0, 1), 0.0);
    EXPECT_EQ(M(1, 0), 0.0);
    EXPECT_DOUBLE_EQ(body.mass(), p.mass);
    // rotational entry: parallel-axis theorem J + m |c|^2 about the frame origin
    EXPECT_NEAR(M(2, 2), p.inertia + p.mass * p.com.squaredNorm(), kRoundoffTol * M(2, 2));
    // coupling m S A c = m d(A c)/dtheta
    const Vec2 sac = rotate(q[2] + kPi / 2, p.com);
    EXPECT_NEAR(M(0, 2), p.mass * sac.x(), kRoundoffTol * p.mass * 2.0);
    EXPECT_NEAR(M(1, 2), p.mass * sac.y(), kRoundoffTol * p.mass * 2.0);
  }
}

TEST(RigidBody2d, KineticEnergyEqualsComTranslationPlusRotation) {
  Random rnd(kSeed + 1);
  for (int s = 0; s < kSamples; ++s) {
    const RigidBodyProperties p = randomProperties(rnd);
    const RigidBody2d body("link", p, FrameState2d{});
    const VecX q = rnd.frame();
    const VecX v = rnd.vector(3, -3.0, 3.0);
    const double T = 0.5 * v.dot(body.massMatrix(q) * v);
    // v_com = Rdot + S A c thetadot, with S A c = A(theta + pi/2) c
    const Vec2 vcom = v.head<2>() + rotate(q[2] + kPi / 2, p.com) * v[2];
    const double Tref = 0.5 * p.mass * vcom.squaredNorm() + 0.5 * p.inertia * v[2] * v[2];
    EXPECT_NEAR(T, Tref, kRoundoffTol * std::max(1.0, Tref)) << "sample " << s;
    // centre of mass and point positions
    const Vec2 com = body.planarCentreOfMass(q);
    const Vec2 comRef = q.head<2>() + rotate(q[2], p.com);
    EXPECT_NEAR((com - comRef).norm(), 0.0, kRoundoffTol * 10.0) << "sample " << s;
    const Vec2 u = rnd.vec2(-2.0, 2.0);
    const PointKinematics pk = body.pointKinematics(q, u);
    EXPECT_NEAR((pk.r - (q.head<2>() + rotate(q[2], u))).norm(), 0.0, kRoundoffTol * 10.0);
    EXPECT_EQ(pk.phi, q[2]);
    // gravity potential -m g . r_com
    const Vec2 g(0.3, -9.81);
    EXPECT_NEAR(body.gravityPotential(q, lift(g)), -p.mass * g.dot(comRef), kRoundoffTol * 100.0);
  }
}

TEST(RigidBody2d, BadMassOrInertiaThrowsInputErrorNamingTheBody) {
  for (const double bad : {0.0, -1.0, kNaN, kInf, -kInf}) {
    RigidBodyProperties pm;
    pm.mass = bad;
    expectThrowsMentioning<InputError>(
        [&] { RigidBody2d("flywheel", pm, FrameState2d{}); }, {"'flywheel'", "mass"},
        "mass = " + std::to_string(bad));
    RigidBodyProperties pi;
    pi.inertia = bad;
    expectThrowsMentioning<InputError>(
        [&] { RigidBody2d("flywheel", pi, FrameState2d{}); }, {"'flywheel'", "inertia"},
        "inertia = " + std::to_string(bad));
    // also through the builder
    System sys;
    expectThrowsMentioning<InputError>([&] { addRigidBody(sys, "rotor", pm, FrameState2d{}); },
                                       {"'rotor'", "mass"}, "addRigidBody mass");
    EXPECT_EQ(sys.numBodies(), 1);  // nothing was added
  }
  RigidBodyProperties pc;
  pc.com = Vec2(kNaN, 0.0);
  expectThrowsMentioning<InputError>([&] { RigidBody2d("flywheel", pc, FrameState2d{}); },
                                     {"'flywheel'", "com"}, "com NaN");
}

// =====================================================================================
// Constraint values
// =====================================================================================

TEST(ConstraintValues, RevoluteJointVanishesWhenAssembled) {
  Random rnd(kSeed + 10);
  System sys;
  const BodyIndex a = addRigidBody(sys, "a", randomProperties(rnd), FrameState2d{});
  const BodyIndex b = addRigidBody(sys, "b", randomProperties(rnd), FrameState2d{});
  const Vec2 ua = rnd.vec2(-1.5, 1.5), ub = rnd.vec2(-1.5, 1.5), ug = rnd.vec2(-2.0, 2.0);
  const ConstraintIndex ab = addRevoluteJoint(sys, "hinge", a, ua, b, ub);
  const ConstraintIndex gb = addRevoluteJoint(sys, "pin", kGround, ug, b, ub);
  sys.finalize();
  for (int s = 0; s < kSamples; ++s) {
    VecX q(sys.numCoordinates());
    q.segment(sys.coordinateOffset(a), 3) = rnd.frame();
    const double thB = rnd.angle();
    const Vec2 qa = q.segment(sys.coordinateOffset(a), 2);
    // b placed so that its point ub coincides with a's point ua
    const Vec2 P = qa + rotate(q[sys.coordinateOffset(a) + 2], ua);
    const Vec2 Rb = P - rotate(thB, ub);
    q.segment(sys.coordinateOffset(b), 3) = Eigen::Vector3d(Rb.x(), Rb.y(), thB);
    ConstraintEvaluation ev;
    const Constraint& hinge = sys.constraint(ab);
    hinge.evaluate(sys.constraintStates(ab, q.data()), false, ev);
    EXPECT_LT(ev.h.norm(), kRoundoffTol * 10.0) << "sample " << s << ": h = " << ev.h.transpose();
    // the ground pin is satisfied only if the ground point is where b's point is
    const Constraint& pin = sys.constraint(gb);
    pin.evaluate(sys.constraintStates(gb, q.data()), false, ev);
    EXPECT_NEAR((ev.h - (P - ug)).norm(), 0.0, kRoundoffTol * 10.0) << "sample " << s;
  }
}

TEST(ConstraintValues, PrismaticNormalEquationIsSignedDistanceToAxisLine) {
  Random rnd(kSeed + 11);
  System sys;
  const BodyIndex a = addRigidBody(sys, "a", randomProperties(rnd), FrameState2d{});
  const BodyIndex b = addRigidBody(sys, "b", randomProperties(rnd), FrameState2d{});
  const Vec2 axis(2.0, 1.0);  // not unit, not axis-aligned: the joint normalises it
  const Vec2 aHat = axis.normalized();
  const double reference = 0.4;
  const Vec2 ua = rnd.vec2(-1.0, 1.0), ub = rnd.vec2(-1.0, 1.0);
  const ConstraintIndex ab = sys.addConstraint(
      std::make_unique<PrismaticJoint>("slide", a, ua, b, ub, axis, reference));
  const ConstraintIndex gb = sys.addConstraint(
      std::make_unique<PrismaticJoint>("slide_ground", kGround, ua, b, ub, axis, reference));
  sys.finalize();
  for (int s = 0; s < kSamples; ++s) {
    const VecX qa = rnd.frame();
    const double thB = rnd.angle();
    const double along = rnd.uniform(-2.0, 2.0);
    for (const double offset : {0.0, rnd.uniform(-1.5, 1.5)}) {
      for (const ConstraintIndex ci : {ab, gb}) {
        const bool ground = ci == gb;
        const Vec2 Ri = ground ? Vec2::Zero() : Vec2(qa.head<2>());
        const double thI = ground ? 0.0 : qa[2];
        const Vec2 Pi = Ri + rotate(thI, ua);
        const Vec2 aw = rotate(thI, aHat);
        const Vec2 nw(-aw.y(), aw.x());
        const Vec2 Pj = Pi + along * aw + offset * nw;
        const Vec2 Rb = Pj - rotate(thB, ub);
        VecX q(sys.numCoordinates());
        q.segment(sys.coordinateOffset(a), 3) = qa;
        q.segment(sys.coordinateOffset(b), 3) = Eigen::Vector3d(Rb.x(), Rb.y(), thB);
        ConstraintEvaluation ev;
        const Constraint& con = sys.constraint(ci);
        con.evaluate(sys.constraintStates(ci, q.data()), false, ev);
        // hand-computed signed distance of P_j from the line through P_i along a_w
        const Vec2 d = Pj - Pi;
        const double distance = (aw.x() * d.y() - aw.y() * d.x()) / aw.norm();
        const std::string at = con.name() + ", sample " + std::to_string(s) +
                               ", offset " + std::to_string(offset);
        EXPECT_NEAR(distance, offset, kRoundoffTol * 10.0) << at;
        EXPECT_NEAR(ev.h[0], distance, kRoundoffTol * 10.0) << at;
        if (offset == 0.0) {
          EXPECT_NEAR(ev.h[0], 0.0, kRoundoffTol * 10.0) << at;
        }
        EXPECT_NEAR(ev.h[1], thB - thI - reference, kRoundoffTol * 10.0) << at;
      }
    }
  }
}

TEST(ConstraintValues, JointDisplacementDriverIsProjectionOnRotatingAxis) {
  Random rnd(kSeed + 12);
  System sys;
  const BodyIndex a = addRigidBody(sys, "a", randomProperties(rnd), FrameState2d{});
  const BodyIndex b = addRigidBody(sys, "b", randomProperties(rnd), FrameState2d{});
  const Vec2 axis(-0.6, 1.7);
  const Vec2 ua = rnd.vec2(-1.0, 1.0), ub = rnd.vec2(-1.0, 1.0);
  const auto law = makeHarmonicLaw(0.5, 2.0, 0.3, 0.1);
  const ConstraintIndex ci = sys.addConstraint(
      std::make_unique<JointDisplacementDriver>("stroke", a, ua, b, ub, axis, law));
  sys.finalize();
  for (int s = 0; s < kSamples; ++s) {
    VecX q(sys.numCoordinates());
    q.segment(sys.coordinateOffset(a), 3) = rnd.frame();
    q.segment(sys.coordinateOffset(b), 3) = rnd.frame();
    const VecX qa = q.segment(sys.coordinateOffset(a), 3), qb = q.segment(sys.coordinateOffset(b), 3);
    const Vec2 d = (Vec2(qb.head<2>()) + rotate(qb[2], ub)) - (Vec2(qa.head<2>()) + rotate(qa[2], ua));
    const Vec2 aw = rotate(qa[2], axis) / axis.norm();
    ConstraintEvaluation ev;
    const Constraint& con = sys.constraint(ci);
    con.evaluate(sys.constraintStates(ci, q.data()), false, ev);
    EXPECT_NEAR(ev.h[0], aw.dot(d), kRoundoffTol * 10.0) << "sample " << s;
    // g = h - f(t) through the whole-system evaluation
    const double t = rnd.uniform(0.0, 3.0);
    VecX g;
    evaluateConstraints(sys, q, t, &g, nullptr);
    EXPECT_NEAR(g[sys.constraintOffset(ci)], aw.dot(d) - law->evaluate(t).f, kRoundoffTol * 10.0);
  }
}

// =====================================================================================
// Rank check
// =====================================================================================

TEST(DependentConstraintRows, FindsDuplicatedAndCombinedRowsOnly) {
  Random rnd(kSeed + 20);
  MatX G = MatX::Zero(5, 6);
  for (int i = 0; i < 3; ++i) G.row(i) = rnd.vector(6, -2.0, 2.0).transpose();
  G.row(3) = G.row(1);                          // duplicate
  G.row(4) = 2.0 * G.row(0) - 0.5 * G.row(2);   // linear combination
  EXPECT_EQ(dependentRows(G), (std::vector<int>{3, 4}));

  MatX dup = G.topRows(4);
  EXPECT_EQ(dependentRows(dup), (std::vector<int>{3}));

  MatX zero = G.topRows(3);
  zero.row(1).setZero();
  EXPECT_EQ(dependentRows(zero), (std::vector<int>{1}));

  // full row rank: nothing
  EXPECT_TRUE(dependentRows(G.topRows(3)).empty());
  const MatX I = MatX::Identity(4, 4);
  EXPECT_TRUE(dependentRows(I).empty());
  // nearly parallel but independent beyond the tolerance
  MatX near = G.topRows(2);
  near.row(1) = near.row(0) + 1e-6 * rnd.vector(6, -1.0, 1.0).transpose();
  EXPECT_TRUE(dependentRows(near).empty());
  // the tolerance is relative: the answer does not depend on the units of G
  for (const double scale : {1e-12, 1e12}) {
    EXPECT_EQ(dependentRows(scale * G), (std::vector<int>{3, 4})) << "scale " << scale;
    EXPECT_TRUE(dependentRows(scale * G.topRows(3)).empty()) << "scale " << scale;
  }
}

// =====================================================================================
// Consistent initial state of a slider-crank
// =====================================================================================

constexpr double kL1 = 1.0, kL2 = 2.0, kCrank0 = 0.3, kOmega = 2.0;

struct SliderCrank {
  System sys;
  BodyIndex crank, rod, slider;
  ConstraintIndex pivot;
};

/// Centred slider-crank: crank (frame at the ground pivot) of length l1, rod of length
/// l2 from the crank pin to the slider, slider on the world x axis; centres of mass
/// off the frame origins; gravity. With drivers >= 1 the crank angle is driven,
/// theta = kCrank0 + kOmega t ("motor", body_theta); drivers = 2 adds a second driver
/// "motor2" on the same angle (through the pivot's joint angle). Bodies start at the
/// exactly assembled position when l2 reaches the axis, otherwise with the rod
/// leaning down towards it.
std::unique_ptr<SliderCrank> makeSliderCrank(double l2, int drivers) {
  auto sc = std::make_unique<SliderCrank>();
  System& sys = sc->sys;
  sys.setGravity(Vec2(0.0, -9.81));
  const Vec2 pin(kL1 * std::cos(kCrank0), kL1 * std::sin(kCrank0));
  const double reach2 = l2 * l2 - pin.y() * pin.y();
  // (not reaching: the rod leans 1 rad below the horizontal, a regular configuration)
  const double xs = pin.x() + (reach2 > 0 ? std::sqrt(reach2) : l2 * std::cos(1.0));
  const double rodAngle = reach2 > 0 ? std::atan2(-pin.y(), xs - pin.x()) : -1.0;
  sc->crank = addRigidBody(sys, "crank", {1.0, 0.1, Vec2(0.5, 0.05)}, {Vec2::Zero(), kCrank0, Vec2::Zero(), 0.0});
  sc->rod = addRigidBody(sys, "rod", {2.0, 0.7, Vec2(1.0, -0.1)}, {pin, rodAngle, Vec2::Zero(), 0.0});
  sc->slider = addRigidBody(sys, "slider", {0.5, 0.01, Vec2(0.02, 0.01)},
                            {Vec2(xs, 0.0), 0.0, Vec2::Zero(), 0.0});
  sc->pivot = addRevoluteJoint(sys, "pivot", kGround, Vec2::Zero(), sc->crank, Vec2::Zero());
  addRevoluteJoint(sys, "crank_pin", sc->crank, Vec2(kL1, 0.0), sc->rod, Vec2::Zero());
  addRevoluteJoint(sys, "wrist", sc->rod, Vec2(l2, 0.0), sc->slider, Vec2::Zero());
  addPrismaticJoint(sys, "slide", kGround, Vec2::Zero(), sc->slider, Vec2::Zero(), Vec2(1.0, 0.0));
  if (drivers >= 1) {
    addBodyCoordinateDriver(sys, "motor", sc->crank, "theta", makeConstantSpeedLaw(kOmega, kCrank0));
  }
  if (drivers >= 2) addJointDriver(sys, "motor2", sc->pivot, makeConstantSpeedLaw(kOmega, kCrank0));
  sys.finalize();
  return sc;
}

/// Slider position x(a) and its derivatives in the crank angle a for the centred
/// slider-crank (Yamada & Tatsumi 1981, eqs. 30-32).
struct SliderKinematics {
  double x, dxda, d2xda2;
};
SliderKinematics sliderKinematics(double a) {
  const double s = std::sin(a), c = std::cos(a);
  const double r = std::sqrt(kL2 * kL2 - kL1 * kL1 * s * s);
  return {kL1 * c + r, -kL1 * s - kL1 * kL1 * s * c / r,
          -kL1 * c - kL1 * kL1 * (kL1 * kL1 * std::pow(s, 4) + kL2 * kL2 * std::cos(2 * a)) / (r * r * r)};
}

class ConsistentSliderCrank : public ::testing::TestWithParam<int> {};

TEST_P(ConsistentSliderCrank, ProjectionSatisfiesEveryLevel) {
  const int drivers = GetParam();
  const auto sc = makeSliderCrank(kL2, drivers);
  const System& sys = sc->sys;
  const int nq = sys.numCoordinates(), m = sys.numConstraintEquations();
  ASSERT_EQ(nq, 9);
  ASSERT_EQ(m, 8 + drivers);  // one degree of freedom, removed by the driver
  Random rnd(kSeed + 30 + static_cast<unsigned>(drivers));
  const int c = sys.coordinateOffset(sc->crank), sl = sys.coordinateOffset(sc->slider);
  for (int s = 0; s < 4; ++s) {
    const double t0 = s == 0 ? 0.0 : rnd.uniform(0.0, 0.2);  // crank at 0.3 rad, then later
    const std::string at = std::to_string(drivers) + " driver(s), sample " + std::to_string(s);
    const VecX q0 = sys.initialCoordinates() + rnd.vector(nq, -0.05, 0.05);
    const VecX v0 = rnd.vector(nq, -1.0, 1.0);
    ConsistentState cs;
    ASSERT_NO_THROW(cs = computeConsistentState(sys, t0, q0, v0)) << at;

    // positions: every constraint satisfied, close to the perturbed guess
    VecX g;
    MatX G;
    evaluateConstraints(sys, cs.q, t0, &g, &G);
    EXPECT_LE(g.lpNorm<Eigen::Infinity>(), kPositionTol) << at << ": g = " << g.transpose();
    EXPECT_LE(cs.positionResidual, kPositionTol) << at;
    // the other assembly branch (slider at l1 cos a - r) is > 3 away
    EXPECT_LT((cs.q - q0).lpNorm<Eigen::Infinity>(), 1.0) << at << ": jumped to another assembly";
    // ... and the closed form in the (projected) crank angle
    const double a = cs.q[c + 2];
    if (drivers == 1) {
      EXPECT_NEAR(a, kCrank0 + kOmega * t0, kClosedFormTol) << at;
    }
    const SliderKinematics k = sliderKinematics(a);
    EXPECT_NEAR(cs.q[sl], k.x, kClosedFormTol) << at;
    EXPECT_NEAR(cs.q[sl + 1], 0.0, kClosedFormTol) << at;

    // velocities: G v = f'(t0)
    const double vScale = 1.0 + cs.v.lpNorm<Eigen::Infinity>();
    EXPECT_LE(velocityConstraintResidual(sys, cs.q, cs.v, t0).lpNorm<Eigen::Infinity>(),
              kSolveTol * vScale) << at;
    if (drivers == 1) {
      EXPECT_NEAR(cs.v[c + 2], kOmega, kClosedFormTol) << at;
    }
    EXPECT_NEAR(cs.v[sl], k.dxda * cs.v[c + 2], kClosedFormTol * vScale) << at;
    // ... the closest to v0 in the mass metric: M (v - v0) is in range(G^T), i.e.
    // orthogonal to the null space of G (KKT condition of min (v-v0)^T M (v-v0) s.t.
    // G v = f'). Driven, G is square and regular and v is unique; undriven, the null
    // space is the one motion of the mechanism and the condition is not trivial.
    const MatX M = massMatrix(sys, cs.q);
    const Eigen::JacobiSVD<MatX> svd(G, Eigen::ComputeFullV);
    const int rank = static_cast<int>(svd.rank());
    EXPECT_EQ(rank, std::min(m, nq)) << at;
    const MatX N = svd.matrixV().rightCols(nq - rank);
    EXPECT_EQ(N.cols(), drivers == 0 ? 1 : 0) << at;
    const VecX kkt = N.transpose() * M * (cs.v - v0);
    EXPECT_LE(kkt.norm(), kSolveTol * (1.0 + (M * (cs.v - v0)).norm()))
        << at << ": N^T M (v - v0) = " << kkt.transpose();
    if (drivers == 0) {
      // and it is a minimum: moving along the null space increases the distance
      auto dist = [&](const VecX& w) { return (w - v0).dot(M * (w - v0)); };
      EXPECT_LT(dist(cs.v), dist(cs.v + 1e-3 * N.col(0))) << at;
      EXPECT_LT(dist(cs.v), dist(cs.v - 1e-3 * N.col(0))) << at;
    }

    // accelerations and multipliers: M a + G^T lambda = Q, G a = f'' - v^T H v
    const VecX Q = generalizedForces(sys, t0, cs.q, cs.v);
    const VecX eom = M * cs.a + G.transpose() * cs.lambda - Q;
    EXPECT_LE(eom.lpNorm<Eigen::Infinity>(),
              kSolveTol * (1.0 + Q.lpNorm<Eigen::Infinity>() +
                           (G.transpose() * cs.lambda).lpNorm<Eigen::Infinity>())) << at;
    const VecX acc = G * cs.a - accelerationConstraintRhs(sys, cs.q, cs.v, t0);
    EXPECT_LE(acc.lpNorm<Eigen::Infinity>(), kSolveTol * (1.0 + cs.a.lpNorm<Eigen::Infinity>())) << at;
    if (drivers == 1) {
      EXPECT_NEAR(cs.a[c + 2], 0.0, kClosedFormTol) << at;
    }
    const double aScale = 1.0 + cs.a.lpNorm<Eigen::Infinity>();
    EXPECT_NEAR(cs.a[sl], k.dxda * cs.a[c + 2] + k.d2xda2 * cs.v[c + 2] * cs.v[c + 2],
                kClosedFormTol * aScale) << at;
  }
}

INSTANTIATE_TEST_SUITE_P(DrivenAndFree, ConsistentSliderCrank, ::testing::Values(1, 0),
                         [](const ::testing::TestParamInfo<int>& info) {
                           return info.param ? std::string("driven") : std::string("undriven");
                         });

TEST(ConsistentState, TwoDriversOnTheCrankAngleNameTheSecond) {
  const auto sc = makeSliderCrank(kL2, /*drivers=*/2);
  const System& sys = sc->sys;
  expectThrowsMentioning<ModelError>(
      [&] { computeConsistentState(sys, 0.0, sys.initialCoordinates(), sys.initialVelocities()); },
      {"'motor2'", "redundant"}, "two drivers on one angle");
  // The first driver is not blamed.
  try {
    computeConsistentState(sys, 0.0, sys.initialCoordinates(), sys.initialVelocities());
  } catch (const ModelError& e) {
    EXPECT_EQ(std::string(e.what()).find("'motor'"), std::string::npos) << e.what();
  }
}

TEST(ConsistentState, RodTooShortToReachTheSlideLineCannotBeAssembled) {
  // The crank pin is at height l1 sin(0.3) = 0.2955 above the slide line: a rod of
  // length 0.2 cannot reach it.
  const double shortRod = 0.2;
  ASSERT_LT(shortRod, kL1 * std::sin(kCrank0));
  const auto sc = makeSliderCrank(shortRod, /*drivers=*/1);
  const System& sys = sc->sys;
  expectThrowsMentioning<ModelError>(
      [&] { computeConsistentState(sys, 0.0, sys.initialCoordinates(), sys.initialVelocities()); },
      {"cannot be assembled", "joint '"}, "rod too short");
  try {
    computeConsistentState(sys, 0.0, sys.initialCoordinates(), sys.initialVelocities());
  } catch (const ModelError& e) {
    const std::string msg = e.what();
    const bool namesLoopJoint = msg.find("'crank_pin'") != std::string::npos ||
                                msg.find("'wrist'") != std::string::npos ||
                                msg.find("'slide'") != std::string::npos;
    EXPECT_TRUE(namesLoopJoint) << msg;
  }
}

// =====================================================================================
// System build rules
// =====================================================================================

TEST(System, AddingAfterFinalizeThrowsInputError) {
  System sys;
  const BodyIndex a = addRigidBody(sys, "a", {}, {});
  const ConstraintIndex j = addRevoluteJoint(sys, "pin", kGround, Vec2::Zero(), a, Vec2::Zero());
  sys.finalize();
  EXPECT_TRUE(sys.isFinalized());
  const std::vector<std::pair<std::string, std::function<void()>>> late = {
      {"body", [&] { addRigidBody(sys, "b", {}, {}); }},
      {"joint", [&] { addRevoluteJoint(sys, "pin2", kGround, Vec2(1.0, 0.0), a, Vec2(1.0, 0.0)); }},
      {"driver", [&] { addJointDriver(sys, "motor", j, makeConstantLaw(0.0)); }},
      {"force", [&] { addSpringDamper(sys, "spring", kGround, Vec2(1.0, 0.0), a, Vec2::Zero(), 1.0, 0.0, 0.0); }},
      {"gravity", [&] { sys.setGravity(Vec2(0.0, -9.81)); }},
      {"finalize", [&] { sys.finalize(); }},
  };
  for (const auto& [what, f] : late) {
    expectThrowsMentioning<InputError>(f, {"finalize"}, "after finalize: " + what);
  }
  EXPECT_EQ(sys.numBodies(), 2);
  EXPECT_EQ(sys.numConstraints(), 1);
  EXPECT_EQ(sys.numForces(), 0);
}

TEST(System, DuplicateNamesThrowInputError) {
  System sys;
  const BodyIndex a = addRigidBody(sys, "arm", {}, {});
  const BodyIndex b = addRigidBody(sys, "link", {}, {});
  const ConstraintIndex j = addRevoluteJoint(sys, "hinge", a, Vec2(1.0, 0.0), b, Vec2::Zero());
  addSpringDamper(sys, "spring", kGround, Vec2(0.0, 1.0), a, Vec2::Zero(), 10.0, 0.0, 1.0);
  expectThrowsMentioning<InputError>([&] { addRigidBody(sys, "arm", {}, {}); }, {"'arm'", "duplicate"},
                                     "body twice");
  expectThrowsMentioning<InputError>([&] { addRigidBody(sys, "ground", {}, {}); },
                                     {"'ground'", "duplicate"}, "body named ground");
  expectThrowsMentioning<InputError>(
      [&] { addRevoluteJoint(sys, "link", a, Vec2::Zero(), b, Vec2(1.0, 0.0)); }, {"'link'", "duplicate"},
      "joint named like a body");
  expectThrowsMentioning<InputError>([&] { addJointDriver(sys, "hinge", j, makeConstantLaw(0.0)); },
                                     {"'hinge'", "duplicate"}, "driver named like a joint");
  expectThrowsMentioning<InputError>(
      [&] { addRotationalSpringDamper(sys, "spring", j, 1.0, 0.0, 0.0); }, {"'spring'", "duplicate"},
      "force twice");
  expectThrowsMentioning<InputError>([&] { addRigidBody(sys, "spring", {}, {}); },
                                     {"'spring'", "duplicate"}, "body named like a force");
  EXPECT_EQ(sys.numBodies(), 3);
  EXPECT_EQ(sys.numConstraints(), 1);
  EXPECT_EQ(sys.numForces(), 1);
  // a DaeSystem needs a finalized system
  expectThrowsMentioning<InputError>([&] { DaeSystem dae(sys, Formulation::Ggl); }, {"finalized"},
                                     "DaeSystem before finalize");
}

}  // namespace
}  // namespace flexmbd
