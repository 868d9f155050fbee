// Validation: the rigid slider-crank against the closed forms of source document 000
// (eqs. 30-32), through the scene file of the README and through the C++ API.
#include <gtest/gtest.h>

#include <cmath>

#include "bodies/rigid_body_2d.hpp"
#include "builders/planar_builders.hpp"
#include "simulation/simulation.hpp"
#include "scene/scene.hpp"
#include "problems/reference_solutions.hpp"

using namespace flexmbd;

namespace {

// At rtol = 1e-8 (atol 1e-10) IDA's global error over one revolution stays within a
// few rtol; the issue requires relative errors below 1e-7.
constexpr double kRelativeTolerance = 1e-7;

struct Errors {
  double x = 0, xd = 0, xdd = 0;
  int samples = 0;
};

/// Max relative errors of the slider against the closed form. Velocity and acceleration
/// cross zero, so their error is relative to their amplitude over the revolution
/// (l1 w (1 + l1/l2) and l1 w^2 (1 + l1/l2) bound them).
Errors compareSlider(const System& sys, const SolverSettings& st, double l1, double l2,
                     double a0, double w) {
  const BodyIndex slider = sys.findBody("slider");
  const int ix = sys.coordinateOffset(slider);
  Errors e;
  const double vScale = l1 * w * (1 + l1 / l2), aScale = l1 * w * w * (1 + l1 / l2);
  const SimulationSummary s = simulate(sys, st, [&](const OutputSample& o) {
    const auto ref = reference::sliderCrank(l1, l2, a0 + w * o.t, w);
    e.x = std::max(e.x, std::abs(o.q[ix] - ref.x) / std::abs(ref.x));
    e.xd = std::max(e.xd, std::abs(o.v[ix] - ref.xd) / vScale);
    e.xdd = std::max(e.xdd, std::abs(o.a[ix] - ref.xdd) / aScale);
    ++e.samples;
  });
  EXPECT_TRUE(s.ok) << s.message;
  return e;
}

}  // namespace

TEST(RigidSliderCrank, SceneFileMatchesClosedFormEq30to32) {
  Scene scene = loadScene(std::string(FLEXMBD_SOURCE_DIR) + "/examples/slider_crank_rigid.json");
  scene.solver.progress = false;
  const Errors e = compareSlider(scene.system, scene.solver, 1.0, 2.0, 0.0, 1.0);
  EXPECT_EQ(e.samples, 61);  // t = 0 and 60 steps per revolution
  EXPECT_LT(e.x, kRelativeTolerance);
  EXPECT_LT(e.xd, kRelativeTolerance);
  EXPECT_LT(e.xdd, kRelativeTolerance);
  RecordProperty("max_rel_error_x", std::to_string(e.x));
}

/// Second geometry: l1 = 0.4, l2 = 1.3, crank starting at 0.7 rad, 2.5 rad/s, built in
/// C++ with the centres of mass off the frame origins and the frames at the joints.
TEST(RigidSliderCrank, OffsetCrankAngleApiBuiltMatchesClosedForm) {
  const double l1 = 0.4, l2 = 1.3, a0 = 0.7, w = 2.5;
  const auto ref0 = reference::sliderCrank(l1, l2, a0, w);
  const Vec2 pB(l1 * std::cos(a0), l1 * std::sin(a0));
  const double rodAngle = std::atan2(-pB.y(), ref0.x - pB.x());
  System sys;
  const BodyIndex crank = addRigidBody(sys, "crank", {2.0, 0.05, {0.2, 0.0}}, {{0, 0}, a0});
  const BodyIndex rod = addRigidBody(sys, "rod", {1.5, 0.3, {0.65, 0.02}}, {pB, rodAngle});
  const BodyIndex slider = addRigidBody(sys, "slider", {0.8, 0.01, {0.1, 0.0}}, {{ref0.x, 0}, 0.0});
  addRevoluteJoint(sys, "O1", kGround, {0, 0}, crank, {0, 0});
  addRevoluteJoint(sys, "O2", crank, {l1, 0}, rod, {0, 0});
  addRevoluteJoint(sys, "O3", rod, {l2, 0}, slider, {0, 0});
  addPrismaticJoint(sys, "P", kGround, {0, 0}, slider, {0, 0}, {1, 0});
  addBodyCoordinateDriver(sys, "motor", crank, "theta", makeConstantSpeedLaw(w, a0));
  sys.finalize();
  SolverSettings st;
  st.rtol = 1e-8;
  st.atol = 1e-10;
  st.tEnd = 2 * M_PI / w;
  st.outputStep = st.tEnd / 60;
  st.progress = false;
  const Errors e = compareSlider(sys, st, l1, l2, a0, w);
  EXPECT_LT(e.x, kRelativeTolerance);
  EXPECT_LT(e.xd, kRelativeTolerance);
  EXPECT_LT(e.xdd, kRelativeTolerance);
}

/// Dense LU and KLU solve the same Newton systems: the trajectories agree to far below
/// the tolerance (only round-off in the factorisations differs).
TEST(RigidSliderCrank, DenseAndKluGiveTheSameTrajectory) {
  const std::string path = std::string(FLEXMBD_SOURCE_DIR) + "/examples/slider_crank_rigid.json";
  std::vector<VecX> runs[2];
  long steps[2] = {0, 0};
  int k = 0;
  for (LinearSolverKind kind : {LinearSolverKind::Dense, LinearSolverKind::Klu}) {
    Scene scene = loadScene(path);
    scene.solver.progress = false;
    scene.solver.linearSolver = kind;
    const auto s = simulate(scene.system, scene.solver, [&](const OutputSample& o) { runs[k].push_back(o.q); });
    ASSERT_TRUE(s.ok) << s.message;
    EXPECT_EQ(s.usedKlu, kind == LinearSolverKind::Klu);
    steps[k++] = s.stats.steps;
  }
  ASSERT_EQ(runs[0].size(), runs[1].size());
  // Round-off differences between the two LU factorisations may change a step-size
  // decision; the results must still agree to well within the tolerance (1e-8).
  constexpr double kSameTrajectory = 1e-8;  // = rtol: both within the tolerance of each other
  double maxDiff = 0;
  for (size_t i = 0; i < runs[0].size(); ++i) maxDiff = std::max(maxDiff, (runs[0][i] - runs[1][i]).lpNorm<Eigen::Infinity>());
  EXPECT_LT(maxDiff, kSameTrajectory) << "steps dense " << steps[0] << ", klu " << steps[1];
}
