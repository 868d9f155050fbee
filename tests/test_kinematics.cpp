// Validation of the kinematic analysis (source document 000, Yamada & Tatsumi 1981):
// the slider-crank against eqs. 30-32, the four-bar against an independent loop-closure
// solution (tests/four_bar_reference.hpp), both against the same mechanisms run as
// driven dynamic systems through IDA, transfer functions against differences of
// positions, and singular positions (Grashof lock, change point) located and reported.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "bodies/rigid_body_2d.hpp"
#include "builders/planar_builders.hpp"
#include "core/errors.hpp"
#include "simulation/simulation.hpp"
#include "linkage/kinematic_analysis.hpp"
#include "linkage/kinematics_scene.hpp"
#include "tests/four_bar_reference.hpp"
#include "problems/reference_solutions.hpp"

using namespace flexmbd;

namespace {

const std::string kDir = std::string(FLEXMBD_SOURCE_DIR) + "/examples/";

// The corrector stops at max |eps| <= 1e-13 (the document's tolerance); positions are
// then exact to a few ulps of the link lengths, and the transfer functions are solved
// from an O(1)-conditioned D L1: relative errors at round-off level. 1e-12 leaves a
// factor ~50 over the measured 2e-14.
constexpr double kRoundOffRelative = 1e-12;
// IDA at rtol 1e-10, atol 1e-12 over one revolution: global errors of a few 1e-9
// relative (README: 1.4e-8 at rtol 1e-8); 1e-7 relative to the amplitudes.
constexpr double kDynamicRelative = 1e-7;

std::vector<KinematicState> runAll(const Linkage2d& linkage, const KinematicSettings& settings,
                                   KinematicSummary* summary = nullptr) {
  std::vector<KinematicState> states;
  const KinematicSummary s = analyzeKinematics(linkage, settings, [&](const KinematicState& st) { states.push_back(st); });
  if (summary) *summary = s;
  return states;
}

struct NodeMotion {
  Vec2 r, rp, rpp, v, a;
};
NodeMotion motion(const Linkage2d& l, const std::string& node, const KinematicState& s) {
  const NodeIndex n = l.findNode(node);
  return {l.nodePosition(n, s.x), l.nodeDerivative(n, s.xp), l.nodeDerivative(n, s.xpp), l.nodeDerivative(n, s.v),
          l.nodeDerivative(n, s.a)};
}

}  // namespace

// ----- slider-crank: eqs. 30-32 ------------------------------------------------------

TEST(KinematicsSliderCrank, MatchesEq30To32AtEveryStep) {
  const KinematicsScene scene = loadKinematicsScene(kDir + "kinematics_slider_crank.json");
  ASSERT_EQ(scene.settings.steps, 60);
  ASSERT_EQ(scene.settings.tolerance, 1e-13);
  KinematicSummary summary;
  const auto states = runAll(scene.linkage, scene.settings, &summary);
  ASSERT_TRUE(summary.ok) << summary.message;
  ASSERT_EQ(states.size(), 61u);
  const double l1 = 1, l2 = 2, vScale = l1 * (1 + l1 / l2), aScale = l1 * (1 + l1 / l2);
  double ex = 0, ev = 0, ea = 0;
  for (const auto& s : states) {
    const auto ref = reference::sliderCrank(l1, l2, s.alpha);  // alphadot = 1, alphaddot = 0
    const NodeMotion m = motion(scene.linkage, "O3", s);
    ex = std::max(ex, std::abs(m.r.x() - ref.x) / std::abs(ref.x));
    ev = std::max(ev, std::abs(m.v.x() - ref.xd) / vScale);
    ea = std::max(ea, std::abs(m.a.x() - ref.xdd) / aScale);
    EXPECT_EQ(m.r.y(), 0.0);  // on its line by construction
    EXPECT_LE(s.residual, 1e-13);
    if (s.step > 0) {
      EXPECT_GE(s.iterations, 1);
      EXPECT_LE(s.iterations, 3) << "Newton from a third-order predictor: 2 corrections at 60 steps";
    }
  }
  EXPECT_LT(ex, kRoundOffRelative);
  EXPECT_LT(ev, kRoundOffRelative);
  EXPECT_LT(ea, kRoundOffRelative);
  RecordProperty("max_rel_error_x", std::to_string(ex));
  RecordProperty("max_rel_error_v", std::to_string(ev));
  RecordProperty("max_rel_error_a", std::to_string(ea));
  RecordProperty("iterations", std::to_string(summary.minIterations) + "-" + std::to_string(summary.maxIterations));
  std::printf("slider-crank: max rel. error x %.2e, v %.2e, a %.2e; iterations %d-%d, max residual %.2e\n", ex, ev, ea,
              summary.minIterations, summary.maxIterations, summary.maxResidual);
}

/// The document's corrector (D L1 frozen at the reference position, Fig. 3) converges
/// linearly but to the same positions.
TEST(KinematicsSliderCrank, ModifiedNewtonGivesTheSameMotionWithMoreIterations) {
  KinematicsScene scene = loadKinematicsScene(kDir + "kinematics_slider_crank.json");
  const auto newton = runAll(scene.linkage, scene.settings);
  scene.settings.corrector = CorrectorKind::ModifiedNewton;
  KinematicSummary summary;
  const auto modified = runAll(scene.linkage, scene.settings, &summary);
  ASSERT_TRUE(summary.ok) << summary.message;
  ASSERT_EQ(newton.size(), modified.size());
  for (std::size_t k = 0; k < newton.size(); ++k) {
    EXPECT_LT((newton[k].x - modified[k].x).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT((newton[k].a - modified[k].a).cwiseAbs().maxCoeff(), 1e-11);
  }
  EXPECT_GT(summary.minIterations, 3);
  std::printf("modified Newton: iterations %d-%d per step\n", summary.minIterations, summary.maxIterations);
}

/// alphadot and alphaddot enter through eqs. 24-25 only.
TEST(KinematicsSliderCrank, SpeedAndAccelerationOfTheInput) {
  KinematicsScene scene = loadKinematicsScene(kDir + "kinematics_slider_crank.json");
  scene.settings.speed = 2.5;
  scene.settings.acceleration = -0.75;
  scene.settings.steps = 24;
  for (const auto& s : runAll(scene.linkage, scene.settings)) {
    const auto unit = reference::sliderCrank(1, 2, s.alpha);
    const NodeMotion m = motion(scene.linkage, "O3", s);
    EXPECT_NEAR(m.v.x(), unit.xd * 2.5, 1e-12);
    EXPECT_NEAR(m.a.x(), unit.xdd * 2.5 * 2.5 + unit.xd * -0.75, 1e-12);
  }
}

// ----- four-bar: loop closure ----------------------------------------------------------

TEST(KinematicsFourBar, O3MatchesTheLoopClosureSolution) {
  const KinematicsScene scene = loadKinematicsScene(kDir + "kinematics_four_bar.json");
  KinematicSummary summary;
  const auto states = runAll(scene.linkage, scene.settings, &summary);
  ASSERT_TRUE(summary.ok) << summary.message;
  ASSERT_EQ(states.size(), 61u);
  double ex = 0, ev = 0, ea = 0;
  double vMax = 0, aMax = 0;
  std::vector<reference::FourBarState> refs;
  for (const auto& s : states) refs.push_back(reference::fourBar(30, 60, 80, 100, s.alpha));
  for (const auto& r : refs) {
    vMax = std::max(vMax, std::hypot(r.vx, r.vy));
    aMax = std::max(aMax, std::hypot(r.ax, r.ay));
  }
  for (std::size_t k = 0; k < states.size(); ++k) {
    const NodeMotion m = motion(scene.linkage, "O3", states[k]);
    const auto& r = refs[k];
    ex = std::max(ex, (m.r - Vec2(r.x, r.y)).norm() / 80.0);
    ev = std::max(ev, (m.v - Vec2(r.vx, r.vy)).norm() / vMax);
    ea = std::max(ea, (m.a - Vec2(r.ax, r.ay)).norm() / aMax);
    EXPECT_LE(states[k].residual, 1e-13);
  }
  EXPECT_LT(ex, kRoundOffRelative);
  EXPECT_LT(ev, kRoundOffRelative);
  EXPECT_LT(ea, kRoundOffRelative);
  std::printf("four-bar O3: rel. error x %.2e, v %.2e, a %.2e; iterations %d-%d, max residual %.2e\n", ex, ev, ea,
              summary.minIterations, summary.maxIterations, summary.maxResidual);
}

/// The assembly at the start moves O3 from the rough [45, 58] of the scene onto the
/// circles; the link angles follow the chords.
TEST(KinematicsFourBar, AssemblesFromARoughStartingPosition) {
  const KinematicsScene scene = loadKinematicsScene(kDir + "kinematics_four_bar.json");
  const KinematicAnalysis analysis(scene.linkage, scene.settings);
  EXPECT_GT(analysis.assemblyIterations(), 0);
  const Vec2 o3 = scene.linkage.nodePosition(scene.linkage.findNode("O3"), analysis.startCoordinates());
  EXPECT_NEAR(o3.x(), 45.0, 1e-12);
  EXPECT_NEAR(o3.y(), std::sqrt(3375.0), 1e-12);
}

// ----- transfer functions against differences of positions -------------------------

TEST(KinematicsTransferFunctions, MatchDifferencesOfConvergedPositions) {
  for (const char* file : {"kinematics_slider_crank.json", "kinematics_four_bar.json"}) {
    const KinematicsScene scene = loadKinematicsScene(kDir + file);
    const KinematicAnalysis analysis(scene.linkage, scene.settings);
    const auto states = runAll(scene.linkage, scene.settings);
    // h = 1e-4: truncation h^2 X'''/6 ~ 1e-9 (X''' ~ 100 for the four-bar in cm), round-off
    // of positions converged to 1e-13: 1e-13/h = 1e-9 for X', 1e-13/h^2 = 1e-5 for X''.
    const double h = 1e-4;
    for (std::size_t k = 0; k < states.size(); k += 7) {
      const auto& s = states[k];
      const VecX xp = analysis.solve(s.alpha + h, s.x).x, xm = analysis.solve(s.alpha - h, s.x).x;
      const double scale1 = std::max(1.0, s.xp.cwiseAbs().maxCoeff()), scale2 = std::max(1.0, s.xpp.cwiseAbs().maxCoeff());
      EXPECT_LT(((xp - xm) / (2 * h) - s.xp).cwiseAbs().maxCoeff() / scale1, 1e-7) << file << " step " << s.step;
      EXPECT_LT(((xp - 2 * s.x + xm) / (h * h) - s.xpp).cwiseAbs().maxCoeff() / scale2, 1e-4) << file << " step " << s.step;
    }
  }
}

// ----- one motion, two methods: the same mechanisms through IDA ------------------------

namespace {

SolverSettings tightSettings() {
  SolverSettings st;
  st.rtol = 1e-10;
  st.atol = 1e-12;
  st.tEnd = 2 * M_PI;
  st.outputStep = 2 * M_PI / 60;
  st.progress = false;
  return st;
}

}  // namespace

TEST(KinematicsAgainstDynamics, SliderCrankDrivenThroughIda) {
  System sys;
  const BodyIndex crank = addRigidBody(sys, "crank", {1.0, 0.1, {0.5, 0}}, {{0, 0}, 0});
  const BodyIndex rod = addRigidBody(sys, "rod", {1.0, 0.4, {1.0, 0}}, {{1, 0}, 0});
  const BodyIndex slider = addRigidBody(sys, "slider", {0.5, 0.01, {0, 0}}, {{3, 0}, 0});
  addRevoluteJoint(sys, "O1", kGround, {0, 0}, crank, {0, 0});
  addRevoluteJoint(sys, "O2", crank, {1, 0}, rod, {0, 0});
  addRevoluteJoint(sys, "O3", rod, {2, 0}, slider, {0, 0});
  addPrismaticJoint(sys, "P", kGround, {0, 0}, slider, {0, 0}, {1, 0});
  addBodyCoordinateDriver(sys, "motor", crank, "theta", makeConstantSpeedLaw(1.0));
  sys.finalize();
  const int ix = sys.coordinateOffset(slider), ir = sys.coordinateOffset(rod);

  const KinematicsScene scene = loadKinematicsScene(kDir + "kinematics_slider_crank.json");
  const auto states = runAll(scene.linkage, scene.settings);
  const int rodAngle = scene.linkage.link(scene.linkage.findLink("rod")).offset;
  std::size_t k = 0;
  double ex = 0, ev = 0, ea = 0, eRod = 0;
  const SimulationSummary s = simulate(sys, tightSettings(), [&](const OutputSample& o) {
    ASSERT_LT(k, states.size());
    const KinematicState& st = states[k++];
    ASSERT_NEAR(o.t, st.alpha, 1e-12);  // alphadot = 1: t = alpha
    const NodeMotion m = motion(scene.linkage, "O3", st);
    ex = std::max(ex, std::abs(o.q[ix] - m.r.x()) / 3.0);
    ev = std::max(ev, std::abs(o.v[ix] - m.v.x()) / 1.5);
    ea = std::max(ea, std::abs(o.a[ix] - m.a.x()) / 1.5);
    eRod = std::max({eRod, std::abs(o.v[ir + 2] - st.v[rodAngle]), std::abs(o.a[ir + 2] - st.a[rodAngle])});
  });
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_EQ(k, states.size());
  EXPECT_LT(ex, kDynamicRelative);
  EXPECT_LT(ev, kDynamicRelative);
  EXPECT_LT(ea, kDynamicRelative);
  EXPECT_LT(eRod, kDynamicRelative);
  std::printf("slider-crank, kinematics vs IDA: x %.2e, v %.2e, a %.2e, rod angular %.2e\n", ex, ev, ea, eRod);
}

TEST(KinematicsAgainstDynamics, FourBarDrivenThroughIda) {
  const auto r0 = reference::fourBar(30, 60, 80, 100, 0.0);
  System sys;
  const BodyIndex crank = addRigidBody(sys, "crank", {1.0, 75.0, {15, 0}}, {{0, 0}, 0});
  const BodyIndex coupler = addRigidBody(sys, "coupler", {2.0, 600.0, {30, 0}}, {{30, 0}, r0.phi2});
  const BodyIndex rocker = addRigidBody(sys, "rocker", {2.5, 1300.0, {40, 0}}, {{100, 0}, r0.phi3});
  addRevoluteJoint(sys, "O1", kGround, {0, 0}, crank, {0, 0});
  addRevoluteJoint(sys, "O2", crank, {30, 0}, coupler, {0, 0});
  addRevoluteJoint(sys, "O3", coupler, {60, 0}, rocker, {80, 0});
  addRevoluteJoint(sys, "O4", kGround, {100, 0}, rocker, {0, 0});
  addBodyCoordinateDriver(sys, "motor", crank, "theta", makeConstantSpeedLaw(1.0));
  sys.finalize();
  const int ir = sys.coordinateOffset(rocker);

  const KinematicsScene scene = loadKinematicsScene(kDir + "kinematics_four_bar.json");
  const auto states = runAll(scene.linkage, scene.settings);
  std::size_t k = 0;
  double ex = 0, ev = 0, ea = 0;
  const SimulationSummary s = simulate(sys, tightSettings(), [&](const OutputSample& o) {
    ASSERT_LT(k, states.size());
    const KinematicState& st = states[k++];
    // O3 = rocker point (80, 0): r = R + 80 e, v = Rdot + 80 w n, a = Rddot + 80 (wd n - w^2 e).
    const double th = o.q[ir + 2], w = o.v[ir + 2], wd = o.a[ir + 2];
    const Vec2 e(std::cos(th), std::sin(th)), n = perp(e);
    const Vec2 r = o.q.segment<2>(ir) + 80 * e, v = o.v.segment<2>(ir) + 80 * w * n,
               a = o.a.segment<2>(ir) + 80 * (wd * n - w * w * e);
    const NodeMotion m = motion(scene.linkage, "O3", st);
    ex = std::max(ex, (r - m.r).norm() / 80.0);
    ev = std::max(ev, (v - m.v).norm() / 80.0);
    ea = std::max(ea, (a - m.a).norm() / 80.0);
  });
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_EQ(k, states.size());
  EXPECT_LT(ex, kDynamicRelative);
  EXPECT_LT(ev, kDynamicRelative);
  EXPECT_LT(ea, kDynamicRelative);
  std::printf("four-bar, kinematics vs IDA: x %.2e, v %.2e, a %.2e\n", ex, ev, ea);
}

// ----- singular positions ----------------------------------------------------------------

/// 50/60/80/100 violates eq. 34 (l1 + l4 = 150 > l2 + l3 = 140): the crank cannot turn
/// fully. Coupler and rocker stretch into a line when |O2 O4| = l2 + l3:
/// cos(alpha_lock) = (l1^2 + l4^2 - (l2 + l3)^2) / (2 l1 l4) = -0.71.
TEST(KinematicsSingular, NonGrashofFourBarStopsAtTheLockAngle) {
  const KinematicsScene scene = loadKinematicsScene(kDir + "kinematics_four_bar_lock.json");
  KinematicSummary summary;
  const auto states = runAll(scene.linkage, scene.settings, &summary);
  const double lock = std::acos(-0.71);
  ASSERT_FALSE(summary.ok);
  ASSERT_TRUE(summary.singular.has_value());
  EXPECT_EQ(summary.singular->kind, "lock");
  // Bisection to 1e-10 (locate_tolerance); near the fold the corrector still converges
  // at 1e-10 from it (measured error 8e-12).
  EXPECT_NEAR(summary.singular->alpha, lock, 1e-9);
  EXPECT_EQ(summary.singular->links, (std::vector<std::string>{"coupler", "rocker"}));
  EXPECT_EQ(summary.singular->nodes, (std::vector<std::string>{"O2", "O3", "O4"}));
  // Results kept up to the last step before the lock: steps 0..22 (22 x 6 deg = 132 deg).
  ASSERT_EQ(states.size(), 23u);
  EXPECT_LT(states.back().alpha, lock);
  EXPECT_EQ(summary.stepsCompleted, 23);
  EXPECT_NE(summary.message.find("locks at input alpha = 2.36029"), std::string::npos) << summary.message;
  EXPECT_NE(summary.message.find("'O3'"), std::string::npos) << summary.message;
  EXPECT_EQ(summary.message.find('\n'), std::string::npos);
}

/// A parallelogram (crank 1, coupler 2, rocker 1, ground 2) has a change point where all
/// links are collinear (alpha = pi): the parallelogram and the anti-parallelogram
/// branches cross. It is reported, not stepped over.
TEST(KinematicsSingular, ParallelogramChangePointIsReported) {
  Linkage2d l;
  const double a0 = 0.5;
  l.addFixedNode("A", {0, 0});
  l.addFreeNode("B", {std::cos(a0), std::sin(a0)});
  l.addFreeNode("C", {2 + std::cos(a0), std::sin(a0)});
  l.addFixedNode("D", {2, 0});
  l.addLink("crank", "A", "B");
  l.addLink("coupler", "B", "C");
  l.addLink("rocker", "D", "C");
  l.addLinkAngleInput("alpha", "crank");
  l.finalize();
  KinematicSettings st;
  st.start = a0;
  st.end = a0 + 2 * M_PI;
  KinematicSummary summary;
  const auto states = runAll(l, st, &summary);
  ASSERT_FALSE(summary.ok);
  ASSERT_TRUE(summary.singular.has_value());
  EXPECT_EQ(summary.singular->kind, "change point");
  // Near a crossing the corrector may land on either branch within ~1e-8 of it, which
  // limits how well the sign change of det(D L1) is located.
  EXPECT_NEAR(summary.singular->alpha, M_PI, 1e-7);
  EXPECT_LT(states.back().alpha, M_PI);
}

/// A slider-crank driven by its slider has dead points where the crank and rod align
/// (x = l2 - l1 and l1 + l2): singular at the start when started there.
TEST(KinematicsSingular, DeadPointAtTheStartIsAModelError) {
  Linkage2d l;
  l.addFixedNode("O1", {0, 0});
  l.addFreeNode("O2", {1, 0});
  l.addSliderNode("O3", {3, 0}, {1, 0});
  l.addLink("crank", "O1", "O2");
  l.addLink("rod", "O2", "O3");
  l.addSliderInput("piston", "O3");
  l.finalize();
  KinematicSettings st;
  st.start = 0;
  st.end = -1;
  try {
    KinematicAnalysis analysis(l, st);
    FAIL() << "expected a ModelError";
  } catch (const ModelError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("singular at the start"), std::string::npos) << m;
    EXPECT_NE(m.find("'crank'"), std::string::npos) << m;
  }
}

/// Driven by its slider from x = 2.8 towards the outer dead point x = 3: a lock at
/// s = 0.2 (x = l1 + l2) with the crank and rod involved.
TEST(KinematicsSingular, SliderDrivenCrankLocksAtTheDeadPoint) {
  Linkage2d l;
  const double x0 = 2.8, c = (1 + x0 * x0 - 4) / (2 * x0);  // crank angle by the cosine rule
  l.addFixedNode("O1", {0, 0});
  l.addFreeNode("O2", {c, std::sqrt(1 - c * c)});
  l.addSliderNode("O3", {x0, 0}, {1, 0});
  l.addLink("crank", "O1", "O2");
  l.addLink("rod", "O2", "O3");
  l.addSliderInput("piston", "O3");
  l.finalize();
  KinematicSettings st;
  st.start = 0;
  st.end = 0.5;
  st.steps = 10;
  KinematicSummary summary;
  runAll(l, st, &summary);
  ASSERT_FALSE(summary.ok);
  ASSERT_TRUE(summary.singular.has_value());
  EXPECT_NEAR(summary.singular->alpha, 0.2, 1e-9);
  EXPECT_EQ(summary.singular->links, (std::vector<std::string>{"crank", "rod"}));
}
