// Spatial rigid bodies and joints: every analytic derivative against central finite
// differences (the kinematic map T, its inverse and derivative, the frame Jacobians and
// curvature terms, the gyroscopic Jacobian, each joint type's G and H, and the DAE
// iteration matrix of a spatial model in all three formulations).
#include <gtest/gtest.h>

#include <limits>

#include "bodies/rigid_body_3d.hpp"
#include "core/dae_system.hpp"
#include "core/rotation_3d.hpp"
#include "core/system.hpp"
#include "forces/spatial_forces.hpp"
#include "joints/point_in_plane_joint.hpp"
#include "joints/point_on_line_joint.hpp"
#include "joints/spatial_drivers.hpp"
#include "joints/spatial_joint.hpp"
#include "test_support.hpp"

using namespace flexmbd;
using namespace flexmbd::testsupport;

namespace {

constexpr unsigned kSeed = 4711;
constexpr int kSamples = 6;
// Central differences with h = 1e-6 (1 + |x|) on functions with O(1..10) second
// derivatives: truncation O(h^2) ~ 1e-11, round-off ~ eps |f| / h ~ 1e-10 relative to
// the O(1..100) entries; 1e-6 leaves a wide margin while a wrong sign or a missing term
// gives errors of order 1 (checked by dropping terms while writing the code).
constexpr double kFdRelStep = 1e-6;
constexpr double kFdTol = 1e-6;
// Identities evaluated with a few dozen operations on O(1) numbers.
constexpr double kRoundoffTol = 1e-12;

Mat3 randomRotation(Random& rnd) {
  Vec4 p = rnd.vector(4, -1.0, 1.0);
  return quaternionRotation(p);
}

std::unique_ptr<RigidBody3d> randomBody(Random& rnd, const std::string& name) {
  RigidBody3dProperties props;
  props.mass = rnd.uniform(0.5, 3.0);
  const Vec3 I(rnd.uniform(1.0, 2.0), rnd.uniform(1.0, 2.0), rnd.uniform(1.0, 2.0));
  const Mat3 R = randomRotation(rnd);
  props.inertia = R * I.asDiagonal() * R.transpose();
  props.inertia = 0.5 * (props.inertia + props.inertia.transpose()).eval();
  FrameState3d init;
  init.position = rnd.vector(3, -1.0, 1.0);
  init.orientation = randomRotation(rnd);
  init.velocity = rnd.vector(3, -1.0, 1.0);
  init.angularVelocity = rnd.vector(3, -2.0, 2.0);
  return std::make_unique<RigidBody3d>(name, props, init);
}

/// A random state with a quaternion of length != 1 (its length is a gauge and must not matter).
VecX randomCoordinates(Random& rnd) {
  VecX q(7);
  q.head<3>() = rnd.vector(3, -1.0, 1.0);
  q.segment<4>(3) = rnd.vector(4, -1.0, 1.0).normalized() * rnd.uniform(0.8, 1.2);
  return q;
}

/// d f(q (+) eps e_k) / d eps at 0 for each velocity direction k (central).
MatX fdAlongVelocities(const Body& body, const VecX& q, const std::function<VecX(const VecX&)>& f) {
  const int nv = body.numVelocities();
  const VecX f0 = f(q);
  MatX J(f0.size(), nv);
  for (int k = 0; k < nv; ++k) {
    VecX dv = VecX::Zero(nv);
    dv[k] = kFdRelStep;
    VecX qp(q.size()), qm(q.size());
    body.applyIncrement(q, dv, qp);
    body.applyIncrement(q, -dv, qm);
    J.col(k) = (f(qp) - f(qm)) / (2.0 * kFdRelStep);
  }
  return J;
}

MatX fdJacobian(const std::function<VecX(const VecX&)>& f, const VecX& x) {
  return testsupport::fdJacobian(f, x, relativeSteps(x, kFdRelStep));
}

VecX flatten(const Mat3& A) { return Eigen::Map<const VecX>(A.data(), 9); }

}  // namespace

TEST(RigidBody3d, KinematicMapItsInverseAndDerivativeMatchFiniteDifferences) {
  Random rnd(kSeed);
  for (int s = 0; s < kSamples; ++s) {
    const auto bodyPtr = randomBody(rnd, "b");
    const RigidBody3d& body = *bodyPtr;
    const VecX q = randomCoordinates(rnd), w = rnd.vector(6, -2.0, 2.0);
    const std::string at = "sample " + std::to_string(s);
    MatX T, Ti;
    body.coordinateRateMatrix(q, T);
    body.coordinateRateInverse(q, Ti);
    expectMatrixNear(Ti * T, MatX::Identity(6, 6), kRoundoffTol, "T+ T = I, " + at, 1.0);
    VecX Tw = VecX::Zero(7);
    body.addCoordinateRate(q, w, Tw);
    expectMatrixNear(Tw, T * w, kRoundoffTol, "addCoordinateRate = T w, " + at, 1.0);
    // T is the derivative of q along the increment q (+) eps e_k (which renormalises p:
    // checked on a unit quaternion)
    VecX qu = q;
    qu.segment<4>(3).normalize();
    MatX Tu;
    body.coordinateRateMatrix(qu, Tu);
    expectMatrixNear(fdAlongVelocities(body, qu, [](const VecX& z) { return z; }), Tu, kFdTol,
                     "d(q (+) eps e_k)/d eps = T (unit quaternion), " + at, 1.0);
    MatX K = MatX::Zero(7, 7);
    body.addCoordinateRateJacobian(q, w, K);
    expectMatrixNear(K, fdJacobian([&](const VecX& z) { VecX o = VecX::Zero(7); body.addCoordinateRate(z, w, o); return o; }, q),
                     kFdTol, "d(T w)/dq, " + at, 1.0);
  }
}

TEST(RigidBody3d, FrameJacobiansCurvatureAndGyroscopicTermsMatchFiniteDifferences) {
  Random rnd(kSeed + 1);
  for (int s = 0; s < kSamples; ++s) {
    const auto bodyPtr = randomBody(rnd, "b");
    const RigidBody3d& body = *bodyPtr;
    const VecX q = randomCoordinates(rnd), v = rnd.vector(6, -2.0, 2.0);
    const Vec3 u = rnd.vector(3, -1.0, 1.0), wr = rnd.vector(3, -2.0, 2.0), ww = rnd.vector(3, -2.0, 2.0);
    const std::string at = "sample " + std::to_string(s);
    FrameKinematics f;
    body.frameKinematics(q, u, Body::kAnyPoint, nullptr, nullptr, f);
    EXPECT_NEAR((f.A - quaternionRotation(q.segment<4>(3))).norm(), 0.0, kRoundoffTol);
    // Jr: the point's velocity along each velocity direction
    expectMatrixNear(f.Jr, fdAlongVelocities(body, q, [&](const VecX& z) {
                       FrameKinematics g;
                       body.frameKinematics(z, u, Body::kAnyPoint, nullptr, nullptr, g);
                       return VecX(g.r);
                     }), kFdTol, "Jr, " + at, 1.0);
    // Jw: dA/d eps A^T = (Jw e_k)~
    const MatX dA = fdAlongVelocities(body, q, [&](const VecX& z) { return flatten(RigidBody3d::rotationOf(z)); });
    for (int k = 0; k < 6; ++k) {
      const Mat3 W = Eigen::Map<const Mat3>(dA.col(k).data()) * f.A.transpose();
      const Vec3 omega(W(2, 1), W(0, 2), W(1, 0));
      expectMatrixNear(omega, f.Jw.col(k), kFdTol, "Jw column " + std::to_string(k) + ", " + at, 1.0);
    }
    // curvature d(Jr^T wr + Jw^T ww)/dq
    MatX C = MatX::Zero(6, 7);
    body.addFrameCurvature(q, u, Body::kAnyPoint, nullptr, nullptr, wr, ww, C);
    expectMatrixNear(C, fdJacobian([&](const VecX& z) {
                       FrameKinematics g;
                       body.frameKinematics(z, u, Body::kAnyPoint, nullptr, nullptr, g);
                       return VecX(g.Jr.transpose() * wr + g.Jw.transpose() * ww);
                     }, q), kFdTol, "curvature, " + at, 1.0);
    // gyroscopic force and its Jacobian
    MatX dQdq = MatX::Zero(6, 7), dQdv = MatX::Zero(6, 6);
    body.addInternalForceJacobians(q, v, dQdq, dQdv);
    expectMatrixNear(dQdv, fdJacobian([&](const VecX& z) { VecX Q = VecX::Zero(6); body.addInternalForces(q, z, Q); return Q; }, v),
                     kFdTol, "d(gyroscopic)/dv, " + at, 1.0);
  }
}

/// G against central differences of h along the velocity directions (q (+) eps e_k),
/// and each H_a against central differences of G_a^T over the local coordinates.
void checkConstraintDerivatives(const System& sys, ConstraintIndex c, const VecX& q, const std::string& at) {
  const Constraint& con = sys.constraint(c);
  const auto& qcols = sys.constraintCoordinateColumns(c);
  const auto& vcols = sys.constraintColumns(c);
  ConstraintEvaluation ev;
  con.evaluate(sys.constraintStates(c, q.data()), true, ev);
  ASSERT_EQ(ev.G.cols(), static_cast<int>(vcols.size())) << at;
  const auto hOf = [&](const VecX& z) {
    ConstraintEvaluation e;
    con.evaluate(sys.constraintStates(c, z.data()), false, e);
    return e.h;
  };
  MatX Gfd(con.numEquations(), vcols.size());
  for (size_t k = 0; k < vcols.size(); ++k) {
    VecX dv = VecX::Zero(sys.numVelocities());
    dv[vcols[k]] = kFdRelStep;
    Gfd.col(k) = (hOf(sys.applyIncrement(q, dv)) - hOf(sys.applyIncrement(q, -dv))) / (2.0 * kFdRelStep);
  }
  expectMatrixNear(ev.G, Gfd, kFdTol, "G, " + at, 1.0);
  for (int e = 0; e < con.numEquations(); ++e) {
    const auto GaOf = [&](const VecX& ql) {
      VecX z = q;
      for (size_t k = 0; k < qcols.size(); ++k) z[qcols[k]] = ql[k];
      ConstraintEvaluation x;
      con.evaluate(sys.constraintStates(c, z.data()), false, x);
      return VecX(x.G.row(e).transpose());
    };
    VecX ql(qcols.size());
    for (size_t k = 0; k < qcols.size(); ++k) ql[k] = q[qcols[k]];
    expectMatrixNear(ev.H[e], fdJacobian(GaOf, ql), kFdTol, "H_" + std::to_string(e) + ", " + at, 1.0);
  }
}

/// Two random spatial bodies and a constraint made by `make` between body a (or the
/// ground) and body b, checked at random states.
void checkBetweenRandomBodies(unsigned seed, const std::string& what,
                              const std::function<std::unique_ptr<Constraint>(BodyIndex, const JointFrame&, BodyIndex,
                                                                               const JointFrame&)>& make) {
  Random rnd(seed);
  for (int s = 0; s < kSamples; ++s) {
    for (const bool toGround : {false, true}) {
      System sys;
      const BodyIndex a = sys.addBody(randomBody(rnd, "a"));
      const BodyIndex b = sys.addBody(randomBody(rnd, "b"));
      JointFrame fi, fj;
      fi.point = rnd.vector(3, -1.0, 1.0);
      fi.axes = randomRotation(rnd);
      fj.point = rnd.vector(3, -1.0, 1.0);
      fj.axes = randomRotation(rnd);
      const ConstraintIndex c = sys.addConstraint(make(toGround ? kGround : a, fi, b, fj));
      sys.finalize();
      VecX q(sys.numCoordinates());
      for (BodyIndex bi : {a, b}) q.segment(sys.coordinateOffset(bi), 7) = randomCoordinates(rnd);
      checkConstraintDerivatives(sys, c, q, what + (toGround ? " to ground" : "") + ", sample " + std::to_string(s));
    }
  }
}

class SpatialJointDerivatives : public ::testing::TestWithParam<SpatialJointType> {};

TEST_P(SpatialJointDerivatives, GAndHMatchFiniteDifferencesBetweenTwoBodiesAndToGround) {
  checkBetweenRandomBodies(kSeed + 10 + static_cast<unsigned>(GetParam()), toString(GetParam()),
                           [](BodyIndex i, const JointFrame& fi, BodyIndex j, const JointFrame& fj) {
                             return std::make_unique<SpatialJoint>("j", GetParam(), i, fi, j, fj);
                           });
}

TEST(SpatialDriverDerivatives, AngleAndDisplacementDriversMatchFiniteDifferences) {
  checkBetweenRandomBodies(kSeed + 20, "joint angle", [](BodyIndex i, const JointFrame& fi, BodyIndex j, const JointFrame& fj) {
    return std::make_unique<SpatialJointAngleDriver>("d", i, fi, j, fj, makeConstantLaw(0.0));
  });
  checkBetweenRandomBodies(kSeed + 21, "joint displacement", [](BodyIndex i, const JointFrame& fi, BodyIndex j, const JointFrame& fj) {
    return std::make_unique<SpatialJointDisplacementDriver>("d", i, fi, j, fj, makeConstantLaw(0.0));
  });
}

TEST(SpatialPointJointDerivatives, PointOnLineItsDriverAndPointInPlaneMatchFiniteDifferences) {
  // the frames' points are the joints' points; the line's direction and the plane's
  // normal the z axis of the random frame i
  checkBetweenRandomBodies(kSeed + 30, "point on line", [](BodyIndex i, const JointFrame& fi, BodyIndex j, const JointFrame& fj) {
    return std::make_unique<PointOnLineJoint3d>("j", i, fi.point, j, fj.point, fi.axes.col(2));
  });
  checkBetweenRandomBodies(kSeed + 31, "point on line driver", [](BodyIndex i, const JointFrame& fi, BodyIndex j, const JointFrame& fj) {
    return PointOnLineJoint3d("j", i, fi.point, j, fj.point, fi.axes.col(2)).makeDriver("displacement", "d", makeConstantLaw(0.0));
  });
  checkBetweenRandomBodies(kSeed + 32, "point in plane", [](BodyIndex i, const JointFrame& fi, BodyIndex j, const JointFrame& fj) {
    return std::make_unique<PointInPlaneJoint>("j", i, fi.point, j, fj.point, fi.axes.col(2));
  });
}

INSTANTIATE_TEST_SUITE_P(EveryType, SpatialJointDerivatives,
                         ::testing::Values(SpatialJointType::Spherical, SpatialJointType::Revolute,
                                           SpatialJointType::Prismatic, SpatialJointType::Cylindrical,
                                           SpatialJointType::Universal, SpatialJointType::Fixed,
                                           SpatialJointType::Planar),
                         [](const auto& info) { return std::string(toString(info.param)); });

namespace {

/// A spatial double pendulum with a universal joint and a prismatic-cylindrical pair:
/// every kind of block of the DAE (T(q), the gyroscopic term, joint curvature).
System makeSpatialSystem(Random& rnd) {
  System sys;
  sys.setGravity(Vec3(0.0, -9.81, 0.0));
  const BodyIndex a = sys.addBody(randomBody(rnd, "a"));
  const BodyIndex b = sys.addBody(randomBody(rnd, "b"));
  const BodyIndex c = sys.addBody(randomBody(rnd, "c"));
  JointFrame f0, f1, f2, f3;
  f0.point = Vec3(0.1, 0.2, 0.0);
  f1.point = Vec3(-0.5, 0.0, 0.1);
  f1.axes = randomRotation(rnd);
  f2.point = Vec3(0.5, 0.0, 0.0);
  f3.axes = randomRotation(rnd);
  sys.addConstraint(std::make_unique<SpatialJoint>("rev", SpatialJointType::Revolute, kGround, f0, a, f1));
  sys.addConstraint(std::make_unique<SpatialJoint>("uni", SpatialJointType::Universal, a, f2, b, f3));
  sys.addConstraint(std::make_unique<SpatialJoint>("cyl", SpatialJointType::Cylindrical, b, f0, c, f1));
  sys.finalize();
  return sys;
}

MatX fdIterationMatrix(const DaeSystem& dae, double t, const VecX& y, const VecX& yp, double cj) {
  const int n = dae.layout().size;
  MatX J(n, n);
  VecX Fp(n), Fm(n);
  for (int k = 0; k < n; ++k) {
    VecX yy = y, ypp = yp;
    const double hy = kFdRelStep * (1.0 + std::abs(y[k]));
    yy[k] = y[k] + hy;
    dae.residual(t, yy.data(), yp.data(), Fp.data());
    yy[k] = y[k] - hy;
    dae.residual(t, yy.data(), yp.data(), Fm.data());
    J.col(k) = (Fp - Fm) / (2.0 * hy);
    const double hp = kFdRelStep * (1.0 + std::abs(yp[k]));
    ypp[k] = yp[k] + hp;
    dae.residual(t, y.data(), ypp.data(), Fp.data());
    ypp[k] = yp[k] - hp;
    dae.residual(t, y.data(), ypp.data(), Fm.data());
    J.col(k) += cj * (Fp - Fm) / (2.0 * hp);
  }
  return J;
}

}  // namespace

class SpatialDaeJacobian : public ::testing::TestWithParam<Formulation> {};

TEST_P(SpatialDaeJacobian, IterationMatrixMatchesFiniteDifferencesAndStaysInThePattern) {
  Random rnd(kSeed + 30 + static_cast<unsigned>(GetParam()));
  const System sys = makeSpatialSystem(rnd);
  const DaeSystem dae(sys, GetParam());
  const DaeLayout& L = dae.layout();
  ASSERT_EQ(L.nq, 21);
  ASSERT_EQ(L.nv, 18);
  for (int s = 0; s < kSamples / 2; ++s) {
    VecX y = rnd.vector(L.size, -2.0, 2.0), yp = rnd.vector(L.size, -2.0, 2.0);
    for (int b = 1; b < sys.numBodies(); ++b) {
      y.segment(L.q + sys.coordinateOffset(BodyIndex(b)), 7) = randomCoordinates(rnd);
    }
    const double t = rnd.uniform(0.0, 2.0), cj = 7.3;
    const std::string at = toString(GetParam()) + ", sample " + std::to_string(s);
    MatX J = MatX::Zero(L.size, L.size);
    JacobianSink sink = JacobianSink::dense(J.data(), L.size);
    dae.jacobian(t, y.data(), yp.data(), cj, sink);
    expectRowsNear(J, fdIterationMatrix(dae, t, y, yp, cj), kFdTol, "dF/dy + cj dF/dy', " + at);
    std::vector<Eigen::Triplet<double>> written;
    JacobianSink recorder = JacobianSink::recorder(&written);
    dae.jacobian(t, y.data(), yp.data(), cj, recorder);
    for (const auto& e : written) EXPECT_GE(dae.pattern().find(e.row(), e.col()), 0) << at << ": (" << e.row() << ", " << e.col() << ")";
  }
}

// dF/dy' x from the model's structure (I on the q rows, M(q) on the v rows) against the
// assembled J(1) - J(0), to the round-off of that difference (kRoundOff per row, as the
// planar test in test_jacobians.cpp).
TEST_P(SpatialDaeJacobian, RateJacobianProductEqualsAssembledRateJacobian) {
  Random rnd(kSeed + 50 + static_cast<unsigned>(GetParam()));
  const System sys = makeSpatialSystem(rnd);
  const DaeSystem dae(sys, GetParam());
  if (GetParam() == Formulation::Index1) {
    EXPECT_FALSE(dae.providesRateJacobianProduct());
    return;
  }
  constexpr double kRoundOff = 64.0 * std::numeric_limits<double>::epsilon();
  const DaeLayout& L = dae.layout();
  for (int s = 0; s < kSamples / 2; ++s) {
    VecX y = rnd.vector(L.size, -2.0, 2.0), yp = rnd.vector(L.size, -2.0, 2.0);
    for (int b = 1; b < sys.numBodies(); ++b) {
      y.segment(L.q + sys.coordinateOffset(BodyIndex(b)), 7) = randomCoordinates(rnd);
    }
    const double t = rnd.uniform(0.0, 2.0);
    MatX J0 = MatX::Zero(L.size, L.size), J1 = MatX::Zero(L.size, L.size);
    JacobianSink s0 = JacobianSink::dense(J0.data(), L.size), s1 = JacobianSink::dense(J1.data(), L.size);
    dae.jacobian(t, y.data(), yp.data(), 0.0, s0);
    dae.jacobian(t, y.data(), yp.data(), 1.0, s1);
    const VecX x = rnd.vector(L.size, -1.0, 1.0);
    VecX r = VecX::Zero(L.size);
    dae.addRateJacobianProduct(t, y.data(), yp.data(), x.data(), r.data(), *dae.makeScratch());
    const VecX expected = (J1 - J0) * x;
    const VecX bound = kRoundOff * ((J0.cwiseAbs() + J1.cwiseAbs()) * x.cwiseAbs() + VecX::Ones(L.size));
    for (int i = 0; i < L.size; ++i) {
      EXPECT_LE(std::abs(r[i] - expected[i]), bound[i]) << toString(GetParam()) << ", sample " << s << ", row " << i;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(AllFormulations, SpatialDaeJacobian,
                         ::testing::Values(Formulation::Ggl, Formulation::Index3, Formulation::Index1),
                         [](const auto& info) { return toString(info.param); });

TEST(SpatialForceDerivatives, SpringDampersBushingAndAppliedLoadMatchFiniteDifferences) {
  Random rnd(kSeed + 50);
  for (int s = 0; s < kSamples; ++s) {
    for (const bool toGround : {false, true}) {
      System sys;
      const BodyIndex a = sys.addBody(randomBody(rnd, "a"));
      const BodyIndex b = sys.addBody(randomBody(rnd, "b"));
      const ForceIndex spring = sys.addForce(std::make_unique<SpatialSpringDamper>(
          "spring", toGround ? kGround : a, Vec3(rnd.vector(3, -1, 1)), b, Vec3(rnd.vector(3, -1, 1)), 50.0, 3.0, 0.4));
      const ForceIndex load = sys.addForce(std::make_unique<SpatialAppliedLoad>(
          "load", b, Vec3(rnd.vector(3, -1, 1)),
          std::array<TimeLawPtr, 6>{makeConstantLaw(1.0), makeHarmonicLaw(2.0, 3.0), nullptr, makeConstantLaw(-0.5),
                                    nullptr, makeConstantLaw(0.7)}));
      JointFrame fi, fj;
      fi.point = rnd.vector(3, -1.0, 1.0);
      fi.axes = randomRotation(rnd);
      fj.axes = randomRotation(rnd);
      const ForceIndex torsion = sys.addForce(std::make_unique<SpatialRotationalSpringDamper>(
          "torsion", toGround ? kGround : a, fi, b, fj, 30.0, 1.5, 0.2));
      // user laws (core/user_function.hpp), nonlinear, derivatives by central differences
      const auto law = [](double t, double x, double xdot) {
        return 50.0 * (x - 0.4) + 20.0 * x * x * x + 3.0 * xdot + 0.5 * xdot * xdot * xdot + 0.1 * t * x;
      };
      const ForceIndex userSpring = sys.addForce(std::make_unique<SpatialSpringDamper>(
          "user_spring", toGround ? kGround : a, Vec3(rnd.vector(3, -1, 1)), b, Vec3(rnd.vector(3, -1, 1)), 0.0, 0.0,
          0.0, makeSpringLaw(law)));
      const ForceIndex userTorsion = sys.addForce(std::make_unique<SpatialRotationalSpringDamper>(
          "user_torsion", toGround ? kGround : a, fj, b, fi, 0.0, 0.0, 0.2, makeSpringLaw(law)));
      const ForceIndex bushing = sys.addForce(std::make_unique<SpatialBushing>(
          "bushing", toGround ? kGround : a, fj, b, fi, std::array<double, 6>{10, 20, 30, 4, 5, 6},
          std::array<double, 6>{0.1, 0.2, 0.3, 0.04, 0.05, 0.06}));
      sys.finalize();
      VecX q(sys.numCoordinates());
      for (BodyIndex bi : {a, b}) q.segment(sys.coordinateOffset(bi), 7) = randomCoordinates(rnd);
      const VecX vAll = rnd.vector(sys.numVelocities(), -1.0, 1.0);
      const std::string at = std::string(toGround ? "to ground, " : "") + "sample " + std::to_string(s);
      for (ForceIndex fi : {spring, load, torsion, bushing, userSpring, userTorsion}) {
        const Force& f = sys.force(fi);
        const auto& vcols = sys.forceColumns(fi);
        const auto& qcols = sys.forceCoordinateColumns(fi);
        VecX vl(vcols.size()), ql(qcols.size());
        for (size_t k = 0; k < vcols.size(); ++k) vl[k] = vAll[vcols[k]];
        for (size_t k = 0; k < qcols.size(); ++k) ql[k] = q[qcols[k]];
        const double t = 0.3;
        const auto QOf = [&](const VecX& qq, const VecX& vv) {
          VecX z = q;
          for (size_t k = 0; k < qcols.size(); ++k) z[qcols[k]] = qq[k];
          VecX Q = VecX::Zero(vcols.size());
          f.addForce(t, sys.forceStates(fi, z.data()), vv, Q, nullptr, nullptr);
          return Q;
        };
        VecX Q = VecX::Zero(vcols.size());
        MatX dQdq = MatX::Zero(vcols.size(), qcols.size()), dQdv = MatX::Zero(vcols.size(), vcols.size());
        f.addForce(t, sys.forceStates(fi, q.data()), vl, Q, &dQdq, &dQdv);
        expectMatrixNear(dQdq, fdJacobian([&](const VecX& z) { return QOf(z, vl); }, ql), kFdTol,
                         f.name() + " dQ/dq, " + at, 1.0);
        expectMatrixNear(dQdv, fdJacobian([&](const VecX& z) { return QOf(ql, z); }, vl), kFdTol,
                         f.name() + " dQ/dv, " + at, 1.0);
      }
      // the springs' elastic forces are -dV along the velocity directions (v = 0: no damping)
      for (ForceIndex fi : {spring, torsion, bushing}) {
        const Force& sp = sys.force(fi);
        const auto& vcols = sys.forceColumns(fi);
        VecX Q = VecX::Zero(vcols.size());
        sp.addForce(0.0, sys.forceStates(fi, q.data()), VecX::Zero(vcols.size()), Q, nullptr, nullptr);
        VecX gradV(vcols.size());
        for (size_t k = 0; k < vcols.size(); ++k) {
          VecX dv = VecX::Zero(sys.numVelocities());
          dv[vcols[k]] = kFdRelStep;
          const VecX qp = sys.applyIncrement(q, dv), qm = sys.applyIncrement(q, -dv);
          gradV[k] = (sp.potentialEnergy(sys.forceStates(fi, qp.data())) -
                      sp.potentialEnergy(sys.forceStates(fi, qm.data()))) / (2.0 * kFdRelStep);
        }
        expectMatrixNear(Q, -gradV, kFdTol, sp.name() + " force = -dV, " + at, 1.0);
      }
    }
  }
}
