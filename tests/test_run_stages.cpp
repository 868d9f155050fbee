// The stages of a run (simulation/run_stages.hpp, output_recorder.hpp,
// singular_crossing.hpp), each on its own: the hand-over decision, the output recorder,
// the failure diagnosis, the choice of the integrator options, the crossing decision and
// the summary's warnings.
#include <gtest/gtest.h>

#include <cmath>
#include <exception>
#include <limits>
#include <string>

#include "bodies/rigid_body_2d.hpp"
#include "builders/planar_builders.hpp"
#include "core/errors.hpp"
#include "core/system.hpp"
#include "integrators/bdf_stability.hpp"
#include "integrators/initial_conditions.hpp"
#include "simulation/output_recorder.hpp"
#include "simulation/run_stages.hpp"
#include "simulation/singular_crossing.hpp"
#include "problems/ffr_test_models.hpp"

using namespace flexmbd;

namespace {

/// A pendulum: a rigid bar (m 1, I_c 0.1, centre of mass 0.5 along it) pinned to the
/// ground at its frame origin, under gravity. Coordinates x, y, theta; the joint's
/// constraint g = (x, y) (frame origin on the ground pivot), G = [I 0].
System pendulum() {
  System sys;
  RigidBodyProperties bar;
  bar.mass = 1.0;
  bar.inertia = 0.1;
  bar.com = Vec2(0.5, 0.0);
  const BodyIndex b = addRigidBody(sys, "bar", bar, FrameState2d());
  addRevoluteJoint(sys, "pivot", BodyIndex(0), Vec2::Zero(), b, Vec2::Zero());
  sys.setGravity(Vec2(0.0, -9.81));
  sys.finalize();
  return sys;
}

VecX vec3(double a, double b, double c) { return (VecX(3) << a, b, c).finished(); }

}  // namespace

// --- hand over -----------------------------------------------------------------------

TEST(HandOverDecision, HandsOverAtEightyPercentOfACompleteWindow) {
  // The threshold: 1,600 error-test failures in a window of 2,000 steps (kTrapFraction 0.8
  // of kTrapWindow). Counts are integers: no tolerance.
  const std::optional<std::string> reason = shouldHandOver(IntegratorKind::Ida, {2000, 1600}, true, false, 0.25);
  ASSERT_TRUE(reason.has_value());
  EXPECT_EQ(*reason, "at t = 0.25 from ida to radau5: 1600 error-test failures in the last 2000 steps");
  // one failure fewer: IDA keeps the run
  EXPECT_FALSE(shouldHandOver(IntegratorKind::Ida, {2000, 1599}, true, false, 0.25).has_value());
  // a longer window is judged by the same fraction
  EXPECT_TRUE(shouldHandOver(IntegratorKind::Ida, {2500, 2000}, true, false, 0.25).has_value());
  EXPECT_FALSE(shouldHandOver(IntegratorKind::Ida, {2500, 1999}, true, false, 0.25).has_value());
}

TEST(HandOverDecision, AnIncompleteWindowIsNotJudged) {
  EXPECT_FALSE(StepWindow({1999, 1999}).complete());
  EXPECT_TRUE(StepWindow({2000, 0}).complete());
  EXPECT_FALSE(shouldHandOver(IntegratorKind::Ida, {1999, 1999}, true, false, 0.25).has_value());
}

TEST(HandOverDecision, OnlyIdaWithOutputsLeftAndItsAnalyticJacobianHandsOver) {
  const StepWindow trapped{2000, 2000};
  EXPECT_FALSE(shouldHandOver(IntegratorKind::Radau5, trapped, true, false, 0.25).has_value());
  EXPECT_FALSE(shouldHandOver(IntegratorKind::Ida, trapped, false, false, 0.25).has_value());  // the last output
  EXPECT_FALSE(shouldHandOver(IntegratorKind::Ida, trapped, true, true, 0.25).has_value());    // difference quotients
}

TEST(HandOverDecision, TheWindowCountsFromItsStart) {
  IntegratorStats start, now;
  start.steps = 3000;
  start.errorTestFailures = 2600;
  now.steps = 5000;
  now.errorTestFailures = 4200;
  const StepWindow w = stepWindow(now, start);
  EXPECT_EQ(w.steps, 2000);
  EXPECT_EQ(w.errorTestFailures, 1600);
}

// --- output recorder ---------------------------------------------------------------

TEST(OutputRecorder, KeepsTheLargestViolationsCoordinateAndSpeed) {
  const System sys = pendulum();
  int calls = 0;
  const OutputCallback count = [&](const OutputSample&) { ++calls; };
  constexpr double kModelSize = 2.0;  // given, not the pendulum's own: the angular rate is scaled by it
  OutputRecorder recorder(sys, kModelSize, count);
  // g = (x, y) and G v = (vx, vy) exactly (pivot at the frame origin): the maxima are
  // exact values, compared to round-off of their size.
  constexpr double kRoundOff = 1e-15;
  recorder.record(0.1, vec3(1e-3, -2e-4, 3.0), vec3(0.2, 0.0, 0.05));
  recorder.record(0.2, vec3(1e-4, 0.0, -3.0), vec3(0.0, -0.1, 0.5));
  const RecordedOutputs& r = recorder.recorded();
  EXPECT_EQ(calls, 2);
  EXPECT_EQ(r.tReached, 0.2);
  EXPECT_EQ(r.last.t, 0.2);
  EXPECT_NEAR(r.maxPositionViolation, 1e-3, kRoundOff);
  EXPECT_NEAR(r.maxVelocityViolation, 0.2, kRoundOff);
  EXPECT_EQ(r.largestCoordinate, 1e-3);                     // the angle 3 rad is not a coordinate of size
  EXPECT_EQ(r.maxSpeed, 0.5 * kModelSize);                  // angular rate times the model size
  ASSERT_TRUE(r.energyStart.has_value() && r.energyEnd.has_value());  // gravity only: conservative
  EXPECT_NE(*r.energyStart, *r.energyEnd);                  // the second state moves faster
  EXPECT_EQ(r.last.a.size(), 3);                            // accelerations recomputed from the state
  EXPECT_EQ(r.last.lambda.size(), 2);
}

TEST(OutputRecorder, StopsBeforeANonFiniteOutput) {
  // A free bar (the pendulum without its pivot): the accelerations of a NaN translational
  // velocity are still computed (M a = Q, Q depends on the angular rate only), so the
  // recorder's own check finds it.
  System sys;
  RigidBodyProperties bar;
  bar.com = Vec2(0.5, 0.0);
  addRigidBody(sys, "bar", bar, FrameState2d());
  sys.finalize();
  int calls = 0;
  const OutputCallback count = [&](const OutputSample&) { ++calls; };
  OutputRecorder recorder(sys, 1.0, count);
  recorder.record(0.1, vec3(0.0, 0.0, 0.3), vec3(0.0, 0.0, 1.0));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  try {
    recorder.record(0.2, vec3(0.0, 0.0, 0.3), vec3(0.0, nan, 1.0));
    FAIL() << "a NaN velocity was recorded";
  } catch (const NonFiniteResult& e) {
    EXPECT_EQ(std::string(e.what()), "non-finite velocities at t = 0.2");
  }
  const RecordedOutputs& r = recorder.recorded();
  EXPECT_EQ(calls, 1);            // the callback never saw it
  EXPECT_EQ(r.tReached, 0.1);     // the last output passed on
  EXPECT_EQ(r.tEvaluating, 0.2);  // the one that failed
  EXPECT_EQ(r.last.t, 0.1);
  EXPECT_EQ(r.maxSpeed, 1.0);     // a NaN does not enter the maxima
}

TEST(OutputRecorder, AnOverflowingEnergyIsNonFinite) {
  // The pendulum with vx = 1e155 m/s: the state and its accelerations are finite (the pivot
  // at the frame origin: no velocity term in the constraint's right-hand side, the
  // quadratic velocity forces depend on the angular rate), its kinetic energy
  // m vx^2 / 2 = 5e309 overflows.
  const System sys = pendulum();
  OutputRecorder recorder(sys, 1.0, OutputCallback());
  EXPECT_THROW(
      {
        try {
          recorder.record(0.3, vec3(0.0, 0.0, 0.0), vec3(1e155, 0.0, 0.0));
        } catch (const NonFiniteResult& e) {
          EXPECT_EQ(std::string(e.what()), "non-finite energy at t = 0.3");
          throw;
        }
      },
      NonFiniteResult);
  EXPECT_FALSE(recorder.recorded().energyStart.has_value());
}

// --- diagnose ----------------------------------------------------------------------

TEST(DiagnoseFailure, ADivergedRunSaysHowFarItWent) {
  const System sys = pendulum();
  RecordedOutputs outputs;
  outputs.largestCoordinate = 250.0;  // 125 model sizes: beyond kDivergedSize 100
  outputs.tEvaluating = 1.5;
  const FailureContext ctx{sys, outputs, 2.0, 1.0, 1.6};
  const SolverError error("IDA failed at t = 1.6: the corrector did not converge", 1.6, 1e-9);
  const RunFailure f = diagnoseFailure(std::make_exception_ptr(error), ctx);
  EXPECT_EQ(f.message, std::string(error.what()) +
                           "; the solution diverged: a coordinate reached 250 at t = 1.5, 125 times the model size 2");
  EXPECT_EQ(f.time, 1.6);
  EXPECT_EQ(f.signal, 0);
  EXPECT_FALSE(f.outputFailed);
  EXPECT_EQ(divergenceReport(200.0, 2.0, 1.5), "");  // exactly 100 model sizes: not diverged
}

TEST(DiagnoseFailure, ARegularPositionIsNamedNotSingular) {
  const System sys = pendulum();
  const ConsistentState cs = computeConsistentState(sys, 0.0, sys.initialCoordinates(), sys.initialVelocities());
  RecordedOutputs outputs;
  outputs.last.t = 0.0;
  outputs.last.q = cs.q;
  outputs.last.v = cs.v;
  outputs.last.a = cs.a;
  outputs.last.lambda = cs.lambda;
  const FailureContext ctx{sys, outputs, 1.0, 1.0, 0.0};
  const RunFailure f = diagnoseFailure(std::make_exception_ptr(SolverError("IDA failed", 0.01, 1e-9)), ctx);
  EXPECT_EQ(f.message.rfind("IDA failed; constraint Jacobian at t = 0.01", 0), 0u) << f.message;
  EXPECT_NE(f.message.find("not a singular position"), std::string::npos) << f.message;
}

TEST(DiagnoseFailure, InterruptsWriteErrorsAndOutputErrorsAreFailuresOfTheRun) {
  const System sys = pendulum();
  RecordedOutputs outputs;
  outputs.tEvaluating = 0.7;
  const FailureContext ctx{sys, outputs, 1.0, 1.0, 0.65};
  const RunFailure interrupted = diagnoseFailure(std::make_exception_ptr(RunInterrupted("interrupted", 15)), ctx);
  EXPECT_EQ(interrupted.signal, 15);
  EXPECT_EQ(interrupted.time, 0.7);
  const RunFailure full = diagnoseFailure(std::make_exception_ptr(OutputWriteError("disk full")), ctx);
  EXPECT_TRUE(full.outputFailed);
  EXPECT_EQ(full.message, "disk full");
  const RunFailure nonFinite = diagnoseFailure(std::make_exception_ptr(NonFiniteResult("non-finite positions")), ctx);
  EXPECT_EQ(nonFinite.message, "non-finite positions: the run stops before this output (the rows before it are kept)");
  // a model error at an output state: the time is the integrator's
  const RunFailure model = diagnoseFailure(std::make_exception_ptr(ModelError("singular mass matrix")), ctx);
  EXPECT_EQ(model.time, 0.65);
  EXPECT_EQ(model.message.rfind("evaluating the outputs at t = 0.700000 failed: singular mass matrix", 0), 0u)
      << model.message;
  // an input error and an assembly bug keep their type
  EXPECT_THROW(diagnoseFailure(std::make_exception_ptr(InputError("bad key")), ctx), InputError);
  EXPECT_THROW(diagnoseFailure(std::make_exception_ptr(std::logic_error("bug")), ctx), std::logic_error);
}

// --- choose ------------------------------------------------------------------------

TEST(ChooseIntegratorOptions, DampedRodLimitsIdasOrderOnlyForGglAndIndex3) {
  // The Rayleigh-damped 4-element crank of tests/test_damped_crank.cpp (beta 3.1e-5 s):
  // its 0.079-damped mode lies outside BDF4's sector, inside BDF3's.
  Scene s = testmodels::elasticSliderCrank(4, 1.0, 0, 2.0, 1e-7, 1e-10, 3.1e-5);
  s.solver.integrator = IntegratorKind::Ida;  // IDA's order limit is the subject ("auto" picks radau5 here)
  {
    const DaeSystem dae(s.system, s.solver.formulation);
    const ChosenIntegrator c = chooseIntegratorOptions(s.system, dae, s.solver);
    EXPECT_EQ(c.kind, IntegratorKind::Ida);
    EXPECT_EQ(c.options.maxOrder, 3);
    EXPECT_EQ(c.orderLimit, stableBdfOrder(s.system, 5).reason());
    EXPECT_FALSE(c.orderLimit.empty());
    EXPECT_TRUE(c.options.atol.isApprox(absoluteTolerances(dae, s.solver), 0.0));
  }
  s.solver.formulation = Formulation::Index1;
  {
    const DaeSystem dae(s.system, s.solver.formulation);
    const ChosenIntegrator c = chooseIntegratorOptions(s.system, dae, s.solver);
    EXPECT_EQ(c.options.maxOrder, 5);
    EXPECT_EQ(c.orderLimit, "");
  }
  s.solver.formulation = Formulation::Ggl;
  s.solver.integrator = IntegratorKind::Radau5;
  const DaeSystem dae(s.system, s.solver.formulation);
  EXPECT_EQ(chooseIntegratorOptions(s.system, dae, s.solver).options.maxOrder, 5);
}

TEST(ChooseIntegratorOptions, MinStepDefaultsToATrillionthOfTheSpanAtMostOnePicosecond) {
  const System sys = pendulum();
  const DaeSystem dae(sys, Formulation::Ggl);
  SolverSettings st;
  st.tEnd = 0.05;  // span 0.05 s: 5e-14 s
  EXPECT_DOUBLE_EQ(chooseIntegratorOptions(sys, dae, st).options.minStepSize, 5e-14);
  st.tEnd = 1e3;   // long run: capped at 1e-12 s
  EXPECT_DOUBLE_EQ(chooseIntegratorOptions(sys, dae, st).options.minStepSize, 1e-12);
  st.minStepSize = 1e-10;  // given: kept
  EXPECT_EQ(chooseIntegratorOptions(sys, dae, st).options.minStepSize, 1e-10);
}

// --- output times --------------------------------------------------------------------

TEST(OutputSchedule, TheLastOutputIsExactlyTheEndTime) {
  const OutputSchedule a(0.0, 1.0, 0.3);
  EXPECT_EQ(a.count, 4);
  EXPECT_EQ(a.time(4), 1.0);
  const OutputSchedule b(0.0, 0.3, 0.1);  // 0.3 / 0.1 = 2.9999999999999996: three outputs, not four
  EXPECT_EQ(b.count, 3);
  EXPECT_EQ(b.time(3), 0.3);
}

// --- crossing decision -----------------------------------------------------------------

TEST(PlanCrossing, CrossesWhereGIsFarWorseConditionedThanAtTheStartButNotADivergedRun) {
  // The pendulum's G = [I 0] has singular value ratio 1 everywhere; a start ratio of 10
  // makes it 10 times worse than "at the start" (below kCrossingTrigger 0.5): crossed.
  const System sys = pendulum();
  const DaeSystem dae(sys, Formulation::Ggl);
  const SolverSettings st;
  const IntegratorOptions options;
  const ConsistentState cs = computeConsistentState(sys, 0.0, sys.initialCoordinates(), sys.initialVelocities());
  RecordedOutputs outputs;
  outputs.last.q = cs.q;
  outputs.last.v = cs.v;
  outputs.last.a = cs.a;
  outputs.last.lambda = cs.lambda;
  const RunState state;
  const SolverError failure("IDA failed", 0.01, 1e-9);
  const RunContext worse{sys, dae, st, options, OutputSchedule(0.0, 1.0, 0.1), 1.0, 10.0, true};
  const std::optional<CrossingPlan> plan = planCrossing(worse, state, outputs, failure);
  ASSERT_TRUE(plan.has_value());
  EXPECT_EQ(plan->restarts, 0);
  EXPECT_EQ(plan->endFactor, 4.0);  // kCrossingEndFactor, not doubled
  // conditioned as at the start: not crossed
  const RunContext same{sys, dae, st, options, OutputSchedule(0.0, 1.0, 0.1), 1.0, 1.0, true};
  EXPECT_FALSE(planCrossing(same, state, outputs, failure).has_value());
  // crossing not allowed, or the solution diverged: not crossed
  const RunContext notAllowed{sys, dae, st, options, OutputSchedule(0.0, 1.0, 0.1), 1.0, 10.0, false};
  EXPECT_FALSE(planCrossing(notAllowed, state, outputs, failure).has_value());
  outputs.largestCoordinate = 101.0;
  EXPECT_FALSE(planCrossing(worse, state, outputs, failure).has_value());
}

TEST(PlanCrossing, OnlyConstrainedPlanarRunsNotOnAli3pMayCross) {
  const System sys = pendulum();
  SolverSettings st;
  EXPECT_TRUE(mayCrossSingularPositions(sys, st, IntegratorKind::Ida));
  EXPECT_TRUE(mayCrossSingularPositions(sys, st, IntegratorKind::Radau5));
  EXPECT_FALSE(mayCrossSingularPositions(sys, st, IntegratorKind::AugmentedLagrangian));
  st.crossSingular = false;
  EXPECT_FALSE(mayCrossSingularPositions(sys, st, IntegratorKind::Ida));
  System free;
  addRigidBody(free, "bar", RigidBodyProperties(), FrameState2d());
  free.finalize();
  EXPECT_FALSE(mayCrossSingularPositions(free, SolverSettings(), IntegratorKind::Ida));  // nothing to lose rank
}

// --- finish ------------------------------------------------------------------------

TEST(FinishSummary, WarnsOfViolationsAboveAThousandthOfTheScale) {
  RunStart start;
  start.modelSize = 1.0;
  RecordedOutputs outputs;
  outputs.maxPositionViolation = 1e-3;  // at the threshold: no warning
  outputs.maxVelocityViolation = 2e-4;  // velocity scale max(0 speed, 1 m / 10 s) = 0.1: threshold 1e-4
  const ChosenIntegrator choice;
  const RunState state;
  SimulationSummary s = finishSummary(start, outputs, choice, state, std::nullopt, 10.0);
  EXPECT_TRUE(s.ok);
  EXPECT_EQ(s.message, "reached t_end");
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(s.warnings[0], "velocity constraints violated by up to 0.0002, more than 1e-3 of the velocity scale "
                           "0.1: the results are not accurate (tighten atol and rtol)");
  outputs.maxPositionViolation = 2e-3;
  const RunFailure failure{"IDA failed", 3.5};
  s = finishSummary(start, outputs, choice, state, failure, 10.0);
  EXPECT_FALSE(s.ok);
  EXPECT_EQ(s.message, "IDA failed");
  EXPECT_EQ(s.failureTime, 3.5);
  ASSERT_EQ(s.warnings.size(), 2u);
  EXPECT_EQ(s.warnings[0].rfind("position constraints violated by up to 0.002, more than 1e-3 of the model size 1", 0),
            0u);
}
