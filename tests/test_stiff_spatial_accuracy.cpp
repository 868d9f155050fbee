// Accuracy against the tolerance on a stiff spatial benchmark, the
// IFToMM A05 stiff flyball governor (docs/stability.md, "Stiff force elements: the free
// A05 governor"). The governor of examples/flyball_governor.json (the A05 parameters:
// springs k = 8e5 N/m, c = 4e4 N s/m) with the motor removed and the whole model spun at
// 2 pi rad/s from the 30 deg configuration (steady only at 4.917 rad/s): the arms swing
// out against the stiff, heavily damped springs while the spindle turns freely. Its
// rotation angle is neutrally stable (the angular momentum about the axis is conserved),
// so every local error of the angular momentum shifts the phase for the rest of the run.
//
// Reference: the engine's own Radau IIA (orders 5-13) at rtol 1e-11, checked against rtol
// 1e-12 (they agree to ~1e-11 m, measured 5e-12 ... 2e-11 m: far below every error bounded here).
// Error: the largest end-position difference of any body's frame origin (m), divided by rtol.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>

#include <nlohmann/json.hpp>

#include "simulation/integrator_choice.hpp"
#include "simulation/simulation.hpp"
#include "simulation/tolerances.hpp"
#include "scene/scene.hpp"

using namespace flexmbd;
using nlohmann::json;

namespace {

json governorJson() {
  std::ifstream in(std::string(FLEXMBD_SOURCE_DIR) + "/examples/flyball_governor.json");
  EXPECT_TRUE(in.good());
  return json::parse(in);
}

/// The free governor: no motor; every velocity of the file's steady rotation (a rigid
/// rotation about z, so velocities scale with the speed) scaled to `speed` rad/s; outputs
/// every 0.01 s (Nyquist frequency 314 rad/s) over t_end 2 s. `scaleForces`: k and c x it.
json freeGovernor(double speed = 2.0 * M_PI, double scaleForces = 1.0) {
  json j = governorJson();
  const double f = speed / j["drivers"][0]["law"]["speed"].get<double>();
  for (auto& b : j["bodies"]) {
    for (const char* key : {"velocity", "angular_velocity"}) {
      if (b.contains(key)) {
        for (auto& x : b[key]) x = x.get<double>() * f;
      }
    }
  }
  j.erase("drivers");
  for (auto& force : j["forces"]) {
    force["stiffness"] = force["stiffness"].get<double>() * scaleForces;
    force["damping"] = force["damping"].get<double>() * scaleForces;
  }
  j["solver"]["t_end"] = 2.0;
  j["solver"]["output_step"] = 0.01;
  return j;
}

struct EndState {
  VecX positions;  ///< x, y, z of every body's frame origin at t_end
  SimulationSummary summary;
};

/// Runs `j` as `flexmbd run --rtol R [--atol A]` would (overrideTolerances), with the
/// integrator `integrator` ("" keeps the scene's, auto).
EndState run(json j, double rtol, std::optional<double> atol = std::nullopt, const std::string& integrator = "") {
  if (!integrator.empty()) j["solver"]["integrator"] = integrator;
  Scene s = parseScene(j);
  s.solver.progress = false;
  overrideTolerances(s.solver, rtol, atol);
  VecX last;
  EndState e;
  e.summary = simulate(s.system, s.solver, [&](const OutputSample& o) { last = o.q; });
  EXPECT_TRUE(e.summary.ok) << e.summary.message;
  e.positions.resize(3 * s.system.numBodies());
  for (int b = 0; b < s.system.numBodies(); ++b) {
    const int off = s.system.coordinateOffset(BodyIndex{b});
    e.positions.segment<3>(3 * b) = last.segment<3>(off);  // spatial bodies: x, y, z, then the quaternion
  }
  return e;
}

double endError(const EndState& a, const EndState& ref) { return (a.positions - ref.positions).cwiseAbs().maxCoeff(); }

const EndState& reference() {
  static const EndState ref = run(freeGovernor(), 1e-11, 1e-13, "radau");
  return ref;
}

}  // namespace

TEST(StiffSpatialAccuracy, ReferenceIsConverged) {
  const EndState tighter = run(freeGovernor(), 1e-12, 1e-14, "radau");
  const double d = endError(reference(), tighter);
  std::printf("[ measured ] free A05 governor: radau rtol 1e-11 vs 1e-12 at t = 2 s: %.2e m\n", d);
  // 1e-9 m: 100 times below the smallest error bounded below (the default at rtol 1e-8 is
  // allowed 1e-6 m; radau5 was measured at 7.8e-9 m) and ~50 times the measured difference.
  EXPECT_LE(d, 1e-9);
}

TEST(StiffSpatialAccuracy, AutoChoosesRadau5ForTheStiffGovernor) {
  Scene s = parseScene(freeGovernor());
  const IntegratorChoice c = chooseIntegrator(s.system, s.solver);
  const FastestRate fast = fastestLinearRate(s.system, s.solver);
  std::printf("[ measured ] free A05 governor: fastest linearised eigenvalue %.4g /s (damping ratio %.3g)\n",
              fast.omega, fast.dampingRatio);
  EXPECT_EQ(c.kind, IntegratorKind::Radau5) << c.reason;
  // the overdamped sleeve-spring mode, -c / m of the 3 kg sleeve and the arms: measured
  // 8,120 /s, 26 times the output Nyquist frequency 314 rad/s (the bound: a factor 10)
  EXPECT_GT(fast.omega, 10.0 * outputNyquistFrequency(s.solver));
  // the soft variant (k and c / 100: fastest |s| 45 /s, below 314 rad/s) keeps IDA, whose
  // error there was measured at 80 / 147 times rtol 1e-6 / 1e-8
  Scene soft = parseScene(freeGovernor(2.0 * M_PI, 0.01));
  EXPECT_EQ(chooseIntegrator(soft.system, soft.solver).kind, IntegratorKind::Ida);
}

TEST(StiffSpatialAccuracy, DefaultEndErrorIsWithinAHundredTimesTheTolerance) {
  // rtol 1e-6 and 1e-8, atol following as the command line scales it (rtol / 100).
  // Measured (radau5, chosen by auto): 4.2e-5 m (42 x rtol) and 7.8e-9 m (0.8 x); IDA, the
  // default before: 9.6e-4 m (956 x) and 8.5e-6 m (852 x). kRatio 100: the bound.
  constexpr double kRatio = 100.0;
  for (double rtol : {1e-6, 1e-8}) {
    const EndState e = run(freeGovernor(), rtol);
    const double err = endError(e, reference());
    std::printf("[ measured ] free A05 governor, default (%s), rtol %.0e: end error %.2e m = %.1f x rtol, %ld steps\n",
                toString(e.summary.integrator).c_str(), rtol, err, err / rtol, e.summary.stats.steps);
    EXPECT_EQ(e.summary.integrator, IntegratorKind::Radau5);
    EXPECT_LE(err, kRatio * rtol);
  }
}

TEST(StiffSpatialAccuracy, IdaErrorIsThePhaseOfTheFreeSpin) {
  // The cause, pinned: IDA given explicitly on the free governor ends hundreds of times rtol
  // off (measured 852 x at rtol 1e-8), while on the same governor driven at 2 pi rad/s (the
  // spin's phase prescribed, everything else as stiff) it stays near rtol (measured 9 x).
  const double rtol = 1e-8;
  const EndState freeIda = run(freeGovernor(), rtol, std::nullopt, "ida");
  const double free = endError(freeIda, reference()) / rtol;
  // the run says so: IDA given on a stiff model warns in summary.json
  bool warned = false;
  for (const std::string& w : freeIda.summary.warnings) warned = warned || w.find("ida on a stiff model") == 0;
  EXPECT_TRUE(warned);
  json driven = governorJson();
  driven["drivers"][0]["law"]["speed"] = 2.0 * M_PI;
  driven["solver"]["output_step"] = 0.01;
  const EndState dIda = run(driven, rtol, std::nullopt, "ida");
  const EndState dRef = run(driven, 1e-11, 1e-13, "radau");
  const double drivenRatio = endError(dIda, dRef) / rtol;
  std::printf("[ measured ] IDA at rtol 1e-8: free governor %.0f x rtol, driven governor %.1f x rtol\n", free,
              drivenRatio);
  // 200 x: well above the 100 x and 4 times below the measured 852 (the cause
  // stands); 50 x for the driven one: 5 times the measured 9 (it is not the stiffness alone).
  EXPECT_GT(free, 200.0);
  EXPECT_LT(drivenRatio, 50.0);
}
