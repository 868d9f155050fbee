// Benchmark: solver and model variants side by side, as ratios to the default (GGL,
// analytic Jacobian, automatic linear solver = KLU here, nodal model): formulations
// (GGL, index 3, index 1), dense LU against KLU, finite-difference Jacobian (dense
// only), nodal against modal (2 and 4 modes). Scenes: the rigid slider-crank (one
// revolution, rtol 1e-8) and the elastic slider-crank with 8 elements (one revolution,
// rtol 1e-6); atol = rtol/100.
//
// A binary of its own (not a flag of bench_work_precision): it times a few cases many
// times, interleaved round-robin so that machine noise hits all variants alike, and
// reports medians and ratios, while the work-precision sweep times many cases once.
#include <cstdio>

#include "benchmarks/bench_common.hpp"
#include "benchmarks/bench_scenes.hpp"

using namespace flexmbd;
using namespace flexmbd::bench;

namespace {

struct Variant {
  std::string name;
  Formulation formulation = Formulation::Ggl;
  LinearSolverKind solver = LinearSolverKind::Automatic;
  bool fdJacobian = false;
  int modes = 0;
  double initialStep = 0.0;  ///< SolverSettings::initialStepSize (0: IDA's estimate)
};

struct Result {
  std::vector<double> times, ratios;
  SimulationSummary summary;
  std::vector<Probe> probes;
  int size = 0;
};

}  // namespace

int main(int argc, char** argv) {
  Options opt("bench_variants",
              "Formulations, Jacobians, linear solvers and modal reduction as ratios to the default, "
              "repeats interleaved.", 5);
  std::vector<std::string> scenes;
  double revolutions = 1.0, rtolRigid = 1e-8, rtolElastic = 1e-6;
  opt.addList("--scene", "rigid_slider_crank, elastic_slider_crank (default: both)", &scenes);
  opt.addDouble("--revolutions", "crank revolutions of the elastic slider-crank (default 1)", &revolutions);
  opt.addDouble("--rtol-rigid", "rtol of the rigid slider-crank (default 1e-8)", &rtolRigid);
  opt.addDouble("--rtol-elastic", "rtol of the elastic slider-crank (default 1e-6)", &rtolElastic);
  opt.parse(argc, argv);
  if (opt.quick) {
    revolutions = std::min(revolutions, 0.125);
    opt.repeat = std::min(opt.repeat, 2);
  }
  if (scenes.empty()) scenes = {"rigid_slider_crank", "elastic_slider_crank"};

  CsvWriter csv(opt.csvPath("bench_variants.csv"),
                {"scene", "variant", "rtol", "median_seconds", "time_ratio", "steps", "residual_evals",
                 "jacobian_evals", "linear_setups", "dae_size", "error", "diff_vs_default", "ok", "repeats"});
  std::printf("Variants as ratios to the default (GGL, analytic Jacobian, auto linear solver, nodal);\n"
              "%d rounds, each running every variant once (round-robin); time: median of simulate() wall times; "
              "ratio: median over the rounds of t_variant / t_default in the same round.\n", opt.repeat);
  for (const std::string& sceneName : scenes) {
    BenchModel model;
    double rtol = 0;
    std::vector<Variant> variants = {
        {"ggl/auto/analytic (default)"},
        {"ggl/klu/analytic", Formulation::Ggl, LinearSolverKind::Klu},
        {"ggl/dense/analytic", Formulation::Ggl, LinearSolverKind::Dense},
        {"ggl/dense/fd-jacobian", Formulation::Ggl, LinearSolverKind::Dense, true},
        {"index3/auto/analytic", Formulation::Index3},
        {"index1/auto/analytic", Formulation::Index1},
    };
    if (sceneName == "rigid_slider_crank") {
      model = rigidSliderCrank();
      rtol = rtolRigid;
    } else if (sceneName == "elastic_slider_crank") {
      model = elasticSliderCrank(8, 0, revolutions, "elastic_slider_crank");
      rtol = rtolElastic;
      // IDA's first-step estimate (~1/|y'|, accelerations of 5000 m/s^2) is ~1e-14 s here,
      // where the index-3 iteration matrix (condition ~ cj^2) is numerically singular
      variants.push_back({"index3/auto/analytic, initial_step 1e-7", Formulation::Index3, LinearSolverKind::Automatic,
                          false, 0, 1e-7});
      variants.push_back({"ggl/auto/analytic, 2 modes", Formulation::Ggl, LinearSolverKind::Automatic, false, 2});
      variants.push_back({"ggl/auto/analytic, 4 modes", Formulation::Ggl, LinearSolverKind::Automatic, false, 4});
    } else {
      std::fprintf(stderr, "bench_variants: unknown scene '%s'\n", sceneName.c_str());
      return 2;
    }
    std::vector<Result> results(variants.size());
    {  // one untimed run first: the first run of a process pays for cold caches and lazy loading
      Scene s = model.build(rtol, atolFor(rtol));
      runModel(model, s);
    }
    for (int round = 0; round < opt.repeat; ++round) {
      for (std::size_t i = 0; i < variants.size(); ++i) {
        const Variant& v = variants[i];
        const BenchModel m = v.modes ? elasticSliderCrank(8, v.modes, revolutions, model.group) : model;
        Scene s = m.build(rtol, atolFor(rtol));
        s.solver.formulation = v.formulation;
        s.solver.linearSolver = v.solver;
        s.solver.finiteDifferenceJacobian = v.fdJacobian;
        s.solver.initialStepSize = v.initialStep;
        RunResult r = runModel(m, s);
        results[i].times.push_back(r.seconds);
        results[i].ratios.push_back(r.seconds / results[0].times.back());
        results[i].summary = r.summary;
        results[i].probes = std::move(r.probes);
        results[i].size = r.size;
        if (!r.summary.ok) std::fprintf(stderr, "%s failed: %s\n", v.name.c_str(), r.summary.message.c_str());
      }
    }
    std::printf("\n== %s, %g s, rtol %.0e, atol %.0e; positions: %s\n", sceneName.c_str(), model.span, rtol,
                atolFor(rtol), model.positionsDoc.c_str());
    std::printf("error: max over checkpoints of |p - p_ref| / L against %s; diff: the same against the default "
                "variant\n", model.exact ? "the closed form" : "- (no closed form here; see bench_work_precision)");
    std::printf("%-30s %10s %7s %8s %8s %7s %7s %5s %9s %9s\n", "variant", "time [s]", "ratio", "steps", "res", "jac",
                "setups", "size", "error", "diff");
    std::vector<std::vector<double>> exact, base;
    for (const Probe& p : results[0].probes) base.push_back(p.positions);
    if (model.exact) {
      for (int k = 0; k <= model.checkpoints; ++k) exact.push_back(model.exact(model.span * k / model.checkpoints));
    }
    for (std::size_t i = 0; i < variants.size(); ++i) {
      const Result& r = results[i];
      const IntegratorStats& st = r.summary.stats;
      const double err = model.exact ? positionError(model, r.probes, exact) : NAN;
      const double diff = i ? positionError(model, r.probes, base) : 0.0;
      const double t = median(r.times), ratio = median(r.ratios);
      std::printf("%-30s %10.4f %7.3f %8ld %8ld %7ld %7ld %5d %9s %9s%s\n", variants[i].name.c_str(), t, ratio,
                  st.steps, st.residualEvals, st.jacobianEvals, st.linearSetups, r.size, sci(err).c_str(),
                  sci(diff).c_str(), r.summary.ok ? "" : "  FAILED");
      csv.row({sceneName, variants[i].name, fmt(rtol, "%.0e"), fmt(t), fmt(ratio, "%.4f"), std::to_string(st.steps),
               std::to_string(st.residualEvals), std::to_string(st.jacobianEvals), std::to_string(st.linearSetups),
               std::to_string(r.size), fmt(err, "%.6e"), fmt(diff, "%.6e"), r.summary.ok ? "1" : "0",
               std::to_string(r.times.size())});
    }
  }
  std::printf("\nCSV written to %s\n", csv.path().c_str());
  return 0;
}
