// Damped elastic slider-crank under IDA (issue 11, item 10): stiffness-proportional
// damping of the rod must not make IDA reject almost every step.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "integrators/simulation.hpp"
#include "tests/ffr_test_models.hpp"

using namespace flexmbd;

namespace {

/// The case: 4 nodal elements, Rayleigh beta 3.1e-5 s, rtol 1e-7, atol 1e-10.
constexpr double kBeta = 3.1e-5, kRtol = 1e-7, kAtol = 1e-10;

struct CrankRun {
  SimulationSummary summary;
  double peakDeflection = 0.0;  ///< max |mid.uy| over the outputs
};

CrankRun runCrank(Scene& s) {
  CrankRun r;
  const OutputRequest& mid = s.outputs.at(0);
  r.summary = simulate(s.system, s.solver, [&](const OutputSample& o) {
    r.peakDeflection = std::max(r.peakDeflection, std::abs(mid.evaluate(s.system, o.q, o.v)[1]));
  });
  return r;
}

}  // namespace

TEST(DampedCrank, ElasticVelocitiesOfDampedBodiesAreOutOfTheErrorTestWithGgl) {
  // Their positions stay in it; undamped bodies and the other formulations keep all.
  for (const double beta : {kBeta, 0.0}) {
    Scene s = testmodels::elasticSliderCrank(4, 1.0, 0, 2.0, kRtol, kAtol, beta);
    const int rod = s.system.coordinateOffset(s.system.findBody("rod"));
    const int nq = s.system.numCoordinates();
    for (const Formulation f : {Formulation::Ggl, Formulation::Index1}) {
      const DaeSystem dae(s.system, f);
      const VecX id = dae.differentialIds();
      const bool excluded = beta > 0 && f == Formulation::Ggl;
      EXPECT_EQ(id.segment(dae.layout().q, nq).minCoeff(), 1.0);
      for (int k = rod + 3; k < rod + 3 + 12; ++k) EXPECT_EQ(id[dae.layout().v + k], excluded ? 0.0 : 1.0) << k;
      for (int k = rod; k < rod + 3; ++k) EXPECT_EQ(id[dae.layout().v + k], 1.0) << k;  // frame velocities
    }
  }
}

TEST(DampedCrank, TwoRevolutionsWithoutAStepRejectedAtEveryStep) {
  // Before: 13,740 steps with 10,287 error-test failures (0.53 s; the issue measured
  // 377,417 / 373,027 on an older engine): bursts of failures dropped IDA to order 1,
  // where it failed once per step. Now 1,854 steps, 18 failures (0.06 s). Bound: 200,
  // 10 % of the steps (the undamped rod: 1.4 %, 1,769 of 127,515).
  constexpr long kMaxErrorTestFailures = 200;
  constexpr long kMaxSteps = 6000;  // 3x the measured 1,854; before 13,740
  Scene s = testmodels::elasticSliderCrank(4, 1.0, 0, 2.0, kRtol, kAtol, kBeta);
  const CrankRun r = runCrank(s);
  ASSERT_TRUE(r.summary.ok) << r.summary.message;
  EXPECT_LE(r.summary.stats.errorTestFailures, kMaxErrorTestFailures);
  EXPECT_LE(r.summary.stats.steps, kMaxSteps);
  // The accuracy is kept: the peak midpoint deflection agrees with the index-1 run (all
  // velocities error-controlled) at 100x tighter tolerances: rtol 1e-7 of the 0.45 m mechanism
  // is 4.5e-8 m, 2.5e-5 of the 1.8e-3 m deflection; bound 1e-4 (measured 6e-7).
  constexpr double kDeflectionAgreement = 1e-4;
  Scene ref = testmodels::elasticSliderCrank(4, 1.0, 0, 2.0, kRtol / 100, kAtol / 100, kBeta);
  ref.solver.formulation = Formulation::Index1;
  const CrankRun rr = runCrank(ref);
  ASSERT_TRUE(rr.summary.ok) << rr.summary.message;
  EXPECT_NEAR(r.peakDeflection / rr.peakDeflection, 1.0, kDeflectionAgreement);
  std::printf("[ measured ] %ld steps, %ld error-test failures, %.3f s CPU; peak deflection %.6e m "
              "(index-1 reference %.6e m, %ld steps)\n",
              r.summary.stats.steps, r.summary.stats.errorTestFailures, r.summary.cpuSeconds,
              r.peakDeflection, rr.peakDeflection, rr.summary.stats.steps);
}
