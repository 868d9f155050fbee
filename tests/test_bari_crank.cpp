// Simeon's flexible slider crank (Bari IVP test set "crank"): the engine's model of it
// (examples/bari_slider_crank.json, a rod given by its invariants) reproduces the test
// set's equations (problems/bari_crank.*) and its published reference.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>

#include "problems/bari_crank.hpp"
#include "integrators/initial_conditions.hpp"
#include "scene/scene.hpp"
#include "tests/test_support.hpp"

using namespace flexmbd;
using namespace flexmbd::testsupport;

namespace {

Scene bariScene() { return loadScene(std::string(FLEXMBD_SOURCE_DIR) + "/examples/bari_slider_crank.json"); }

struct Offsets {
  int crank, rod, slider;
  explicit Offsets(const System& sys)
      : crank(sys.coordinateOffset(sys.findBody("crank"))), rod(sys.coordinateOffset(sys.findBody("rod"))),
        slider(sys.coordinateOffset(sys.findBody("slider"))) {}
  /// (phi2, x3, q1..q4) of the engine's coordinates, the test set's order.
  std::array<double, 6> positions(const VecX& q) const {
    return {q[rod + 2], q[slider], q[rod + 3], q[rod + 4], q[rod + 5], q[rod + 6]};
  }
};

/// scd of a run of the engine's scene to t = 0.1 at rtol = tol, atol (default tol); its
/// step count in *steps when given.
double engineDigits(Formulation f, IntegratorKind integrator, double tol, std::optional<double> atol = {},
                    long* steps = nullptr) {
  Scene s = bariScene();
  s.solver.formulation = f;
  s.solver.integrator = integrator;
  // as the classic codes' runs: rtol = atol = tol for positions, angles and velocities
  // (set explicitly, as the classic codes do), elastic coordinates 1e-3 atol
  s.solver.rtol = tol;
  s.solver.atol = atol.value_or(tol);
  s.solver.atolAngle = s.solver.atolVelocity = s.solver.atol;
  s.solver.atolElastic = 1e-3 * s.solver.atol;
  s.solver.outputStep = bari::kEndTime;
  s.solver.progress = false;
  const Offsets off(s.system);
  VecX qEnd;
  const SimulationSummary sum = simulate(s.system, s.solver, [&](const OutputSample& o) { qEnd = o.q; });
  EXPECT_TRUE(sum.ok) << sum.message;
  if (steps) *steps = sum.stats.steps;
  return bari::significantDigits(off.positions(qEnd));
}

}  // namespace

TEST(BariCrank, HandCodedJacobianMatchesFiniteDifferences) {
  // The hand-coded Jacobian is forward-mode automatic differentiation: exact, so it
  // matches central differences to their truncation and round-off error, 1e-6 relative
  // per row with steps 1e-6 (1 + |y|) on entries up to 1e4.
  constexpr double kFdAgreement = 1e-6;
  const bari::HandCodedCrank crank;
  VecX y0, yp0;
  bari::HandCodedCrank::initialValues(y0, yp0);
  Random rnd(7);
  const VecX y = y0 + rnd.vector(y0.size(), -0.05, 0.05).cwiseProduct(VecX::Ones(y0.size()) + y0.cwiseAbs());
  const VecX yp = yp0 + rnd.vector(y0.size(), -1.0, 1.0);
  const int n = crank.size();
  for (double cj : {0.0, 1e3}) {
    MatX J = MatX::Zero(n, n);
    JacobianSink sink = JacobianSink::dense(J.data(), n);
    crank.jacobian(0.05, y.data(), yp.data(), cj, sink);
    auto F = [&](const VecX& yy, const VecX& yyp) {
      VecX r(n);
      crank.residual(0.05, yy.data(), yyp.data(), r.data());
      return r;
    };
    const MatX dFdy = fdJacobian([&](const VecX& z) { return F(z, yp); }, y, relativeSteps(y, 1e-6));
    const MatX dFdyp = fdJacobian([&](const VecX& z) { return F(y, z); }, yp, relativeSteps(yp, 1e-6));
    expectRowsNear(J, dFdy + cj * dFdyp, kFdAgreement, "cj = " + std::to_string(cj));
  }
}

TEST(BariCrank, SceneReproducesTheTestSetEquations) {
  // The engine's consistent initial state of the scene against the test set's consistent
  // initial values: positions and velocities as given (the engine keeps the elastic
  // state and projects the frame coordinates by 3e-12 m at most: the given x3 has 9
  // digits), and the accelerations it computes from its own mass matrix, forces and
  // constraints against the test set's w, which come from Simeon's equations. They agree
  // only if the invariants reproduce those equations (the 15-times axial mass block and
  // the truncated pi included): relative 1e-7 of each acceleration's scale (measured
  // 1e-10; the bound allows for the 9-digit initial positions).
  constexpr double kAccelerationAgreement = 1e-7;
  const Scene s = bariScene();
  const System& sys = s.system;
  const ConsistentState init = computeConsistentState(sys, 0.0, sys.initialCoordinates(), sys.initialVelocities());
  const Offsets off(sys);
  VecX y0, yp0;
  bari::HandCodedCrank::initialValues(y0, yp0);
  const VecX w = y0.segment(14, 7);  // accelerations (phi1, phi2, x3, q1..q4)
  const double phi2dd = init.a[off.rod + 2], x3dd = init.a[off.slider];
  // the rod's angular acceleration is nearly zero at t = 0: compared on the scale x3'' / L2
  EXPECT_NEAR(phi2dd, w[1], kAccelerationAgreement * std::abs(w[2]) / 0.3) << "rod angular acceleration";
  EXPECT_NEAR(x3dd, w[2], kAccelerationAgreement * std::abs(w[2])) << "slider acceleration";
  for (int k = 0; k < 4; ++k) {
    EXPECT_NEAR(init.a[off.rod + 3 + k], w[3 + k], kAccelerationAgreement * w.tail(4).cwiseAbs().maxCoeff())
        << "q" << k + 1 << "''";
  }
  std::printf("[ measured ] x3'' %.12e (test set %.12e), q1'' %.12e (%.12e), q4'' %.12e (%.12e)\n", x3dd, w[2],
              init.a[off.rod + 3], w[3], init.a[off.rod + 6], w[6]);
}

TEST(BariCrank, EngineAndHandCodedEquationsReachThePublishedReference) {
  // At tol 1e-8 (rtol = atol, elastic atol 1e-11) the positions at t = 0.1 agree with the
  // published reference to 5 significant digits or better in every formulation (measured
  // scd: see the output; bench_bari_crank sweeps the tolerances).
  constexpr double kDigitsAt1e8 = 5.0;
  for (Formulation f : {Formulation::Ggl, Formulation::Index1}) {
    const double scd = engineDigits(f, IntegratorKind::Ida, 1e-8);
    std::printf("[ measured ] engine %s IDA tol 1e-8: scd %.2f\n", toString(f).c_str(), scd);
    EXPECT_GT(scd, kDigitsAt1e8) << toString(f);
  }
  const bari::HandCodedCrank crank;
  VecX y0, yp0;
  bari::HandCodedCrank::initialValues(y0, yp0);
  IntegratorOptions o;
  o.rtol = 1e-8;
  o.atol = VecX::Constant(crank.size(), 1e10);  // w, lambda: algebraic
  o.atol.head(14).setConstant(1e-8);
  const auto ida = makeIntegrator(IntegratorKind::Ida, crank, 0.0, y0, yp0, o);
  ida->advance(bari::kEndTime, bari::kEndTime);
  const double scd = bari::significantDigits(bari::HandCodedCrank::positions(ida->y()));
  std::printf("[ measured ] hand-coded IDA tol 1e-8: scd %.2f\n", scd);
  // the hand-coded runs keep atol = tol on q (1e-5 m): 3 digits fewer on the q's
  constexpr double kHandCodedDigitsAt1e8 = 3.0;
  EXPECT_GT(scd, kHandCodedDigitsAt1e8);
}

TEST(BariCrank, GglReachesEightDigitsAtTightTolerances) {
  // The default GGL formulation used to stop improving at scd 5 to 6.5 and to fail at
  // rtol 1e-12..1e-13: its position correction G^T mu moved the rod's axial coordinate,
  // whose undamped modes carried the error to the end. With the stabilisation metric
  // (docs/formulations.md) it reaches 8 digits: measured 8.49 at rtol 1e-12, atol 1e-14
  // (elastic 1e-17, raised to its floor 1e-15 s_e; elastic rates at their floor 1e-15 V0
  // = 6.8e-14 m/s, docs/formulations.md). At rtol = atol = 1e-11 it reached 8.6 with
  // elastic rates at 1e-14 m/s, below that floor: 7.92.
  constexpr double kTightDigits = 8.0;
  const double scd = engineDigits(Formulation::Ggl, IntegratorKind::Ida, 1e-12, 1e-14);
  std::printf("[ measured ] engine ggl IDA rtol 1e-12, atol 1e-14: scd %.2f\n", scd);
  EXPECT_GT(scd, kTightDigits);
}

TEST(BariCrank, HigherRadauOrdersReachTheReferenceInFarFewerSteps) {
  // The rod's undamped modes (up to 2.5e4 rad/s, 390 periods of the fastest in 0.1 s) are
  // resolved, not damped, at these tolerances: orders 9 and 13 take far longer steps than
  // order 5 for the same accuracy. Measured at tol 1e-8 (GGL): radau5 15,500 steps, scd
  // 7.9; radau 1,500 steps, scd 8.8 (bench_bari_crank). Bounds: a fifth of the steps, and
  // no digit lost beyond 0.3 (the scd of neighbouring tolerances differ by about 1).
  constexpr double kStepRatio = 5.0, kDigitSlack = 0.3;
  long steps5 = 0, steps = 0;
  const double scd5 = engineDigits(Formulation::Ggl, IntegratorKind::Radau5, 1e-8, {}, &steps5);
  const double scd = engineDigits(Formulation::Ggl, IntegratorKind::Radau, 1e-8, {}, &steps);
  std::printf("[ measured ] engine ggl tol 1e-8: radau5 %ld steps, scd %.2f; radau %ld steps, scd %.2f\n", steps5, scd5,
              steps, scd);
  EXPECT_LT(kStepRatio * steps, steps5);
  EXPECT_GT(scd, scd5 - kDigitSlack);
}

TEST(BariCrank, AbsoluteTolerancesByCoordinateClass) {
  // Positions, angles and elastic coordinates each get their class's tolerance; their
  // velocities the same times atol_velocity / atol; multipliers are out of the tests.
  Scene s = bariScene();
  s.solver.atol = 1e-6;
  s.solver.atolAngle = 1e-7;
  s.solver.atolElastic = 1e-9;
  s.solver.atolVelocity = 1e-4;
  const DaeSystem dae(s.system, Formulation::Ggl);
  const VecX atol = absoluteTolerances(dae, s.solver);
  const DaeLayout& L = dae.layout();
  const Offsets off(s.system);
  EXPECT_EQ(atol[L.q + off.slider], 1e-6);
  EXPECT_EQ(atol[L.q + off.rod + 2], 1e-7);
  EXPECT_EQ(atol[L.q + off.rod + 3], 1e-9);
  EXPECT_DOUBLE_EQ(atol[L.v + off.slider], 1e-4);
  EXPECT_DOUBLE_EQ(atol[L.v + off.rod + 2], 1e-5);
  EXPECT_DOUBLE_EQ(atol[L.v + off.rod + 6], 1e-7);
  EXPECT_GE(atol.segment(L.lambda, 2 * L.m).minCoeff(), 1e9);
}
