// Benchmark: Simeon's flexible slider crank (Bari IVP test set "crank"), the field's
// standard work-precision test of flexible multibody integrators. Tolerance sweep; per
// configuration the accuracy scd (significant correct digits of the positions at t = 0.1
// against the published reference), the CPU time of the integration, and the solver's
// statistics; then the CPU time to reach scd 3, 5 and 7 (log time interpolated linearly
// in scd) as ratios to the hand-coded equations under IDA, all from one run.
//
// Configurations: the engine's model of the mechanism (examples/bari_slider_crank.json,
// the general engine with no per-problem tuning: rtol = atol = tol as in the classic
// codes' runs, the elastic coordinates' atol in the scene's ratio to atol) under IDA (GGL, index 1) and Radau IIA, and the hand-coded equations of
// the test set (problems/bari_crank.*) under the same integrators.
#include <time.h>

#include <cmath>
#include <cstdio>
#include <map>

#include "benchmarks/bench_common.hpp"
#include "problems/bari_crank.hpp"
#include "integrators/initial_conditions.hpp"
#include "integrators/radau_solver.hpp"
#include "scene/scene.hpp"

using namespace flexmbd;
using namespace flexmbd::bench;

namespace {

struct Config {
  std::string name;
  bool engine = true;
  Formulation formulation = Formulation::Ggl;
  IntegratorKind integrator = IntegratorKind::Ida;
  RadauStages stages{};  // the Radau IIA orders (integrator Radau5 or Radau)
};

struct Run {
  std::vector<double> cpu;
  double scd = std::nan("");
  IntegratorStats stats;
  bool ok = true;
  std::string message;
};

/// The engine's model, consistent initial values and the offsets of the six positions.
struct EngineModel {
  Scene scene;
  ConsistentState init;
  int rodOffset = 0, sliderOffset = 0;
  explicit EngineModel(const std::string& path) : scene(loadScene(path)) {
    const System& sys = scene.system;
    init = computeConsistentState(sys, 0.0, sys.initialCoordinates(), sys.initialVelocities());
    rodOffset = sys.coordinateOffset(sys.findBody("rod"));
    sliderOffset = sys.coordinateOffset(sys.findBody("slider"));
  }
  std::array<double, 6> positions(const VecX& y) const {
    return {y[rodOffset + 2], y[sliderOffset], y[rodOffset + 3], y[rodOffset + 4], y[rodOffset + 5], y[rodOffset + 6]};
  }
};

/// One timed integration from 0 to 0.1; CPU seconds of set-up + integration.
double integrate(const DaeProblem& dae, const Config& c, const VecX& y0, const VecX& yp0,
                 const IntegratorOptions& o, VecX& yEnd, IntegratorStats& stats) {
  const double c0 = cpuSeconds();
  const bool radau = c.integrator == IntegratorKind::Radau5 || c.integrator == IntegratorKind::Radau;
  const auto integrator = radau ? std::make_unique<RadauSolver>(dae, 0.0, y0, yp0, o, c.stages)
                                : makeIntegrator(c.integrator, dae, 0.0, y0, yp0, o);
  integrator->advance(bari::kEndTime, bari::kEndTime);
  const double c1 = cpuSeconds();
  yEnd = integrator->y();
  stats = integrator->stats();
  return c1 - c0;
}

/// CPU time to reach `target` scd: log time linear in scd between the two runs of
/// neighbouring tolerances that bracket it (the first crossing from loose to tight).
double timeToReach(const std::vector<std::pair<double, double>>& scdTime, double target) {
  for (std::size_t k = 0; k < scdTime.size(); ++k) {
    const auto [s1, t1] = scdTime[k];
    if (!(s1 >= target)) continue;
    if (k == 0) return t1;  // the loosest tolerance already reaches it
    const auto [s0, t0] = scdTime[k - 1];
    if (!(s0 < target) || !(s1 > s0)) return t1;
    const double a = (target - s0) / (s1 - s0);
    return std::exp(std::log(t0) + a * (std::log(t1) - std::log(t0)));
  }
  return std::nan("");
}

}  // namespace

int main(int argc, char** argv) {
  Options opt("bench_bari_crank",
              "Simeon's flexible slider crank: scd and CPU time per tolerance, engine and hand-coded equations, "
              "IDA and Radau IIA; time to reach scd 3, 5, 7 as ratios to the hand-coded IDA run.",
              5);
  std::string scenePath = std::string(FLEXMBD_SOURCE_DIR) + "/examples/bari_slider_crank.json";
  double tolLoose = 1e-3, tolTight = 1e-12;
  std::vector<std::string> only;
  opt.addString("--scene", "scene of the engine's model (default examples/bari_slider_crank.json)", &scenePath);
  opt.addDouble("--tol-loose", "loosest tolerance (default 1e-3)", &tolLoose);
  opt.addDouble("--tol-tight", "tightest tolerance (default 1e-12)", &tolTight);
  double elasticMetric = kElasticStabilisationWeight;
  opt.addDouble("--ggl-elastic-metric", "weight of the elastic coordinates in the GGL stabilisation metric (default: the engine's)", &elasticMetric);
  double velocityRatio = 0.0;
  opt.addDouble("--atol-velocity-ratio",
                "atol_velocity / atol of the engine runs (default: the scene's ratio)", &velocityRatio);
  double elasticRatio = 0.0;
  opt.addDouble("--atol-elastic-ratio",
                "atol of elastic coordinates / atol of the engine runs (default: the scene's atol_elastic / atol)",
                &elasticRatio);
  opt.addList("--config", "configurations to run (default: all)", &only);
  opt.parse(argc, argv);
  if (opt.quick) {
    tolTight = std::max(tolTight, 1e-6);
    opt.repeat = 1;
  }

  std::vector<Config> configs = {
      {"engine_ggl_ida", true, Formulation::Ggl, IntegratorKind::Ida},
      {"engine_index1_ida", true, Formulation::Index1, IntegratorKind::Ida},
      {"engine_ggl_radau5", true, Formulation::Ggl, IntegratorKind::Radau5},
      {"engine_index1_radau5", true, Formulation::Index1, IntegratorKind::Radau5},
      {"hand_ida", false, Formulation::Ggl, IntegratorKind::Ida},
      {"hand_radau5", false, Formulation::Ggl, IntegratorKind::Radau5},
      {"engine_index1_radau9", true, Formulation::Index1, IntegratorKind::Radau5, {5, 5, 5}},
      {"engine_index1_radau", true, Formulation::Index1, IntegratorKind::Radau, {3, 7, 3}},
      {"engine_ggl_radau", true, Formulation::Ggl, IntegratorKind::Radau, {3, 7, 3}},
      {"hand_radau9", false, Formulation::Ggl, IntegratorKind::Radau5, {5, 5, 5}},
      {"hand_radau13", false, Formulation::Ggl, IntegratorKind::Radau5, {7, 7, 7}},
      {"hand_radau", false, Formulation::Ggl, IntegratorKind::Radau, {3, 7, 3}},
  };
  if (!only.empty()) {
    std::vector<Config> kept;
    for (const Config& c : configs) {
      if (std::find(only.begin(), only.end(), c.name) != only.end()) kept.push_back(c);
    }
    configs = kept;
  }
  std::vector<double> tols;
  for (double t = tolLoose; t >= tolTight * 0.999; t /= 10.0) tols.push_back(t);

  const EngineModel engine(scenePath);
  if (!(velocityRatio > 0.0)) velocityRatio = engine.scene.solver.atolVelocity.value_or(engine.scene.solver.atol) / engine.scene.solver.atol;
  if (!(elasticRatio > 0.0)) elasticRatio = engine.scene.solver.atolElastic.value_or(engine.scene.solver.atol) / engine.scene.solver.atol;
  VecX D = VecX::Ones(engine.scene.system.numCoordinates());
  {
    const auto kinds = engine.scene.system.coordinateKinds();
    for (int k = 0; k < D.size(); ++k) D[k] = kinds[k] == CoordinateKind::Elastic ? elasticMetric : 1.0;
  }
  const DaeSystem ggl(engine.scene.system, Formulation::Ggl, D), index1(engine.scene.system, Formulation::Index1);
  const bari::HandCodedCrank hand;
  VecX handY0, handYp0;
  bari::HandCodedCrank::initialValues(handY0, handYp0);

  std::map<std::pair<std::string, double>, Run> runs;
  for (int rep = 0; rep < opt.repeat; ++rep) {
    for (double tol : tols) {
      for (const Config& c : configs) {
        Run& r = runs[{c.name, tol}];
        if (!r.ok) continue;  // a failed configuration is not retried
        IntegratorOptions o;
        o.rtol = tol;
        o.maxSteps = 100000000;
        o.minStepSize = 1e-15;
        VecX yEnd;
        try {
          if (c.engine) {
            const DaeSystem& dae = c.formulation == Formulation::Ggl ? ggl : index1;
            SolverSettings s = engine.scene.solver;
            s.rtol = tol;
            s.atol = tol;  // as the classic codes' runs: rtol = atol = tol, elastic atol as the scene's ratio
            s.atolVelocity = velocityRatio * tol;
            s.atolAngle.reset();
            s.atolElastic = elasticRatio * tol;
            o.atol = absoluteTolerances(dae, s);
            VecX y0, yp0;
            dae.packState(engine.init.q, engine.init.v, engine.init.a, engine.init.lambda, y0, yp0);
            r.cpu.push_back(integrate(dae, c, y0, yp0, o, yEnd, r.stats));
            r.scd = bari::significantDigits(engine.positions(yEnd));
          } else {
            VecX atol = VecX::Constant(hand.size(), 1e10);  // w, lambda: algebraic
            atol.head(14).setConstant(tol);
            o.atol = atol;
            o.linearSolver = LinearSolverKind::Dense;  // 24 dense unknowns, as the classic codes
            r.cpu.push_back(integrate(hand, c, handY0, handYp0, o, yEnd, r.stats));
            r.scd = bari::significantDigits(bari::HandCodedCrank::positions(yEnd));
          }
        } catch (const std::exception& e) {
          r.ok = false;
          r.message = e.what();
        }
      }
    }
  }

  CsvWriter csv(opt.csvPath("bench_bari_crank.csv"),
                {"config", "tol", "scd", "cpu_ms", "steps", "residual_evals", "jacobian_evals", "linear_setups",
                 "error_test_failures", "conv_failures", "ok"});
  std::printf("Simeon's flexible slider crank, t in [0, 0.1]; median CPU time of %d runs (set-up + integration)\n",
              opt.repeat);
  std::printf("%-22s %8s %6s %10s %9s %9s %7s %7s %6s %6s\n", "config", "tol", "scd", "cpu_ms", "steps", "res",
              "jac", "setups", "etf", "ncf");
  std::map<std::string, std::vector<std::pair<double, double>>> curves;
  for (const Config& c : configs) {
    for (double tol : tols) {
      const Run& r = runs[{c.name, tol}];
      const double ms = r.cpu.empty() ? std::nan("") : 1e3 * median(r.cpu);
      if (r.ok) curves[c.name].push_back({r.scd, ms});
      std::printf("%-22s %8.0e %6.2f %10.3f %9ld %9ld %7ld %7ld %6ld %6ld%s\n", c.name.c_str(), tol,
                  r.ok ? r.scd : std::nan(""), ms, r.stats.steps, r.stats.residualEvals, r.stats.jacobianEvals,
                  r.stats.linearSetups, r.stats.errorTestFailures, r.stats.nonlinearConvFailures,
                  r.ok ? "" : ("  FAILED: " + r.message).c_str());
      csv.row({c.name, sci(tol), fmt(r.scd), fmt(ms), std::to_string(r.stats.steps),
               std::to_string(r.stats.residualEvals), std::to_string(r.stats.jacobianEvals),
               std::to_string(r.stats.linearSetups), std::to_string(r.stats.errorTestFailures),
               std::to_string(r.stats.nonlinearConvFailures), r.ok ? "1" : "0"});
    }
  }
  std::printf("\nCPU ms to reach scd 3 / 5 / 7 (ratio to hand_ida)\n");
  const auto& base = curves["hand_ida"];
  for (const Config& c : configs) {
    std::printf("%-22s", c.name.c_str());
    for (double target : {3.0, 5.0, 7.0}) {
      const double t = timeToReach(curves[c.name], target), tb = timeToReach(base, target);
      std::printf("  %9.3f (%6.3f)", t, t / tb);
      csv.comment(c.name + " scd " + fmt(target) + ": " + fmt(t) + " ms, ratio " + fmt(t / tb));
    }
    std::printf("\n");
  }
  std::printf("\nCSV: %s\n", csv.path().c_str());
  return 0;
}
