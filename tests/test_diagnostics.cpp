// Failure messages state what was measured and name a cause only when the measurement
// supports it: an undriven mechanism is not told that its drivers do
// not determine its motion; a well-conditioned Jacobian near a singular position is not
// called "not near a singular configuration"; a diverged solution is called diverged, not
// a model with redundant constraints or a massless body.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

#include "bodies/rigid_body_2d.hpp"
#include "builders/planar_builders.hpp"
#include "core/force.hpp"
#include "core/system.hpp"
#include "simulation/simulation.hpp"
#include "scene/scene.hpp"

using namespace flexmbd;

namespace {

/// Q_x = +k x on a rigid body (no potential is claimed): a runaway the scene format
/// refuses (stiffness >= 0), for making a solution diverge on purpose.
class RepellingForce : public Force {
 public:
  RepellingForce(BodyIndex b, double k) : Force("repelling", {b}), k_(k) {}
  std::string typeName() const override { return "repelling"; }
  void addForce(double, const BodyStates& bodies, const VecX&, VecX& Q, MatX* dQdq, MatX*,
                KinematicsWork&) const override {
    Q[0] += k_ * bodies[0].q[0];
    if (dQdq) (*dQdq)(0, 0) += k_;
  }
  bool isConservative() const override { return false; }

 private:
  double k_;
};

bool has(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

/// The undriven parallelogram with the crossing of singular positions switched off: the
/// run stops at its first change point, and the message of that stop is what is tested.
Scene parallelogram(double rtol) {
  Scene s = loadScene(std::string(FLEXMBD_SOURCE_DIR) + "/examples/parallelogram_undriven.json");
  s.solver.progress = false;
  s.solver.crossSingular = false;
  s.solver.rtol = rtol;
  s.solver.atol = rtol * 1e-2;
  return s;
}

/// The crank of the undriven parallelogram is horizontal (all links collinear) where the
/// run fails: |theta| of the last output below one output step of its motion (|theta'|
/// < 4 rad/s from the energy, output step 0.01 s).
constexpr double kNearCollinear = 0.05;

}  // namespace

TEST(Diagnostics, UndrivenMechanismAtItsChangePointIsNotToldAboutDrivers) {
  // Without crossings (cross_singular false) the engine stops at the first change point
  // (t ~ 0.64) at rtol 1e-8. This test holds the message of that stop to what was measured.
  Scene s = parallelogram(1e-8);
  const int crank = s.system.coordinateOffset(s.system.findBody("crank"));
  double lastTheta = 0;
  const SimulationSummary sum =
      simulate(s.system, s.solver, [&](const OutputSample& o) { lastTheta = o.q[crank + 2]; });
  std::printf("[ measured ] undriven parallelogram, rtol 1e-8: %s at t = %.4f, crank angle %.4f\n  %s\n",
              sum.ok ? "passes" : "stops", sum.failureTime, lastTheta, sum.message.c_str());
  ASSERT_FALSE(sum.ok);
  EXPECT_LT(std::fabs(std::remainder(lastTheta, M_PI)), kNearCollinear);
  EXPECT_TRUE(has(sum.message, "undriven mechanism")) << sum.message;
  EXPECT_TRUE(has(sum.message, "joint 'O")) << sum.message;
  EXPECT_FALSE(has(sum.message, "driver")) << sum.message;
  EXPECT_TRUE(has(sum.message, "at the start)")) << sum.message;  // the model's own conditioning, for comparison
}

TEST(Diagnostics, FullRankNearASingularPositionIsCalledApproachingIt) {
  // At rtol 1e-10 the run stops 0.015 rad before the collinear position, where G still
  // has full rank by the rank test but is 47 times worse conditioned than at the start.
  Scene s = parallelogram(1e-10);
  const SimulationSummary sum = simulate(s.system, s.solver, nullptr);
  std::printf("[ measured ] undriven parallelogram, rtol 1e-10: %s at t = %.4f\n  %s\n", sum.ok ? "passes" : "stops",
              sum.failureTime, sum.message.c_str());
  ASSERT_FALSE(sum.ok);
  EXPECT_TRUE(has(sum.message, "approaching a singular position") || has(sum.message, "undriven mechanism"))
      << sum.message;
  EXPECT_FALSE(has(sum.message, "not a singular position")) << sum.message;
  EXPECT_FALSE(has(sum.message, "not near")) << sum.message;
}

TEST(Diagnostics, DivergedSolutionIsCalledDiverged) {
  // A free body pushed away by Q_x = k x, k = 1e6 N/m: x grows as exp(1000 t) until the
  // numbers overflow. The message must report the growth measured, not redundant
  // constraints or a missing mass.
  System sys;
  RigidBodyProperties p;
  FrameState2d init;
  init.position = Vec2(1.0, 0.0);
  const BodyIndex b = addRigidBody(sys, "runaway", p, init);
  sys.addForce(std::make_unique<RepellingForce>(b, 1e6));
  sys.finalize();
  SolverSettings st;
  st.progress = false;
  st.tEnd = 2.0;
  st.outputStep = 0.01;
  const SimulationSummary sum = simulate(sys, st, nullptr);
  std::printf("[ measured ] runaway body: %s at t = %.4f\n  %s\n", sum.ok ? "passes" : "stops", sum.failureTime,
              sum.message.c_str());
  ASSERT_FALSE(sum.ok);
  EXPECT_TRUE(has(sum.message, "diverged") || has(sum.message, "non-finite")) << sum.message;
  EXPECT_FALSE(has(sum.message, "redundant")) << sum.message;
  EXPECT_FALSE(has(sum.message, "no mass")) << sum.message;
}
