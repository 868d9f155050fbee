// Validation: GGL (index 2), index 3 and index 1 give the same trajectory where they work.
#include <gtest/gtest.h>

#include <cmath>

#include "integrators/simulation.hpp"
#include "io/scene.hpp"
#include "tests/reference_solutions.hpp"

using namespace flexmbd;

namespace {

struct Result {
  SimulationSummary summary;
  double maxPosError = 0, maxVelError = 0;  // slider, against the closed form
};

Result runSliderCrank(Formulation f, double tEnd) {
  Scene scene = loadScene(std::string(FLEXMBD_SOURCE_DIR) + "/examples/slider_crank_rigid.json");
  scene.solver.formulation = f;
  scene.solver.tEnd = tEnd;
  scene.solver.progress = false;
  const int ix = scene.system.coordinateOffset(scene.system.findBody("slider"));
  Result r;
  r.summary = simulate(scene.system, scene.solver, [&](const OutputSample& o) {
    const auto ref = reference::sliderCrank(1.0, 2.0, o.t);
    r.maxPosError = std::max(r.maxPosError, std::abs(o.q[ix] - ref.x));
    r.maxVelError = std::max(r.maxVelError, std::abs(o.v[ix] - ref.xd));
  });
  return r;
}

}  // namespace

TEST(Formulations, AllThreeAgreeOnTheRigidSliderCrank) {
  // Each formulation at rtol 1e-8 over one revolution. Positions are in the error test
  // of all three: they agree with the closed form to 1e-6 (100 rtol, allowing for the
  // index-1 drift). Index 3 keeps the velocities out of the error test (they are
  // index-2 variables there), so its velocities are only ~1e-5 accurate.
  constexpr double kPositionTolerance = 1e-6;
  constexpr double kVelocityToleranceIndex2Or1 = 1e-6;
  constexpr double kVelocityToleranceIndex3 = 1e-4;
  for (Formulation f : {Formulation::Ggl, Formulation::Index3, Formulation::Index1}) {
    const Result r = runSliderCrank(f, 2 * M_PI);
    ASSERT_TRUE(r.summary.ok) << toString(f) << ": " << r.summary.message;
    EXPECT_LT(r.maxPosError, kPositionTolerance) << toString(f);
    EXPECT_LT(r.maxVelError, f == Formulation::Index3 ? kVelocityToleranceIndex3 : kVelocityToleranceIndex2Or1)
        << toString(f);
    std::printf("[ measured ] %-6s steps %5ld  |x - x_exact| %.2e  |v - v_exact| %.2e  |g| %.2e  |Gv+gt| %.2e\n",
                toString(f).c_str(), r.summary.stats.steps, r.maxPosError, r.maxVelError,
                r.summary.maxPositionViolation, r.summary.maxVelocityViolation);
  }
}

TEST(Formulations, Index1DriftsGglDoesNot) {
  // Over 20 revolutions the acceleration-level form lets position and velocity
  // constraint violations grow (nothing pulls them back); GGL keeps both at the Newton
  // tolerance. This is why GGL is the default.
  const Result ggl = runSliderCrank(Formulation::Ggl, 40 * M_PI);
  const Result i1 = runSliderCrank(Formulation::Index1, 40 * M_PI);
  ASSERT_TRUE(ggl.summary.ok && i1.summary.ok);
  constexpr double kGglDrift = 1e-7;  // Newton tolerance level at rtol 1e-8
  EXPECT_LT(ggl.summary.maxPositionViolation, kGglDrift);
  EXPECT_LT(ggl.summary.maxVelocityViolation, kGglDrift);
  EXPECT_GT(i1.summary.maxPositionViolation, ggl.summary.maxPositionViolation);
  std::printf("[ measured ] 20 revolutions: index1 |g| %.2e |Gv+gt| %.2e ; ggl |g| %.2e |Gv+gt| %.2e\n",
              i1.summary.maxPositionViolation, i1.summary.maxVelocityViolation,
              ggl.summary.maxPositionViolation, ggl.summary.maxVelocityViolation);
}
