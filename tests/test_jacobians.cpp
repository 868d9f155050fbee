// Unit tests of every analytic derivative of the engine against central finite
// differences: rigid-body kinematics, mass-matrix derivative, internal and gravity
// force Jacobians; constraint Jacobians and Hessians of every joint and driver; force
// Jacobians of every force element (and force = -grad(energy) for conservative ones);
// the full DAE iteration matrix dF/dy + cj dF/dy' of every formulation, and the
// agreement of the sparse and dense Jacobian sinks.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <ostream>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "bodies/ffr_beam_model.hpp"
#include "bodies/ffr_body_2d.hpp"
#include "bodies/rigid_body_2d.hpp"
#include "builders/planar_builders.hpp"
#include "core/dae_system.hpp"
#include "core/errors.hpp"
#include "core/sparse_pattern.hpp"
#include "core/system.hpp"
#include "core/time_law.hpp"
#include "forces/applied_load.hpp"
#include "forces/rotational_spring_damper.hpp"
#include "forces/spring_damper.hpp"
#include "joints/drivers.hpp"
#include "joints/fixed_joint.hpp"
#include "joints/point_on_line_joint.hpp"
#include "joints/prismatic_joint.hpp"
#include "joints/revolute_joint.hpp"
#include "tests/test_support.hpp"

namespace flexmbd {

// Readable parameter values in GoogleTest messages (found by ADL in flexmbd).
void PrintTo(Formulation f, std::ostream* os) { *os << toString(f); }

namespace {

using namespace testsupport;

// Fixed seed: the random configurations are the same on every run (reproducible).
constexpr unsigned kSeed = 20240611u;
// Random configurations per case: enough to visit every quadrant of the angles.
constexpr int kSamples = 8;

// Central-difference step relative to the variable: h = kFdRelStep (1 + |x|).
// Balances truncation h^2/6 |f'''| against roundoff eps |f| / h near their minimum
// (h ~ eps^(1/3) ~ 6e-6).
constexpr double kFdRelStep = 1e-6;
// Tolerance of analytic vs finite-difference derivatives, relative to
// max(1, largest entry compared). With h = 1e-6 (1 + |x|), |x| <= 4: truncation
// h^2/6 |f'''| <= 5e-12 |f'''| and roundoff ~ eps |f| / h <= 2.2e-10 |f|. Here
// |f| <= ~1e3 (springs k <= 150 over lengths <= 8, gravity ~10 m) and |f'''| <= ~1e4
// (spring lengths kept >= 0.5), so the error is <= ~3e-7 absolute against entries
// >= ~1e2 in those rows, i.e. <= ~1e-8 relative (measured: <= 1.2e-8, the dQ/dv of
// the stiff springs; <= 2e-9 elsewhere). 1e-6 leaves a wide margin while a wrong sign
// or a missing term gives errors of order 1 (checked by mutating the library).
constexpr double kFdTol = 1e-6;
// Hessians are assembled from a handful of products; H and H^T differ only by the
// order of floating-point additions: a few ulps of the entries, <= 1e-15 relative.
// 1e-13 bounds that; a genuinely unsymmetric term would be O(1) relative.
constexpr double kSymmetryTol = 1e-13;
// Identities that hold exactly in exact arithmetic and are evaluated with a few
// dozen operations on O(1..1e3) numbers: error <= ~1e-13 relative.
constexpr double kRoundoffTol = 1e-12;

double fdStep(double x) { return kFdRelStep * (1.0 + std::abs(x)); }

/// Central differences with the steps fdStep.
MatX fdJacobian(const std::function<VecX(const VecX&)>& f, const VecX& x) {
  return testsupport::fdJacobian(f, x, relativeSteps(x, kFdRelStep));
}
VecX fdGradient(const std::function<double(const VecX&)>& f, const VecX& x) {
  return testsupport::fdGradient(f, x, relativeSteps(x, kFdRelStep));
}

/// Entries compared relative to max(1, largest entry): the values here are O(1..1e3).
void expectNear(const MatX& analytic, const MatX& reference, double tol, const std::string& what) {
  expectMatrixNear(analytic, reference, tol, what, 1.0);
}

RigidBodyProperties randomProperties(Random& rnd) {
  RigidBodyProperties p;
  p.mass = rnd.uniform(0.5, 5.0);
  p.inertia = rnd.uniform(0.1, 2.0);
  // centre of mass clearly off the frame origin
  p.com = Vec2(rnd.uniform(0.3, 1.2), rnd.uniform(-0.8, -0.2));
  return p;
}

// =====================================================================================
// 1. RigidBody2d
// =====================================================================================

TEST(RigidBodyJacobians, PointKinematicsFirstAndSecondDerivatives) {
  Random rnd(kSeed);
  for (int s = 0; s < kSamples; ++s) {
    const RigidBody2d body("link", randomProperties(rnd), FrameState2d{});
    const VecX q = rnd.frame();
    const Vec2 u = rnd.vec2(-2.0, 2.0);
    const PointKinematics pk = body.pointKinematics(q, u);
    const std::string at = "sample " + std::to_string(s);

    // J = d[r; phi]/dq
    const MatX Jfd = fdJacobian(
        [&](const VecX& z) {
          const PointKinematics p = body.pointKinematics(z, u);
          return VecX(Eigen::Vector3d(p.r.x(), p.r.y(), p.phi));
        },
        q);
    expectNear(pk.Jr, Jfd.topRows(2), kFdTol, "Jr, " + at);
    expectNear(pk.Jphi, Jfd.row(2), kFdTol, "Jphi, " + at);

    // Hessians = d(J rows)/dq
    auto rowOf = [&](int which) {
      return [&, which](const VecX& z) -> VecX {
        const PointKinematics p = body.pointKinematics(z, u);
        if (which < 2) return p.Jr.row(which).transpose();
        return p.Jphi.transpose();
      };
    };
    expectNear(pk.Hrx, fdJacobian(rowOf(0), q), kFdTol, "Hrx, " + at);
    expectNear(pk.Hry, fdJacobian(rowOf(1), q), kFdTol, "Hry, " + at);
    expectNear(pk.Hphi, fdJacobian(rowOf(2), q), kFdTol, "Hphi, " + at);
    // hessianR(w) is the w-weighted sum
    const Vec2 w = rnd.vec2(-2.0, 2.0);
    expectNear(pk.hessianR(w), w.x() * pk.Hrx + w.y() * pk.Hry, kRoundoffTol,
                     "hessianR, " + at);
  }
}

TEST(RigidBodyJacobians, MassMatrixDerivative) {
  Random rnd(kSeed + 1);
  for (int s = 0; s < kSamples; ++s) {
    const RigidBody2d body("link", randomProperties(rnd), FrameState2d{});
    const VecX q = rnd.frame();
    const VecX a = rnd.vector(3, -3.0, 3.0);
    // The method accumulates (+=): start from a non-zero matrix.
    const MatX K0 = MatX::Constant(3, 3, 0.25);
    MatX K = K0;
    body.addMassMatrixDerivative(q, a, K);
    const MatX Kfd = fdJacobian([&](const VecX& z) -> VecX { return body.massMatrix(z) * a; }, q);
    expectNear(K - K0, Kfd, kFdTol, "d(M a)/dq, sample " + std::to_string(s));
  }
}

TEST(RigidBodyJacobians, InternalForceJacobians) {
  Random rnd(kSeed + 2);
  for (int s = 0; s < kSamples; ++s) {
    const RigidBody2d body("link", randomProperties(rnd), FrameState2d{});
    const VecX q = rnd.frame();
    const VecX v = rnd.vector(3, -3.0, 3.0);
    auto Q = [&](const VecX& qq, const VecX& vv) {
      VecX out = VecX::Zero(3);
      body.addInternalForces(qq, vv, out);
      return out;
    };
    MatX dQdq = MatX::Zero(3, 3), dQdv = MatX::Zero(3, 3);
    body.addInternalForceJacobians(q, v, dQdq, dQdv);
    const std::string at = "sample " + std::to_string(s);
    expectNear(dQdq, fdJacobian([&](const VecX& z) { return Q(z, v); }, q), kFdTol,
                     "dQ/dq, " + at);
    expectNear(dQdv, fdJacobian([&](const VecX& z) { return Q(q, z); }, v), kFdTol,
                     "dQ/dv, " + at);
  }
}

TEST(RigidBodyJacobians, GravityJacobianAndPotential) {
  Random rnd(kSeed + 3);
  for (int s = 0; s < kSamples; ++s) {
    const RigidBody2d body("link", randomProperties(rnd), FrameState2d{});
    const VecX q = rnd.frame();
    const Vec3 g = lift(rnd.vec2(-10.0, 10.0));
    auto Q = [&](const VecX& z) {
      VecX out = VecX::Zero(3);
      body.addGravityForce(z, g, out);
      return out;
    };
    MatX K = MatX::Zero(3, 3);
    body.addGravityJacobian(q, g, K);
    const std::string at = "sample " + std::to_string(s);
    expectNear(K, fdJacobian(Q, q), kFdTol, "d(gravity)/dq, " + at);
    // A conservative force: Q_g = -dV/dq.
    const VecX gradV = fdGradient([&](const VecX& z) { return body.gravityPotential(z, g); }, q);
    expectNear(Q(q), -gradV, kFdTol, "gravity force vs -dV/dq, " + at);
  }
}

// =====================================================================================
// 2. Constraints
// =====================================================================================

/// Checks h, G and the Hessians of constraint ci at the global coordinates q.
void checkConstraintDerivatives(const System& sys, ConstraintIndex ci, const VecX& q,
                                const std::string& at) {
  const Constraint& con = sys.constraint(ci);
  const std::vector<int>& cols = sys.constraintColumns(ci);
  const int me = con.numEquations(), nl = static_cast<int>(cols.size());
  const std::string who = con.typeName() + " '" + con.name() + "', " + at;

  ConstraintEvaluation ev;
  con.evaluate(sys.constraintStates(ci, q.data()), true, ev);
  ASSERT_EQ(ev.h.size(), me) << who;
  ASSERT_EQ(ev.G.rows(), me) << who;
  ASSERT_EQ(ev.G.cols(), nl) << who;
  ASSERT_EQ(static_cast<int>(ev.H.size()), me) << who;

  // Without Hessians h and G are the same (bitwise: same code path).
  ConstraintEvaluation ev0;
  con.evaluate(sys.constraintStates(ci, q.data()), false, ev0);
  EXPECT_TRUE(ev0.h == ev.h) << who;
  EXPECT_TRUE(ev0.G == ev.G) << who;

  VecX ql(nl);
  for (int k = 0; k < nl; ++k) ql[k] = q[cols[k]];
  // Evaluates the constraint with the local coordinates replaced by z.
  auto evalAt = [&](const VecX& z) {
    VecX qg = q;
    for (int k = 0; k < nl; ++k) qg[cols[k]] = z[k];
    ConstraintEvaluation e;
    con.evaluate(sys.constraintStates(ci, qg.data()), false, e);
    return e;
  };
  expectNear(ev.G, fdJacobian([&](const VecX& z) { return evalAt(z).h; }, ql), kFdTol,
                   "G vs FD of h, " + who);
  for (int a = 0; a < me; ++a) {
    ASSERT_EQ(ev.H[a].rows(), nl) << who;
    ASSERT_EQ(ev.H[a].cols(), nl) << who;
    const MatX Hfd = fdJacobian(
        [&](const VecX& z) -> VecX { return evalAt(z).G.row(a).transpose(); }, ql);
    expectNear(ev.H[a], Hfd, kFdTol, "H_" + std::to_string(a) + " vs FD of G row, " + who);
    expectNear(ev.H[a], ev.H[a].transpose(), kSymmetryTol,
                     "H_" + std::to_string(a) + " symmetric, " + who);
  }
}

TEST(ConstraintJacobians, EveryConstraintTypeBetweenBodiesAndWithGround) {
  Random rnd(kSeed + 10);
  System sys;
  const BodyIndex a = addRigidBody(sys, "a", randomProperties(rnd), FrameState2d{});
  const BodyIndex b = addRigidBody(sys, "b", randomProperties(rnd), FrameState2d{});
  const Vec2 prismaticAxis(0.6, -1.3);      // not unit, not axis-aligned
  const Vec2 displacementAxis(-0.8, 0.5);   // not unit, not axis-aligned
  const double prismaticReference = 0.7;
  const double fixedReference = -0.4;

  // Every two-point constraint for the pairs (a, b), (ground, b), (a, ground).
  const std::vector<std::pair<BodyIndex, BodyIndex>> pairs = {{a, b}, {kGround, b}, {a, kGround}};
  const std::vector<std::string> pairNames = {"a_b", "ground_b", "a_ground"};
  std::vector<ConstraintIndex> all;
  for (size_t p = 0; p < pairs.size(); ++p) {
    const auto [i, j] = pairs[p];
    const std::string sfx = "_" + pairNames[p];
    const Vec2 ui = rnd.vec2(-1.5, 1.5), uj = rnd.vec2(-1.5, 1.5);
    all.push_back(sys.addConstraint(std::make_unique<RevoluteJoint>("rev" + sfx, i, ui, j, uj)));
    all.push_back(sys.addConstraint(std::make_unique<PrismaticJoint>(
        "pri" + sfx, i, ui, j, uj, prismaticAxis, prismaticReference)));
    all.push_back(sys.addConstraint(
        std::make_unique<FixedJoint>("fix" + sfx, i, ui, j, uj, fixedReference)));
    all.push_back(sys.addConstraint(std::make_unique<JointAngleDriver>(
        "ang" + sfx, i, ui, j, uj, makeHarmonicLaw(0.5, 2.0, 0.1, 0.2))));
    all.push_back(sys.addConstraint(std::make_unique<JointDisplacementDriver>(
        "dis" + sfx, i, ui, j, uj, displacementAxis, makeConstantSpeedLaw(0.3, 0.1))));
    all.push_back(addPointOnLineJoint(sys, "pol" + sfx, i, ui, j, uj, prismaticAxis));
    all.push_back(sys.addConstraint(sys.constraint(all.back()).makeDriver("displacement", "pold" + sfx,
                                                                          makeHarmonicLaw(0.4, 1.5))));
  }
  // Body-coordinate drivers on every coordinate of b.
  for (const char* c : {"x", "y", "theta"}) {
    all.push_back(addBodyCoordinateDriver(sys, std::string("drv_") + c, b, c,
                                          makeHarmonicLaw(1.0, 3.0)));
  }
  // The convenience builders (builders/; reference angles from the initial positions,
  // drivers derived from the joints).
  const ConstraintIndex rev = addRevoluteJoint(sys, "rev_builder", a, Vec2(0.4, -0.2), b,
                                               Vec2(-0.6, 0.3));
  const ConstraintIndex pri =
      addPrismaticJoint(sys, "pri_builder", kGround, Vec2(0.5, 0.5), b, Vec2(0.2, -0.1),
                        Vec2(1.0, 2.0));
  all.push_back(rev);
  all.push_back(pri);
  all.push_back(addFixedJoint(sys, "fix_builder", a, Vec2(1.0, 0.0), b, Vec2(0.0, 1.0)));
  all.push_back(addJointDriver(sys, "ang_builder", rev, makeConstantSpeedLaw(1.0)));
  all.push_back(addJointDriver(sys, "dis_builder", pri, makeConstantSpeedLaw(1.0)));
  sys.finalize();

  for (int s = 0; s < kSamples; ++s) {
    VecX q(sys.numCoordinates());
    q.segment(sys.coordinateOffset(a), 3) = rnd.frame();
    q.segment(sys.coordinateOffset(b), 3) = rnd.frame();
    for (ConstraintIndex ci : all) {
      checkConstraintDerivatives(sys, ci, q, "sample " + std::to_string(s));
    }
  }
}

// =====================================================================================
// 3. Forces
// =====================================================================================

/// Checks dQ/dq, dQ/dv of force fi against finite differences of addForce.
void checkForceDerivatives(const System& sys, ForceIndex fi, double t, const VecX& q,
                           const VecX& v, const std::string& at) {
  const Force& force = sys.force(fi);
  const std::vector<int>& cols = sys.forceColumns(fi);
  const int nl = static_cast<int>(cols.size());
  const std::string who = force.typeName() + " '" + force.name() + "', " + at;
  VecX ql(nl), vl(nl);
  for (int k = 0; k < nl; ++k) {
    ql[k] = q[cols[k]];
    vl[k] = v[cols[k]];
  }
  auto Q = [&](const VecX& qz, const VecX& vz) {
    VecX qg = q;
    for (int k = 0; k < nl; ++k) qg[cols[k]] = qz[k];
    VecX out = VecX::Zero(nl);
    force.addForce(t, sys.forceStates(fi, qg.data()), vz, out, nullptr, nullptr);
    return out;
  };
  VecX Qj = VecX::Zero(nl);
  MatX dQdq = MatX::Zero(nl, nl), dQdv = MatX::Zero(nl, nl);
  force.addForce(t, sys.forceStates(fi, q.data()), vl, Qj, &dQdq, &dQdv);
  // The force itself does not depend on whether Jacobians are requested.
  EXPECT_TRUE(Qj == Q(ql, vl)) << who;
  expectNear(dQdq, fdJacobian([&](const VecX& z) { return Q(z, vl); }, ql), kFdTol,
                   "dQ/dq, " + who);
  expectNear(dQdv, fdJacobian([&](const VecX& z) { return Q(ql, z); }, vl), kFdTol,
                   "dQ/dv, " + who);
}

/// Q(q, v = 0) = -dV/dq (a damper exerts no force at rest, so this holds for c > 0 too).
void checkForceIsEnergyGradient(const System& sys, ForceIndex fi, const VecX& q,
                                const std::string& at) {
  const Force& force = sys.force(fi);
  const std::vector<int>& cols = sys.forceColumns(fi);
  const int nl = static_cast<int>(cols.size());
  const std::string who = force.typeName() + " '" + force.name() + "', " + at;
  VecX ql(nl);
  for (int k = 0; k < nl; ++k) ql[k] = q[cols[k]];
  auto withLocal = [&](const VecX& z) {
    VecX qg = q;
    for (int k = 0; k < nl; ++k) qg[cols[k]] = z[k];
    return qg;
  };
  VecX Q = VecX::Zero(nl);
  force.addForce(0.0, sys.forceStates(fi, q.data()), VecX::Zero(nl), Q, nullptr,
                 nullptr);
  const VecX gradV = fdGradient(
      [&](const VecX& z) {
        const VecX qg = withLocal(z);
        return force.potentialEnergy(sys.forceStates(fi, qg.data()));
      },
      ql);
  expectNear(Q, -gradV, kFdTol, "Q vs -dV/dq, " + who);
}

struct ForceCase {
  System sys;
  BodyIndex a, b;
  ForceIndex load;
  std::vector<ForceIndex> all, conservative;
};

/// A spring-damper law nonlinear in x, x' and t.
double nonlinearLaw(double t, double x, double xdot) {
  const double s = x - 0.8;
  return 150.0 * s + 40.0 * s * s * s + 4.5 * xdot + 0.7 * xdot * xdot * xdot + 0.2 * t * x;
}

std::unique_ptr<ForceCase> makeForceCase(Random& rnd) {
  auto fc = std::make_unique<ForceCase>();
  System& sys = fc->sys;
  fc->a = addRigidBody(sys, "a", randomProperties(rnd), FrameState2d{});
  fc->b = addRigidBody(sys, "b", randomProperties(rnd), FrameState2d{});
  const BodyIndex a = fc->a, b = fc->b;
  const std::vector<std::pair<BodyIndex, BodyIndex>> pairs = {{a, b}, {kGround, b}, {a, kGround}};
  const std::vector<std::string> pairNames = {"a_b", "ground_b", "a_ground"};
  for (size_t p = 0; p < pairs.size(); ++p) {
    const auto [i, j] = pairs[p];
    const std::string sfx = "_" + pairNames[p];
    const Vec2 ui = rnd.vec2(-1.0, 1.0), uj = rnd.vec2(-1.0, 1.0);
    fc->all.push_back(sys.addForce(
        std::make_unique<SpringDamper>("spring" + sfx, i, ui, j, uj, 150.0, 4.5, 0.8)));
    fc->conservative.push_back(sys.addForce(
        std::make_unique<SpringDamper>("spring0" + sfx, i, uj, j, ui, 90.0, 0.0, 1.3)));
    fc->all.push_back(sys.addForce(std::make_unique<RotationalSpringDamper>(
        "torsion" + sfx, i, ui, j, uj, 35.0, 2.5, 0.3)));
    fc->conservative.push_back(sys.addForce(std::make_unique<RotationalSpringDamper>(
        "torsion0" + sfx, i, ui, j, uj, 20.0, 0.0, -1.1)));
    // user laws (core/user_function.hpp), nonlinear in x, x' and t, their derivatives by
    // central differences inside the law
    fc->all.push_back(sys.addForce(std::make_unique<SpringDamper>(
        "user_spring" + sfx, i, ui, j, uj, 0.0, 0.0, 0.0, makeSpringLaw(nonlinearLaw))));
    fc->all.push_back(sys.addForce(std::make_unique<RotationalSpringDamper>(
        "user_torsion" + sfx, i, ui, j, uj, 0.0, 0.0, 0.0, makeSpringLaw(nonlinearLaw))));
  }
  fc->load = sys.addForce(std::make_unique<AppliedLoad>(
      "load", b, Vec2(0.7, -0.4), makeHarmonicLaw(3.0, 2.0, 0.4, 1.0),
      makePolynomialLaw({-2.0, 1.5, 0.5}), makeConstantSpeedLaw(-1.2, 0.8)));
  fc->all.push_back(fc->load);
  fc->all.push_back(sys.addForce(std::make_unique<AppliedLoad>(
      "load_partial", a, Vec2(-0.3, 1.1), nullptr, makeHarmonicLaw(2.0, 1.0), nullptr)));
  for (ForceIndex f : fc->conservative) fc->all.push_back(f);
  sys.finalize();
  return fc;
}

/// Random q with every spring longer than 0.5 (the spring direction d/l is then smooth
/// on the finite-difference stencil and its third derivatives stay moderate).
VecX randomForceConfiguration(Random& rnd, const ForceCase& fc) {
  const System& sys = fc.sys;
  for (;;) {
    VecX q(sys.numCoordinates());
    q.segment(sys.coordinateOffset(fc.a), 3) = rnd.frame();
    q.segment(sys.coordinateOffset(fc.b), 3) = rnd.frame();
    bool ok = true;
    for (int f = 0; f < sys.numForces(); ++f) {
      const auto* s = dynamic_cast<const SpringDamper*>(&sys.force(ForceIndex(f)));
      if (s && s->length(sys.forceStates(ForceIndex(f), q.data())) < 0.5) ok = false;
    }
    if (ok) return q;
  }
}

TEST(ForceJacobians, EveryForceTypeMatchesFiniteDifferences) {
  Random rnd(kSeed + 20);
  const auto fc = makeForceCase(rnd);
  const System& sys = fc->sys;
  for (int s = 0; s < kSamples; ++s) {
    const VecX q = randomForceConfiguration(rnd, *fc);
    const VecX v = rnd.vector(sys.numCoordinates(), -3.0, 3.0);
    const double t = rnd.uniform(0.0, 3.0);
    for (ForceIndex f : fc->all) checkForceDerivatives(sys, f, t, q, v, "sample " + std::to_string(s));
  }
}

TEST(ForceJacobians, ConservativeForcesAreMinusEnergyGradient) {
  Random rnd(kSeed + 21);
  const auto fc = makeForceCase(rnd);
  const System& sys = fc->sys;
  for (ForceIndex f : fc->conservative) EXPECT_TRUE(sys.force(f).isConservative()) << sys.force(f).name();
  for (int s = 0; s < kSamples; ++s) {
    const VecX q = randomForceConfiguration(rnd, *fc);
    for (int f = 0; f < sys.numForces(); ++f) {
      const Force& force = sys.force(ForceIndex(f));
      if (force.typeName() == "applied_load") continue;  // no potential
      if (force.name().rfind("user_", 0) == 0) continue;  // a user law: no potential the engine knows
      // c = 0 forces, and damped ones at rest
      checkForceIsEnergyGradient(sys, ForceIndex(f), q, "sample " + std::to_string(s));
    }
  }
}

TEST(ForceJacobians, AppliedLoadIsTheVirtualWorkOfForceAndTorque) {
  // Q = [F; (A u) x F + tau] for a rigid body (virtual work of F at r = R + A u and tau).
  Random rnd(kSeed + 22);
  const auto fc = makeForceCase(rnd);
  const System& sys = fc->sys;
  const ForceIndex load = fc->load;
  ASSERT_EQ(sys.force(load).name(), "load");
  const auto F = makeHarmonicLaw(3.0, 2.0, 0.4, 1.0);
  const auto Fy = makePolynomialLaw({-2.0, 1.5, 0.5});
  const auto tau = makeConstantSpeedLaw(-1.2, 0.8);
  const Vec2 u(0.7, -0.4);
  for (int s = 0; s < kSamples; ++s) {
    const VecX q = randomForceConfiguration(rnd, *fc);
    const double t = rnd.uniform(0.0, 3.0);
    VecX Q = VecX::Zero(3);
    sys.force(load).addForce(t, sys.forceStates(load, q.data()), VecX::Zero(3), Q,
                             nullptr, nullptr);
    const double th = q[sys.coordinateOffset(fc->b) + 2];
    const Vec2 au(std::cos(th) * u.x() - std::sin(th) * u.y(),
                  std::sin(th) * u.x() + std::cos(th) * u.y());
    const Vec2 f(F->evaluate(t).f, Fy->evaluate(t).f);
    const VecX expected = Eigen::Vector3d(f.x(), f.y(), au.x() * f.y() - au.y() * f.x() + tau->evaluate(t).f);
    expectNear(Q, expected, kRoundoffTol, "applied load, sample " + std::to_string(s));
  }
}

// =====================================================================================
// 4. DaeSystem
// =====================================================================================

/// A model with every component: slider-crank with centre-of-mass offsets on a tilted
/// slide line, driven by a harmonic body-angle driver; a small body welded to the rod;
/// a spring-damper from ground to the slider; a rotational spring-damper in the crank
/// pin; an applied load on the rod; gravity; a carriage on a tilted prismatic joint to
/// ground driven in displacement and an arm hinged on it driven in angle; a flexible
/// beam hinged to the arm.
System makeEverythingSystem() {
  System sys;
  sys.setGravity(Vec2(0.0, -9.81));
  const double l1 = 1.0, l2 = 2.0;
  const double slideAngle = 0.35;
  const Vec2 slideAxis(std::cos(slideAngle), std::sin(slideAngle));
  const double crank0 = 0.9;
  const Vec2 pin(l1 * std::cos(crank0), l1 * std::sin(crank0));
  // slider on the line s * slideAxis at distance l2 from the pin
  const double pa = pin.dot(slideAxis);
  const double sSlider = pa + std::sqrt(l2 * l2 - (pin.squaredNorm() - pa * pa));
  const Vec2 sliderPos = sSlider * slideAxis;
  const double rodAngle = std::atan2(sliderPos.y() - pin.y(), sliderPos.x() - pin.x());

  const BodyIndex crank = addRigidBody(sys, "crank", {2.0, 0.2, Vec2(0.45, 0.06)},
                                       {Vec2::Zero(), crank0, Vec2::Zero(), 0.0});
  const BodyIndex rod = addRigidBody(sys, "rod", {3.0, 1.1, Vec2(1.1, -0.12)},
                                     {pin, rodAngle, Vec2::Zero(), 0.0});
  const BodyIndex slider = addRigidBody(sys, "slider", {1.5, 0.05, Vec2(0.08, 0.03)},
                                        {sliderPos, slideAngle, Vec2::Zero(), 0.0});
  const Vec2 weldPoint(1.0, 0.2);
  const Vec2 weightPos = pin + rotation(rodAngle) * weldPoint;
  const BodyIndex weight = addRigidBody(sys, "weight", {0.3, 0.01, Vec2(0.02, -0.05)},
                                        {weightPos, rodAngle + 0.5, Vec2::Zero(), 0.0});
  const ConstraintIndex pivot = addRevoluteJoint(sys, "pivot", kGround, Vec2::Zero(), crank, Vec2::Zero());
  (void)pivot;
  const ConstraintIndex crankPin = addRevoluteJoint(sys, "crank_pin", crank, Vec2(l1, 0.0), rod, Vec2::Zero());
  addRevoluteJoint(sys, "wrist", rod, Vec2(l2, 0.0), slider, Vec2::Zero());
  addPrismaticJoint(sys, "slide", kGround, Vec2::Zero(), slider, Vec2::Zero(), slideAxis);
  addFixedJoint(sys, "weld", rod, weldPoint, weight, Vec2::Zero());
  addBodyCoordinateDriver(sys, "motor", crank, "theta", makeHarmonicLaw(0.4, 3.0, 0.2, crank0));

  const Vec2 carriageAxis(-0.5, 1.0);
  const BodyIndex carriage = addRigidBody(sys, "carriage", {1.2, 0.3, Vec2(-0.1, 0.2)},
                                          {Vec2(3.0, 1.0), 0.25, Vec2::Zero(), 0.0});
  const BodyIndex arm = addRigidBody(sys, "arm", {0.8, 0.15, Vec2(0.6, 0.05)},
                                     {Vec2(3.2, 1.1), -0.6, Vec2::Zero(), 0.0});
  const ConstraintIndex carriageSlide =
      addPrismaticJoint(sys, "carriage_slide", kGround, Vec2(3.0, 1.0), carriage, Vec2::Zero(), carriageAxis);
  const ConstraintIndex hinge =
      addRevoluteJoint(sys, "hinge", carriage, Vec2(0.2, 0.1), arm, Vec2::Zero());
  addJointDriver(sys, "lift", carriageSlide, makePolynomialLaw({0.0, 0.2, -0.1}));
  addJointDriver(sys, "swing", hinge, makeHarmonicLaw(0.3, 1.5, 0.0, -0.85));

  // A flexible beam (4 FFR elements, geometric stiffening, damping) hinged at its middle
  // node to the arm, loaded at a quarter node, sprung at its end node: joints and forces
  // on nodes use only the frame and that node's coordinates (sparse Jacobian blocks).
  BeamSection section;
  section.area = 1e-3;
  section.inertia = 1e-7;
  section.youngsModulus = 1e5;
  section.density = 1000.0;
  section.damping = 0.01;
  FfrBeamOptions beamOptions;
  beamOptions.geometricStiffening = true;
  auto beamModel = std::make_shared<const FfrBeamModel>(BeamMesh2d::straight(1.0, 4, section), beamOptions,
                                                        "body 'beam'");
  const BodyIndex beam = sys.addBody(std::make_unique<FfrBody2d>(
      "beam", beamModel, FrameState2d{Vec2(2.7, 1.6), 0.3, Vec2::Zero(), 0.0}));
  addRevoluteJoint(sys, "beam_hinge", arm, Vec2(0.6, 0.0), beam, Vec2(0.5, 0.0));
  addSpringDamper(sys, "beam_spring", kGround, Vec2(4.0, 2.5), beam, Vec2(1.0, 0.0), 50.0, 2.0, 1.0);
  addAppliedLoad(sys, "beam_load", beam, Vec2(0.25, 0.0), makeHarmonicLaw(1.0, 2.0, 0.1), makeConstantLaw(0.5),
                 makeConstantLaw(0.2));
  addBodyCoordinateDriver(sys, "beam_mode", beam, "q4", makeHarmonicLaw(0.01, 5.0, 0.0));

  addSpringDamper(sys, "spring", kGround, Vec2(-1.0, 0.5), slider, Vec2(0.1, 0.05), 120.0, 3.0, 1.5);
  addRotationalSpringDamper(sys, "torsion", crankPin, 25.0, 1.5, 0.2);
  addAppliedLoad(sys, "load", rod, Vec2(1.5, 0.1), makeHarmonicLaw(4.0, 2.5, 0.3),
                 makeConstantLaw(-2.0), makePolynomialLaw({0.5, -0.3}));
  sys.finalize();
  return sys;
}

/// Random state (y, yp) of the DAE; positions anywhere (angles on the whole circle).
void randomDaeState(Random& rnd, const System& sys, const DaeSystem& dae, VecX& y, VecX& yp) {
  const DaeLayout& L = dae.layout();
  for (;;) {
    y = rnd.vector(L.size, -3.0, 3.0);
    yp = rnd.vector(L.size, -3.0, 3.0);
    for (int b = 1; b < sys.numBodies(); ++b) y[L.q + sys.coordinateOffset(BodyIndex(b)) + 2] = rnd.angle();
    // keep the spring away from zero length (its direction is undefined there)
    bool ok = true;
    for (int f = 0; f < sys.numForces(); ++f) {
      const auto* s = dynamic_cast<const SpringDamper*>(&sys.force(ForceIndex(f)));
      if (s && s->length(sys.forceStates(ForceIndex(f), y.data() + L.q)) < 0.5) ok = false;
    }
    if (ok) return;
  }
}

/// dF/dy + cj dF/dy' by central differences of the residual.
MatX fdIterationMatrix(const DaeSystem& dae, double t, const VecX& y, const VecX& yp, double cj) {
  const int n = dae.layout().size;
  MatX J(n, n);
  VecX Fp(n), Fm(n);
  for (int k = 0; k < n; ++k) {
    VecX yy = y, ypp = yp;
    const double hy = fdStep(y[k]);
    yy[k] = y[k] + hy;
    dae.residual(t, yy.data(), yp.data(), Fp.data());
    yy[k] = y[k] - hy;
    dae.residual(t, yy.data(), yp.data(), Fm.data());
    J.col(k) = (Fp - Fm) / (2.0 * hy);
    const double hp = fdStep(yp[k]);
    ypp[k] = yp[k] + hp;
    dae.residual(t, y.data(), ypp.data(), Fp.data());
    ypp[k] = yp[k] - hp;
    dae.residual(t, y.data(), ypp.data(), Fm.data());
    J.col(k) += cj * (Fp - Fm) / (2.0 * hp);
  }
  return J;
}

class DaeJacobian : public ::testing::TestWithParam<Formulation> {};

TEST_P(DaeJacobian, IterationMatrixMatchesFiniteDifferencesOfResidual) {
  const System sys = makeEverythingSystem();
  const DaeSystem dae(sys, GetParam());
  const int n = dae.layout().size;
  constexpr double kCj = 7.3;  // any value: the identity holds for every cj
  Random rnd(kSeed + 30 + static_cast<unsigned>(GetParam()));
  for (int s = 0; s < kSamples / 2; ++s) {
    VecX y, yp;
    randomDaeState(rnd, sys, dae, y, yp);
    const double t = rnd.uniform(0.0, 2.0);
    for (const double cj : {kCj, 0.0}) {
      MatX J = MatX::Zero(n, n);
      JacobianSink sink = JacobianSink::dense(J.data(), n);
      dae.jacobian(t, y.data(), yp.data(), cj, sink);
      expectRowsNear(J, fdIterationMatrix(dae, t, y, yp, cj), kFdTol,
                     toString(GetParam()) + " dF/dy + cj dF/dy' (cj = " + std::to_string(cj) +
                         "), sample " + std::to_string(s));
    }
  }
}

TEST_P(DaeJacobian, SparseSinkEqualsDenseSinkAndStaysInPattern) {
  const System sys = makeEverythingSystem();
  const DaeSystem dae(sys, GetParam());
  const SparsePattern& P = dae.pattern();
  const int n = dae.layout().size;
  ASSERT_EQ(P.size(), n);
  Random rnd(kSeed + 40 + static_cast<unsigned>(GetParam()));
  for (int s = 0; s < kSamples / 2; ++s) {
    VecX y, yp;
    randomDaeState(rnd, sys, dae, y, yp);
    const double t = rnd.uniform(0.0, 2.0);
    const double cj = 7.3;
    const std::string at = toString(GetParam()) + ", sample " + std::to_string(s);

    // every entry the assembly writes at this state is in the pattern
    std::vector<Eigen::Triplet<double>> written;
    JacobianSink recorder = JacobianSink::recorder(&written);
    dae.jacobian(t, y.data(), yp.data(), cj, recorder);
    EXPECT_FALSE(written.empty());
    for (const auto& e : written) {
      const int r = e.row(), c = e.col();
      EXPECT_GE(P.find(r, c), 0) << at << ": entry (" << r << ", " << c << ") not in the pattern";
    }

    MatX Jd = MatX::Zero(n, n);
    JacobianSink dense = JacobianSink::dense(Jd.data(), n);
    dae.jacobian(t, y.data(), yp.data(), cj, dense);

    std::vector<double> values(static_cast<size_t>(P.nonZeros()), 0.0);
    JacobianSink sparse = JacobianSink::sparse(values.data(), P);
    ASSERT_NO_THROW(dae.jacobian(t, y.data(), yp.data(), cj, sparse)) << at;
    MatX Js = MatX::Zero(n, n);
    for (int c = 0; c < n; ++c) {
      for (int64_t k = P.colStart()[c]; k < P.colStart()[c + 1]; ++k) {
        Js(static_cast<int>(P.rowIndex()[k]), c) = values[static_cast<size_t>(k)];
      }
    }
    int mismatches = 0;
    for (int c = 0; c < n; ++c) {
      for (int r = 0; r < n; ++r) {
        if (Js(r, c) != Jd(r, c) && mismatches++ < 10) {
          ADD_FAILURE() << at << ": (" << r << ", " << c << ") sparse " << Js(r, c) << " dense "
                        << Jd(r, c);
        }
      }
    }
    EXPECT_EQ(mismatches, 0) << at;
  }
}

// dF/dy' x from the model's structure (the sensitivity residual's product) against the
// assembled J(1) - J(0): both exact, so they agree to the round-off of the difference,
// bounded per row by kRoundOff (|J(0)| + |J(1)|) |x| (a few operations per entry).
TEST_P(DaeJacobian, RateJacobianProductEqualsAssembledRateJacobian) {
  const System sys = makeEverythingSystem();
  const DaeSystem dae(sys, GetParam());
  if (GetParam() == Formulation::Index1) {
    EXPECT_FALSE(dae.providesRateJacobianProduct());  // G on the multiplier rows: not provided
    return;
  }
  ASSERT_TRUE(dae.providesRateJacobianProduct());
  constexpr double kRoundOff = 64.0 * std::numeric_limits<double>::epsilon();
  const int n = dae.layout().size;
  Random rnd(kSeed + 50 + static_cast<unsigned>(GetParam()));
  for (int s = 0; s < kSamples / 2; ++s) {
    VecX y, yp;
    randomDaeState(rnd, sys, dae, y, yp);
    const double t = rnd.uniform(0.0, 2.0);
    MatX J0 = MatX::Zero(n, n), J1 = MatX::Zero(n, n);
    JacobianSink s0 = JacobianSink::dense(J0.data(), n), s1 = JacobianSink::dense(J1.data(), n);
    dae.jacobian(t, y.data(), yp.data(), 0.0, s0);
    dae.jacobian(t, y.data(), yp.data(), 1.0, s1);
    const VecX x = rnd.vector(n, -1.0, 1.0);
    VecX r = VecX::Constant(n, 0.5);  // the product is added to r
    dae.addRateJacobianProduct(t, y.data(), yp.data(), x.data(), r.data(), *dae.makeScratch());
    const VecX expected = VecX::Constant(n, 0.5) + (J1 - J0) * x;
    const VecX bound = kRoundOff * ((J0.cwiseAbs() + J1.cwiseAbs()) * x.cwiseAbs() + VecX::Ones(n));
    for (int i = 0; i < n; ++i) {
      EXPECT_LE(std::abs(r[i] - expected[i]), bound[i])
          << toString(GetParam()) << ", sample " << s << ", row " << i << ": " << r[i] << " vs " << expected[i];
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Formulations, DaeJacobian,
                         ::testing::Values(Formulation::Ggl, Formulation::Index3, Formulation::Index1),
                         [](const ::testing::TestParamInfo<Formulation>& info) {
                           return toString(info.param);
                         });

TEST(JacobianPositions, ReplayedPositionsMatchSearchesAndSurviveAChangedOrder) {
  // A 4 x 4 pattern; the same entries written with positions recorded and replayed, then
  // in another order (and fewer), against the same writes searched entry by entry.
  const SparsePattern p(4, {{0, 0}, {1, 0}, {3, 0}, {2, 1}, {0, 2}, {2, 2}, {3, 2}, {1, 3}, {3, 3}});
  const auto writeA = [](JacobianSink& J) {
    J.add(0, 0, 1.0);
    const int rows[] = {0, 2, 3};
    const double vals[] = {2.0, 3.0, 4.0};
    J.addColumn(2, 0, rows, vals, 3, 0.5);
    J.addColumnSegment(3, 1, 1, [](int) { return 5.0; }, 2.0);
    J.add(3, 0, -1.0);
  };
  const auto writeB = [](JacobianSink& J) {  // another order, one entry fewer
    J.add(2, 1, 7.0);
    J.add(0, 0, 1.5);
    const int rows[] = {1, 3};
    const double vals[] = {6.0, 8.0};
    J.addColumn(0, 0, rows, vals, 2, 1.0);
  };
  JacobianPositions positions;
  for (const auto& write : {std::function<void(JacobianSink&)>(writeA), std::function<void(JacobianSink&)>(writeA),
                            std::function<void(JacobianSink&)>(writeB), std::function<void(JacobianSink&)>(writeA)}) {
    std::vector<double> searched(p.nonZeros(), 0.0), replayed(p.nonZeros(), 0.0);
    JacobianSink plain = JacobianSink::sparse(searched.data(), p);
    write(plain);
    JacobianSink positioned = JacobianSink::sparse(replayed.data(), p).withPositions(positions);
    write(positioned);
    EXPECT_EQ(searched, replayed);
  }
  // an entry outside the pattern is still refused
  std::vector<double> values(p.nonZeros(), 0.0);
  JacobianSink J = JacobianSink::sparse(values.data(), p).withPositions(positions);
  EXPECT_THROW(J.add(1, 1, 1.0), std::logic_error);
}

}  // namespace
}  // namespace flexmbd
