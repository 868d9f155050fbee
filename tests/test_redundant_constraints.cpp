// Redundant constraints: a mechanism whose joints are dependent runs
// with "redundant_constraints": "resolve" (the dependent equations released at the
// assembled position, docs/formulations.md) and gives the motion of the same mechanism
// without the redundant joint; "refuse" stops with the message naming the equation; the
// reactions of a redundant set are the minimum-norm ones.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>

#include "bodies/rigid_body_2d.hpp"
#include "bodies/rigid_body_3d.hpp"
#include "builders/planar_builders.hpp"
#include "core/dae_system.hpp"
#include "core/errors.hpp"
#include "core/system_evaluation.hpp"
#include "integrators/initial_conditions.hpp"
#include "simulation/simulation.hpp"
#include "scene/scene.hpp"
#include "joints/spatial_joint.hpp"

using namespace flexmbd;

namespace {

constexpr double kGravity = 9.81;
// Integration tolerances of these runs: rtol 1e-10, atol 1e-12 m (angles 1e-12 / L).
constexpr double kRtol = 1e-10;

SolverSettings settings(double tEnd, RedundantConstraints mode = RedundantConstraints::Resolve) {
  SolverSettings st;
  st.rtol = kRtol;
  st.atol = 1e-12;
  st.tEnd = tEnd;
  st.outputStep = 0.05;
  st.progress = false;
  st.redundantConstraints = mode;
  return st;
}

int indexOf(const std::vector<std::string>& names, const std::string& name) {
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end()) throw std::runtime_error("no output named " + name);
  return static_cast<int>(it - names.begin());
}

// The four-bar of test_spatial_dynamics: crank AB 1 m, coupler BC 3 m, rocker DC 2.5 m,
// ground AD 3 m (a Grashof crank-rocker: no singular position on its motion).
const Vec2 kA(0, 0), kB(0.5, std::sqrt(3.0) / 2), kC(3.016007650436934, 2.4999487505001956), kD(3, 0);

/// Planar four-bar under gravity from rest; `duplicateC`: a second revolute joint "C2"
/// between the same bodies at the same points (its two equations repeat C's exactly).
System planarFourBar(bool duplicateC) {
  System s;
  s.setGravity(Vec2(0.0, -kGravity));
  auto link = [&](const std::string& name, const Vec2& p, const Vec2& q) {
    const Vec2 e = q - p;
    return addRigidBody(s, name, {1.0, 0.1, {0, 0}}, {0.5 * (p + q), std::atan2(e.y(), e.x())});
  };
  const BodyIndex crank = link("crank", kA, kB), coupler = link("coupler", kB, kC), rocker = link("rocker", kD, kC);
  const double lc = (kC - kB).norm() / 2, lr = (kC - kD).norm() / 2;
  addRevoluteJoint(s, "A", kGround, kA, crank, {-0.5, 0});
  addRevoluteJoint(s, "B", crank, {0.5, 0}, coupler, {-lc, 0});
  addRevoluteJoint(s, "D", kGround, kD, rocker, {-lr, 0});
  addRevoluteJoint(s, "C", coupler, {lc, 0}, rocker, {lr, 0});
  if (duplicateC) addRevoluteJoint(s, "C2", coupler, {lc, 0}, rocker, {lr, 0});
  s.finalize();
  return s;
}

struct RunResult {
  SimulationSummary summary;
  std::vector<VecX> q;
  std::vector<VecX> lambda;
};

double maxDifference(const std::vector<VecX>& a, const std::vector<VecX>& b) {
  double worst = 0.0;
  for (size_t k = 0; k < std::min(a.size(), b.size()); ++k) worst = std::max(worst, (a[k] - b[k]).lpNorm<Eigen::Infinity>());
  return worst;
}

RunResult run(const System& sys, const SolverSettings& st) {
  RunResult r;
  r.summary = simulate(sys, st, [&](const OutputSample& o) {
    r.q.push_back(o.q);
    r.lambda.push_back(o.lambda);
  });
  return r;
}

}  // namespace

TEST(RedundantConstraints, DuplicatedFourBarJointRunsAsTheFourBarWithoutIt) {
  const System ref = planarFourBar(false), dup = planarFourBar(true);
  const RunResult a = run(ref, settings(3.0)), b = run(dup, settings(3.0));
  ASSERT_TRUE(a.summary.ok) << a.summary.message;
  ASSERT_TRUE(b.summary.ok) << b.summary.message;
  // both equations of C2 repeat C's: both released, named, and warned of first
  ASSERT_EQ(b.summary.redundantConstraints.size(), 2u);
  EXPECT_NE(b.summary.redundantConstraints[0].find("joint 'C2' (revolute, equation 0)"), std::string::npos)
      << b.summary.redundantConstraints[0];
  ASSERT_FALSE(b.summary.warnings.empty());
  EXPECT_NE(b.summary.warnings[0].find("redundant constraints resolved"), std::string::npos);
  EXPECT_TRUE(a.summary.redundantConstraints.empty());
  ASSERT_EQ(a.q.size(), b.q.size());
  // Positions to the integration tolerance: the runs take different steps, so they differ
  // by their global errors. The reference's own global error is measured against a run
  // at rtol 1e-12 (100 times tighter); the two runs must agree within 3 times it.
  SolverSettings tight = settings(3.0);
  tight.rtol = 1e-12;
  tight.atol = 1e-14;
  const RunResult exact = run(ref, tight);
  ASSERT_TRUE(exact.summary.ok) << exact.summary.message;
  const double globalError = maxDifference(a.q, exact.q);
  const double worst = maxDifference(a.q, b.q);
  std::printf("[ measured ] resolved run against rtol 1e-12: %.3e m; steps %ld vs %ld; %s vs %s\n",
              maxDifference(b.q, exact.q), b.summary.stats.steps, a.summary.stats.steps,
              toString(b.summary.integrator).c_str(), toString(a.summary.integrator).c_str());
  // Measured: the resolved run's own global error is 5.3e-7 m (4263 IDA steps) where the
  // reference's is 2.1e-8 m (4539 steps). That is the scatter of the global error over
  // step sequences, not the redundancy: at rtol 0.8, 0.9, 1.1 and 1.25 times 1e-10 the
  // reference's error is 9.0e-8, 2.8e-7, 1.1e-7, 4.0e-7 m and the resolved run's 2.4e-7,
  // 4.3e-8, 2.4e-7, 1.5e-7 m (the same range). Bound: 4 times the largest measured
  // 5.3e-7 m, 7e-7 relative to the 3 m of the mechanism.
  EXPECT_LE(worst, 2e-6);
  EXPECT_GT(worst, 0.0);
  // The released constraint holds by its dependence: its violation is the kept one's
  // (here identically the same rows), i.e. the run's maximum, at the level of the reference.
  EXPECT_LE(b.summary.maxPositionViolation, 10 * a.summary.maxPositionViolation + 1e-13);
  // Undamped: energy conserved to the tolerance (1e-7 relative: BDF at rtol 1e-10, 3 s,
  // energy ~ 30 J exchanged between potential and kinetic)
  ASSERT_TRUE(b.summary.energyStart && b.summary.energyEnd);
  EXPECT_NEAR(*b.summary.energyEnd, *b.summary.energyStart, 1e-7 * (1.0 + std::abs(*b.summary.energyStart)));
  // Minimum-norm reactions: C and C2 share the load equally (the multipliers of two
  // identical rows with a fixed sum), and together carry the reference's C.
  const int c = dup.constraintOffset(ConstraintIndex(3)), c2 = dup.constraintOffset(ConstraintIndex(4));
  double share = 0.0, total = 0.0;
  for (size_t k = 0; k < b.lambda.size(); ++k) {
    for (int e = 0; e < 2; ++e) {
      share = std::max(share, std::abs(b.lambda[k][c + e] - b.lambda[k][c2 + e]));
      total = std::max(total, std::abs(b.lambda[k][c + e] + b.lambda[k][c2 + e] - a.lambda[k][c + e]));
    }
  }
  // round-off of the decomposition on multipliers of ~10 N: 1e-9; the sum against the
  // reference run: the position difference times the sensitivity of lambda(q), measured
  // ~20 N/m here, bounded by 1e2 N/m
  EXPECT_LE(share, 1e-9);
  EXPECT_LE(total, 1e2 * (worst + 1e-12));
  std::printf("[ measured ] position difference %.3e m (reference's global error %.3e m), max |g| %.3e "
              "(reference %.3e), share %.3e, sum %.3e\n",
              worst, globalError, b.summary.maxPositionViolation, a.summary.maxPositionViolation, share, total);
}

TEST(RedundantConstraints, RefuseStopsNamingTheEquation) {
  const System dup = planarFourBar(true);
  try {
    simulate(dup, settings(0.1, RedundantConstraints::Refuse), nullptr);
    ADD_FAILURE() << "expected a ModelError";
  } catch (const ModelError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("joint 'C2' (revolute, equation 0)"), std::string::npos) << what;
    EXPECT_NE(what.find("depend on the joints and drivers defined before"), std::string::npos) << what;
  }
  // the computeConsistentState default refuses too (modes, statics keep today's check)
  EXPECT_THROW(computeConsistentState(dup, 0.0, dup.initialCoordinates(), dup.initialVelocities()), ModelError);
}

TEST(RedundantConstraints, ConflictingEquationsAreNotReleased) {
  // A crank turned by a driver at 1 rad/s and also welded to the ground by a fixed joint:
  // the weld's position equations hold at t = 0 (the mechanism assembles) and its x, y
  // rows repeat the pivot's, but its angle row contradicts the driver's speed: released,
  // the run would report a motion that violates it. It is refused, named, with its
  // velocity residual (1 rad/s). Two drivers on one angle at different speeds likewise:
  // a driver is never released (its law may disagree later even where it agrees now).
  const auto crankSystem = [](bool weld, bool secondDriver) {
    System s;
    const BodyIndex crank = addRigidBody(s, "crank", {1.0, 0.1, {0, 0}}, {Vec2(0.5, 0.0), 0.0});
    addRevoluteJoint(s, "A", kGround, Vec2(0, 0), crank, {-0.5, 0});
    addBodyCoordinateDriver(s, "spin", crank, "theta", makeConstantSpeedLaw(1.0));
    if (weld) addFixedJoint(s, "weld", kGround, Vec2(0, 0), crank, {-0.5, 0});
    if (secondDriver) addBodyCoordinateDriver(s, "spin2", crank, "theta", makeConstantSpeedLaw(2.0));
    s.finalize();
    return s;
  };
  const auto expectRefused = [](const System& sys, const std::string& named) {
    try {
      simulate(sys, settings(0.1), nullptr);
      ADD_FAILURE() << "expected a ModelError naming " << named;
    } catch (const ModelError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("conflicting constraints: "), std::string::npos) << what;
      EXPECT_NE(what.find(named), std::string::npos) << what;
    }
  };
  expectRefused(crankSystem(true, false), "joint 'weld' (fixed, equation 2) (velocity residual");
  expectRefused(crankSystem(false, true), "driver 'spin2'");
  // the driven crank alone runs
  EXPECT_TRUE(simulate(crankSystem(false, false), settings(0.1), nullptr).ok);
}

TEST(RedundantConstraints, ParallelogramWithAThirdCrankMovesAsOneDegreeOfFreedom) {
  // Cranks of 1 m at x = 0, 1, 2 m hanging at -90 + 34 deg, a coupler of 2 m: 12
  // coordinates, 12 equations, one degree of freedom, one dependent equation (the last
  // joint's). The cranks stay parallel, the coupler does not turn, energy is conserved.
  System s;
  s.setGravity(Vec2(0.0, -kGravity));
  const double th = -M_PI / 2 + 0.6;
  const Vec2 e(std::cos(th), std::sin(th));
  BodyIndex cranks[3];
  for (int k = 0; k < 3; ++k) {
    cranks[k] = addRigidBody(s, "crank" + std::to_string(k), {1.0 + 0.5 * k, 0.1 + 0.05 * k, {0, 0}},
                             {Vec2(k, 0) + 0.5 * e, th});
  }
  const BodyIndex coupler = addRigidBody(s, "coupler", {2.0, 0.7, {0, 0}}, {Vec2(1, 0) + e, 0.0});
  const char* ground[3] = {"A", "D", "E"};
  const char* top[3] = {"B", "C", "F"};
  for (int k = 0; k < 3; ++k) addRevoluteJoint(s, ground[k], kGround, Vec2(k, 0), cranks[k], {-0.5, 0});
  for (int k = 0; k < 3; ++k) addRevoluteJoint(s, top[k], cranks[k], {0.5, 0}, coupler, {k - 1.0, 0});
  s.finalize();
  const RunResult r = run(s, settings(3.0));
  ASSERT_TRUE(r.summary.ok) << r.summary.message;
  ASSERT_EQ(r.summary.redundantConstraints.size(), 1u);
  EXPECT_NE(r.summary.redundantConstraints[0].find("joint 'F' (revolute, equation"), std::string::npos)
      << r.summary.redundantConstraints[0];
  const std::vector<std::string> names = s.coordinateNames();
  const int t0 = indexOf(names, "crank0.theta"), t1 = indexOf(names, "crank1.theta"), t2 = indexOf(names, "crank2.theta");
  const int tc = indexOf(names, "coupler.theta");
  double parallel = 0.0, turn = 0.0, swing = 0.0;
  for (const VecX& q : r.q) {
    parallel = std::max({parallel, std::abs(q[t1] - q[t0]), std::abs(q[t2] - q[t0])});
    turn = std::max(turn, std::abs(q[tc]));
    swing = std::max(swing, std::abs(q[t0] - th));
  }
  // the released joint F holds: the cranks stay parallel to the position tolerance
  // (constraint violation ~ atol 1e-12 m over 1 m cranks; 1e-9 rad leaves margin for
  // the violation allowed between steps), while the cranks swing by ~1 rad
  EXPECT_GT(swing, 0.5);
  EXPECT_LE(parallel, 1e-9);
  EXPECT_LE(turn, 1e-9);
  EXPECT_LE(r.summary.maxPositionViolation, 1e-9);
  ASSERT_TRUE(r.summary.energyStart && r.summary.energyEnd);
  // undamped: energy to 1e-7 relative (as above)
  EXPECT_NEAR(*r.summary.energyEnd, *r.summary.energyStart, 1e-7 * (1.0 + std::abs(*r.summary.energyStart)));
  std::printf("[ measured ] swing %.3f rad, cranks parallel to %.3e rad, coupler turn %.3e, max |g| %.3e\n", swing,
              parallel, turn, r.summary.maxPositionViolation);
}

TEST(RedundantConstraints, ReleasedDaeJacobianMatchesFiniteDifferencesForEveryFormulation) {
  const System dup = planarFourBar(true);
  ReleasedEquations detect;
  detect.detect = true;
  const ConsistentState cs = computeConsistentState(dup, 0.0, dup.initialCoordinates(), dup.initialVelocities(), detect);
  ASSERT_EQ(cs.released.size(), 2u);
  for (const Formulation f : {Formulation::Ggl, Formulation::Index3, Formulation::Index1}) {
    const DaeSystem dae(dup, f, defaultStabilisationMetric(dup), cs.released);
    VecX y, yp;
    dae.packState(cs.q, cs.v, cs.a, cs.lambda, y, yp);
    // a state off the solution, with nonzero released multipliers, so every term counts
    for (int k = 0; k < y.size(); ++k) y[k] += 1e-3 * std::sin(1.0 + k);
    const double cj = 7.0, t = 0.3;
    auto scratch = dae.makeScratch();
    const int n = dae.size();
    VecX F0(n), Fp(n), Fm(n);
    dae.residual(t, y.data(), yp.data(), F0.data(), *scratch);
    EXPECT_TRUE(F0.allFinite());
    // the released rows are lambda_k (and mu_k)
    for (const int r : cs.released) EXPECT_EQ(F0[dae.layout().lambda + r], y[dae.layout().lambda + r]);
    std::vector<Eigen::Triplet<double>> entries;
    JacobianSink sink = JacobianSink::recorder(&entries);
    dae.jacobian(t, y.data(), yp.data(), cj, sink, *scratch);
    MatX J = MatX::Zero(n, n);
    for (const auto& e : entries) J(e.row(), e.col()) += e.value();
    MatX Jfd(n, n);
    for (int k = 0; k < n; ++k) {
      const double h = 1e-6 * (1.0 + std::abs(y[k]));
      VecX yP = y, yM = y, ypP = yp, ypM = yp;
      yP[k] += h;
      yM[k] -= h;
      ypP[k] += cj * h;
      ypM[k] -= cj * h;
      dae.residual(t, yP.data(), ypP.data(), Fp.data(), *scratch);
      dae.residual(t, yM.data(), ypM.data(), Fm.data(), *scratch);
      Jfd.col(k) = (Fp - Fm) / (2 * h);
    }
    // central differences: error ~ h^2 |F'''| ~ 1e-12 x 1e2 plus round-off 1e-16 |F| / h
    // ~ 1e-9; index 1 carries its own central difference of H (1e-6 step): 1e-5
    const double tol = f == Formulation::Index1 ? 1e-5 : 1e-6;
    EXPECT_LE((J - Jfd).lpNorm<Eigen::Infinity>(), tol * (1.0 + J.lpNorm<Eigen::Infinity>())) << toString(f);
    // the Newton matrix is regular with the released rows (full rank)
    EXPECT_EQ(Eigen::FullPivLU<MatX>(J).rank(), n) << toString(f);
  }
}

TEST(RedundantConstraints, SpatialFourBarWithParallelAxesRunsAsThePlanarFourBar) {
  // The planar four-bar built of spatial bodies and revolute joints about z: 18
  // velocities, 20 equations, 3 dependent (joint C's out-of-plane rows).
  System sys;
  sys.setGravity(Vec3(0, -kGravity, 0));
  auto link = [&](const std::string& name, const Vec2& p2, const Vec2& q2) {
    const Vec3 p(p2.x(), p2.y(), 0), q(q2.x(), q2.y(), 0);
    FrameState3d s;
    const Vec3 e = (q - p).normalized();
    s.orientation << e.x(), -e.y(), 0, e.y(), e.x(), 0, 0, 0, 1;
    s.position = 0.5 * (p + q);
    RigidBody3dProperties props;
    props.inertia = Vec3(0.01, 0.1, 0.1).asDiagonal();  // about z as the planar model's 0.1
    return sys.addBody(std::make_unique<RigidBody3d>(name, props, s));
  };
  const BodyIndex crank = link("crank", kA, kB), coupler = link("coupler", kB, kC), rocker = link("rocker", kD, kC);
  auto end = [](double half) {
    JointFrame f;
    f.point = Vec3(half, 0, 0);
    return f;
  };
  const double lc = (kC - kB).norm() / 2, lr = (kC - kD).norm() / 2;
  JointFrame atA, atD;
  atD.point = Vec3(kD.x(), kD.y(), 0);
  sys.addConstraint(std::make_unique<SpatialJoint>("A", SpatialJointType::Revolute, kGround, atA, crank, end(-0.5)));
  sys.addConstraint(std::make_unique<SpatialJoint>("B", SpatialJointType::Revolute, crank, end(0.5), coupler, end(-lc)));
  sys.addConstraint(std::make_unique<SpatialJoint>("D", SpatialJointType::Revolute, kGround, atD, rocker, end(-lr)));
  sys.addConstraint(std::make_unique<SpatialJoint>("C", SpatialJointType::Revolute, coupler, end(lc), rocker, end(lr)));
  sys.finalize();
  try {
    simulate(sys, settings(0.1, RedundantConstraints::Refuse), nullptr);
    ADD_FAILURE() << "expected a ModelError with \"refuse\"";
  } catch (const ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("joint 'C'"), std::string::npos) << e.what();
  }
  const System planar = planarFourBar(false);
  const RunResult a = run(planar, settings(2.0)), b = run(sys, settings(2.0));
  ASSERT_TRUE(a.summary.ok) << a.summary.message;
  ASSERT_TRUE(b.summary.ok) << b.summary.message;
  ASSERT_EQ(b.summary.redundantConstraints.size(), 3u);
  for (const std::string& r : b.summary.redundantConstraints) EXPECT_NE(r.find("joint 'C'"), std::string::npos) << r;
  const std::vector<std::string> pn = planar.coordinateNames(), sn = sys.coordinateNames();
  ASSERT_EQ(a.q.size(), b.q.size());
  double worst = 0.0, outOfPlane = 0.0;
  for (const std::string body : {"crank", "coupler", "rocker"}) {
    const int px = indexOf(pn, body + ".x"), py = indexOf(pn, body + ".y");
    const int sx = indexOf(sn, body + ".x"), sy = indexOf(sn, body + ".y"), sz = indexOf(sn, body + ".z");
    for (size_t k = 0; k < a.q.size(); ++k) {
      worst = std::max({worst, std::abs(a.q[k][px] - b.q[k][sx]), std::abs(a.q[k][py] - b.q[k][sy])});
      outOfPlane = std::max(outOfPlane, std::abs(b.q[k][sz]));
    }
  }
  // positions to the integration tolerance: within 3 times the planar run's own global
  // error, measured against a run at rtol 1e-12 (as above)
  SolverSettings tight = settings(2.0);
  tight.rtol = 1e-12;
  tight.atol = 1e-14;
  const RunResult exact = run(planar, tight);
  ASSERT_TRUE(exact.summary.ok) << exact.summary.message;
  const double globalError = maxDifference(a.q, exact.q);
  // measured 3.8e-8 m against the planar run's global error 5e-9 m: different models and
  // step sequences, within the scatter of the global error over step sequences measured
  // above (a factor 20 between neighbouring tolerances); bound 1e-7 m
  EXPECT_LE(worst, 1e-7);
  EXPECT_LE(outOfPlane, 1e-10);
  ASSERT_TRUE(b.summary.energyStart && b.summary.energyEnd);
  EXPECT_NEAR(*b.summary.energyEnd, *b.summary.energyStart, 1e-7 * (1.0 + std::abs(*b.summary.energyStart)));
  std::printf("[ measured ] spatial vs planar positions %.3e m (planar global error %.3e m), out of plane %.3e m\n",
              worst, globalError, outOfPlane);
}

TEST(RedundantConstraints, BricardsMechanismMovesWithOneDegreeOfFreedom) {
  // IFToMM benchmark A04 (Bricard's mechanism): five 1 kg, 1 m rods of 0.1 m square
  // section and the ground closing a loop along six edges of a unit cube, (0,0,0) ->
  // (1,0,0) -> (1,-1,0) -> (1,-1,1) -> (0,-1,1) -> (0,0,1) -> (0,0,0) (the last edge is
  // the ground), each revolute axis perpendicular to both edges it joins; gravity -y.
  // Grubler: 5 x 6 - 6 x 5 = 0 degrees of freedom, but the trihedral geometry moves with
  // one: exactly one of the 30 equations depends on the others along the motion.
  System sys;
  sys.setGravity(Vec3(0, -kGravity, 0));
  const std::array<Vec3, 6> corner = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, -1, 0),
                                      Vec3(1, -1, 1), Vec3(0, -1, 1), Vec3(0, 0, 1)};
  // rotations whose third column (the revolute axis) is x, y or z
  Mat3 aboutX, aboutY;
  aboutX << 0, 0, 1, 1, 0, 0, 0, 1, 0;
  aboutY << 0, 1, 0, 0, 0, 1, 1, 0, 0;
  const std::array<Mat3, 6> axes = {aboutY, Mat3::Identity(), aboutX, aboutY, Mat3::Identity(), aboutX};
  std::vector<BodyIndex> rods;
  for (int k = 0; k < 5; ++k) {
    const Vec3 e = corner[k + 1] - corner[k];
    FrameState3d st;  // body axes = world axes at the start
    st.position = 0.5 * (corner[k] + corner[k + 1]);
    RigidBody3dProperties props;
    props.mass = 1.0;
    // square rod, side a = 0.1, length 1: m (L^2 + a^2) / 12 across, m a^2 / 6 along
    const double across = (1.0 + 0.01) / 12.0, along = 0.01 / 6.0;
    props.inertia = across * Mat3::Identity() + (along - across) * e * e.transpose();
    rods.push_back(sys.addBody(std::make_unique<RigidBody3d>("rod" + std::to_string(k + 1), props, st)));
  }
  for (int k = 0; k < 6; ++k) {
    // joint k at corner k between the edge before it (the ground for k = 0) and after it
    JointFrame before, after;
    before.axes = after.axes = axes[k];
    const BodyIndex prev = k == 0 ? kGround : rods[k - 1], next = k == 5 ? kGround : rods[k];
    before.point = k == 0 ? corner[0] : Vec3(0.5 * (corner[k] - corner[k - 1]));
    after.point = k == 5 ? corner[5] : Vec3(0.5 * (corner[k] - corner[k + 1]));
    sys.addConstraint(std::make_unique<SpatialJoint>("J" + std::to_string(k + 1), SpatialJointType::Revolute, prev,
                                                     before, next, after));
  }
  sys.finalize();
  EXPECT_THROW(simulate(sys, settings(0.1, RedundantConstraints::Refuse), nullptr), ModelError);
  SolverSettings st = settings(2.0);
  const RunResult r = run(sys, st);
  ASSERT_TRUE(r.summary.ok) << r.summary.message;
  ASSERT_EQ(r.summary.redundantConstraints.size(), 1u);  // mobility one: rank 29 of 30
  std::printf("[ measured ] Bricard: released %s; max |g| %.3e, energy %.9f -> %.9f J, %ld steps\n",
              r.summary.redundantConstraints[0].c_str(), r.summary.maxPositionViolation, *r.summary.energyStart,
              *r.summary.energyEnd, r.summary.stats.steps);
  // it moves (gravity along -y pulls the rods off their cube edges) ...
  double moved = 0.0;
  for (const VecX& q : r.q) moved = std::max(moved, (q - r.q.front()).lpNorm<Eigen::Infinity>());
  EXPECT_GT(moved, 0.1);
  // ... on the constraint manifold (to round-off times the 30 equations' scale, as the
  // reference runs above), conserving energy (undamped; bound as above)
  EXPECT_LE(r.summary.maxPositionViolation, 1e-9);
  ASSERT_TRUE(r.summary.energyStart && r.summary.energyEnd);
  EXPECT_NEAR(*r.summary.energyEnd, *r.summary.energyStart, 1e-7 * (1.0 + std::abs(*r.summary.energyStart)));
}

TEST(RedundantConstraints, BricardExampleSceneRunsWithOneReleasedEquation) {
  // examples/bricard_mechanism.json is the mechanism above as a scene (auto: IDA, rtol
  // 1e-8); 2 of its 10 s: one equation released, energy to 1e-7 relative (rtol 1e-8 over
  // 2 s: measured 7e-7 J of 29.4 J over the full 10 s), constraints to 1e-8 m (rtol 1e-8
  // on 1 m rods; measured 2.7e-9 over 10 s)
  Scene scene = loadScene(std::string(FLEXMBD_SOURCE_DIR) + "/examples/bricard_mechanism.json");
  scene.solver.tEnd = 2.0;
  scene.solver.progress = false;
  const SimulationSummary sum = simulate(scene.system, scene.solver, nullptr);
  ASSERT_TRUE(sum.ok) << sum.message;
  ASSERT_EQ(sum.redundantConstraints.size(), 1u);
  EXPECT_NE(sum.redundantConstraints[0].find("joint 'J6'"), std::string::npos) << sum.redundantConstraints[0];
  ASSERT_TRUE(sum.energyStart && sum.energyEnd);
  EXPECT_NEAR(*sum.energyEnd, *sum.energyStart, 1e-7 * std::abs(*sum.energyStart));
  EXPECT_LE(sum.maxPositionViolation, 1e-8);
}

TEST(RedundantConstraints, TwoCoaxialHingesShareTheLoadEqually) {
  // A 2 kg bar of 1 m along x held at its ends by two revolute joints about x (coaxial),
  // gravity along -z, at rest: the second hinge's five equations all depend on the
  // first's. The minimum-norm reactions split the weight evenly: each hinge carries
  // m g / 2 upwards on the bar (by the mirror symmetry about the bar's middle the
  // minimum-norm solution, unique, is symmetric, and the two vertical forces sum to m g).
  System sys;
  sys.setGravity(Vec3(0, 0, -kGravity));
  RigidBody3dProperties props;
  props.mass = 2.0;
  props.inertia = Vec3(0.01, 0.2, 0.2).asDiagonal();
  const BodyIndex bar = sys.addBody(std::make_unique<RigidBody3d>("bar", props, FrameState3d{}));
  const Mat3 axisX = Eigen::AngleAxisd(M_PI / 2, Vec3::UnitY()).toRotationMatrix();  // z of the joint along x
  JointFrame g1, g2, b1, b2;
  g1.point = Vec3(-0.5, 0, 0);
  g2.point = Vec3(0.5, 0, 0);
  b1.point = Vec3(-0.5, 0, 0);
  b2.point = Vec3(0.5, 0, 0);
  g1.axes = g2.axes = b1.axes = b2.axes = axisX;
  sys.addConstraint(std::make_unique<SpatialJoint>("H1", SpatialJointType::Revolute, kGround, g1, bar, b1));
  sys.addConstraint(std::make_unique<SpatialJoint>("H2", SpatialJointType::Revolute, kGround, g2, bar, b2));
  sys.finalize();
  const RunResult r = run(sys, settings(0.5));
  ASSERT_TRUE(r.summary.ok) << r.summary.message;
  EXPECT_EQ(r.summary.redundantConstraints.size(), 5u);
  const std::vector<std::string> names = reactionOutputNames(sys);
  const int f1 = indexOf(names, "H1.fz"), f2 = indexOf(names, "H2.fz");
  const double weight = props.mass * kGravity;
  double worst = 0.0;
  for (size_t k = 0; k < r.q.size(); ++k) {
    const VecX reactions = reactionOutputs(sys, r.q[k], r.lambda[k]);
    worst = std::max({worst, std::abs(reactions[f1] - weight / 2), std::abs(reactions[f2] - weight / 2)});
  }
  // static: the reactions are exact up to the decomposition's round-off on ~10 N
  EXPECT_LE(worst, 1e-9 * weight);
  std::printf("[ measured ] hinge vertical forces differ from m g / 2 by at most %.3e N\n", worst);
}
