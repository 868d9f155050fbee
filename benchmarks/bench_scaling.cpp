// Benchmark: cost against model size. The elastic slider-crank with 2, 4, 8, ..., 512
// rod elements (nodal) at rtol 1e-6 (atol 1e-8), GGL, KLU: time per step and per unit
// simulated time against the number of unknowns (DAE size), and the exponent of a
// least-squares fit in log-log from 16 elements up.
//
// Step counts grow with the mesh (the error control resolves the rod's axial modes,
// whose frequencies grow with the number of elements), so every mesh simulates the
// same short span from the start, 2e-5 s by default (--span; 0.05 % of a revolution),
// and the time per step is measured over that span. Initialisation (consistent initial
// values, DAE pattern, IDA and KLU set-up) is timed separately and not in the per-step
// figure. Times: median of --repeat runs, interleaved round-robin over the meshes.
#include <cstdio>

#include "benchmarks/bench_common.hpp"
#include "benchmarks/bench_scenes.hpp"
#include "integrators/ida_solver.hpp"
#include "integrators/initial_conditions.hpp"

#include <time.h>

using namespace flexmbd;
using namespace flexmbd::bench;

namespace {

struct Case {
  int elements = 0, nq = 0, m = 0, size = 0;
  long long nonZeros = 0;
  std::vector<double> setup, integration;
  IntegratorStats stats;
};

void runCase(Case& c, double rtol, double span, LinearSolverKind solver) {
  Scene s = testmodels::elasticSliderCrank(c.elements, 1.0, 0, 1.0, rtol, atolFor(rtol));
  const System& sys = s.system;
  const auto t0 = Clock::now();
  const ConsistentState init = computeConsistentState(sys, 0.0, sys.initialCoordinates(), sys.initialVelocities());
  const DaeSystem dae(sys, Formulation::Ggl);
  VecX y0, yp0;
  dae.packState(init.q, init.v, init.a, init.lambda, y0, yp0);
  IntegratorOptions o;
  o.rtol = rtol;
  o.atol = absoluteTolerances(dae, s.solver);
  o.maxSteps = 100000000;
  o.minStepSize = 1e-12 * span;
  o.linearSolver = solver;
  IdaSolver ida(dae, 0.0, y0, yp0, o);
  c.setup.push_back(secondsSince(t0));
  const auto t1 = Clock::now();
  ida.advance(span, span);
  c.integration.push_back(secondsSince(t1));
  c.stats = ida.stats();
  c.nq = sys.numCoordinates();
  c.m = sys.numConstraintEquations();
  c.size = dae.layout().size;
  c.nonZeros = dae.pattern().nonZeros();
}


/// Midpoint deflection of the rod at the checkpoints of one run (first entry t = 0).
struct DeflectionRun {
  std::vector<double> deflection;
  double cpu = 0.0;
  bool ok = false;
  long steps = 0;
  std::string message;
};

DeflectionRun runDeflection(int elements, IntegratorKind integrator, double rtol, double span, int checkpoints) {
  const BenchModel m = elasticSliderCrank(elements, 0, span * 150.0 / (2 * M_PI), "scaling");
  Scene s = m.build(rtol, atolFor(rtol));
  setRun(s.solver, rtol, atolFor(rtol), span, checkpoints);
  s.solver.integrator = integrator;
  s.solver.maxSteps = 100000000;
  DeflectionRun r;
  const double c0 = cpuSeconds();
  try {
    const SimulationSummary sum = simulate(s.system, s.solver, [&](const OutputSample& o) {
      r.deflection.push_back(m.probe(s, o).deflection);
    });
    r.ok = sum.ok;
    r.steps = sum.stats.steps;
    r.message = sum.message;
  } catch (const std::exception& e) {
    r.message = e.what();
    std::fprintf(stderr, "bench_scaling: %d elements, %s, rtol %.0e: %s\n", elements, toString(integrator).c_str(),
                 rtol, e.what());
  }
  r.cpu = cpuSeconds() - c0;
  return r;
}

/// Time per simulated second at a fixed accuracy: for each mesh and integrator the
/// loosest rtol (decades from 1e-3, atol = rtol/100) whose midpoint deflection is within
/// `accuracy` (relative to its largest value over the span) of a reference run of the
/// same mesh at rtol 1e-10; the exponent of that time against the DAE size.
int fixedAccuracy(const Options& opt, int minElements, int maxElements, double span, double accuracy,
                  double budget, const std::vector<IntegratorKind>& integrators) {
  const int checkpoints = 8;
  CsvWriter csv(opt.csvPath("bench_scaling_fixed_accuracy.csv"),
                {"integrator", "elements", "dae_size", "rtol", "deflection_error", "steps", "cpu_seconds",
                 "seconds_per_unit_time"});
  std::printf("Elastic slider-crank, nodal rod, GGL; first %g s; loosest rtol with midpoint deflection within %.0e "
              "(relative) of the rtol 1e-10 run of the same mesh\n", span, accuracy);
  std::printf("%-8s %6s %6s %8s %10s %9s %10s %12s\n", "integr.", "elem", "size", "rtol", "defl.err", "steps",
              "cpu [s]", "t/t_sim [s]");
  for (IntegratorKind kind : integrators) {
    std::vector<double> lx, ly;
    bool stop = false;
    for (int n = minElements; n <= maxElements && !stop; n *= 2) {
      // the reference: the tightest rtol from 1e-10 that runs (Radau IIA, else IDA)
      DeflectionRun reference;
      double refRtol = 1e-10;
      for (; refRtol <= 1e-7 && !reference.ok; refRtol *= 10) {
        for (IntegratorKind rk : {IntegratorKind::Radau5, IntegratorKind::Ida}) {
          reference = runDeflection(n, rk, refRtol, span, checkpoints);
          if (reference.ok) break;
          std::fprintf(stderr, "reference %d elements, %s, rtol %.0e failed: %s\n", n, toString(rk).c_str(), refRtol,
                       reference.message.c_str());
        }
      }
      if (!reference.ok) break;
      double peak = 0.0;
      for (double d : reference.deflection) peak = std::max(peak, std::abs(d));
      const int size = daeSize(testmodels::elasticSliderCrank(n, 1.0, 0, 1.0, 1e-6, 1e-8).system, Formulation::Ggl);
      bool met = false;
      for (double rtol = 1e-3; rtol >= 1e-9 && !met; rtol /= 10) {
        DeflectionRun r = runDeflection(n, kind, rtol, span, checkpoints);
        double err = r.ok && r.deflection.size() == reference.deflection.size() ? 0.0 : INFINITY;
        for (std::size_t k = 0; std::isfinite(err) && k < r.deflection.size(); ++k) {
          err = std::max(err, std::abs(r.deflection[k] - reference.deflection[k]) / peak);
        }
        if (err > accuracy && r.cpu < budget && rtol > 1.5e-9) continue;
        met = true;
        for (int rep = 1; rep < opt.repeat && err <= accuracy; ++rep) {
          r.cpu = std::min(r.cpu, runDeflection(n, kind, rtol, span, checkpoints).cpu);
        }
        std::printf("%-8s %6d %6d %8.0e %10.2e %9ld %10.3f %12.4g%s\n", toString(kind).c_str(), n, size, rtol, err,
                    r.steps, r.cpu, r.cpu / span, err <= accuracy ? "" : !r.ok ? ("  failed: " + r.message.substr(0, 100)).c_str() : "  (accuracy not reached within the budget or by rtol 1e-9: larger meshes skipped)");
        csv.row({toString(kind), std::to_string(n), std::to_string(size), sci(rtol), sci(err), std::to_string(r.steps),
                 fmt(r.cpu), fmt(r.cpu / span)});
        if (err <= accuracy && n >= 16) {
          lx.push_back(std::log(size));
          ly.push_back(std::log(r.cpu / span));
        }
        stop = err > accuracy || r.cpu > budget;
      }
    }
    if (lx.size() >= 2) {
      const double b = fitLine(lx, ly).second;
      std::printf("%s: time per simulated second at fixed accuracy ~ size^%.2f (%zu meshes from 16 elements)\n",
                  toString(kind).c_str(), b, lx.size());
      csv.comment(toString(kind) + " exponent_time_per_unit_time_fixed_accuracy," + fmt(b, "%.4f"));
    }
  }
  std::printf("CSV written to %s\n", csv.path().c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options opt("bench_scaling",
              "Elastic slider-crank, 2 to 512 rod elements: time per step against the DAE size, fitted exponent.", 3);
  int maxElements = 512, minElements = 2, fitFrom = 16;
  double span = 2e-5, rtol = 1e-6;
  std::string solverName = "klu";
  opt.addInt("--max-elements", "largest mesh (default 512; powers of two from --min-elements)", &maxElements);
  opt.addInt("--min-elements", "smallest mesh (default 2)", &minElements);
  opt.addInt("--fit-from", "smallest mesh in the exponent fit (default 16)", &fitFrom);
  opt.addDouble("--span", "simulated time from t = 0 [s] (default 2e-5)", &span);
  opt.addDouble("--rtol", "relative tolerance (default 1e-6; atol = rtol/100)", &rtol);
  opt.addString("--solver", "linear solver: klu, dense, auto (default klu)", &solverName);
  bool fixed = false;
  double accuracy = 1e-4, accuracySpan = 2 * M_PI / 150.0 / 8, budget = 120.0;
  std::vector<std::string> integratorNames;
  opt.flag("--fixed-accuracy", "time per simulated second at a fixed midpoint-deflection accuracy", &fixed);
  opt.addDouble("--accuracy", "relative midpoint-deflection accuracy of --fixed-accuracy (default 1e-4)", &accuracy);
  opt.addDouble("--accuracy-span", "simulated time of --fixed-accuracy (default 1/8 revolution)", &accuracySpan);
  opt.addDouble("--budget", "CPU seconds per run above which larger meshes are skipped (default 120)", &budget);
  opt.addList("--integrator", "ida, radau5 (default both) for --fixed-accuracy", &integratorNames);
  opt.parse(argc, argv);
  if (fixed) {
    std::vector<IntegratorKind> kinds;
    for (const std::string& n : integratorNames) kinds.push_back(parseIntegrator(n));
    if (kinds.empty()) kinds = {IntegratorKind::Radau5, IntegratorKind::Ida};
    if (opt.quick) maxElements = std::min(maxElements, 16);
    return fixedAccuracy(opt, std::max(8, minElements), std::min(maxElements, 256), accuracySpan, accuracy, budget,
                         kinds);
  }
  if (opt.quick) {
    maxElements = std::min(maxElements, 32);
    span = std::min(span, 1e-5);
    opt.repeat = 1;
  }
  LinearSolverKind solver;
  try {
    solver = parseLinearSolver(solverName);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_scaling: %s\n", e.what());
    return 2;
  }
  std::vector<Case> cases;
  for (int n = std::max(1, minElements); n <= maxElements; n *= 2) cases.push_back({n});
  const auto wall0 = Clock::now();
  try {
    for (int r = 0; r < opt.repeat; ++r) {
      for (Case& c : cases) runCase(c, rtol, span, solver);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_scaling: %s\n", e.what());
    return 1;
  }

  std::printf("Elastic slider-crank, nodal rod, rtol %.0e, atol %.0e, GGL, %s; first %g s simulated per mesh; "
              "median of %d runs\n", rtol, atolFor(rtol), solverName.c_str(), span, opt.repeat);
  std::printf("%6s %6s %6s %9s %8s %8s %8s %7s %7s %10s %10s %11s %11s %11s\n", "elem", "nq", "size", "nnz(J)",
              "steps", "res", "jac", "setups", "res/st", "setup [s]", "integ [s]", "t/step [us]", "steps/s_sim",
              "t/t_sim");
  CsvWriter csv(opt.csvPath("bench_scaling.csv"),
                {"elements", "nq", "constraints", "dae_size", "jacobian_nonzeros", "span", "steps", "residual_evals",
                 "jacobian_evals", "linear_setups", "setup_seconds", "integration_seconds", "seconds_per_step",
                 "steps_per_unit_time", "seconds_per_unit_time"});
  std::vector<double> lx, ly, lz;
  for (const Case& c : cases) {
    const double tInt = median(c.integration), tSetup = median(c.setup);
    const double perStep = tInt / c.stats.steps;
    std::printf("%6d %6d %6d %9lld %8ld %8ld %8ld %7ld %7.2f %10.4f %10.4f %11.2f %11.4g %11.4g\n", c.elements, c.nq,
                c.size, c.nonZeros, c.stats.steps, c.stats.residualEvals, c.stats.jacobianEvals, c.stats.linearSetups,
                static_cast<double>(c.stats.residualEvals) / c.stats.steps, tSetup, tInt, 1e6 * perStep,
                c.stats.steps / span, tInt / span);
    csv.row({std::to_string(c.elements), std::to_string(c.nq), std::to_string(c.m), std::to_string(c.size),
             std::to_string(c.nonZeros), fmt(span), std::to_string(c.stats.steps),
             std::to_string(c.stats.residualEvals), std::to_string(c.stats.jacobianEvals),
             std::to_string(c.stats.linearSetups), fmt(tSetup), fmt(tInt), fmt(perStep), fmt(c.stats.steps / span),
             fmt(tInt / span)});
    if (c.elements >= fitFrom) {
      lx.push_back(std::log(c.size));
      ly.push_back(std::log(perStep));
      lz.push_back(std::log(tInt / span));
    }
  }
  if (lx.size() >= 2) {
    const double b = fitLine(lx, ly).second, bz = fitLine(lx, lz).second;
    std::printf("\nleast-squares fit in log-log over %zu meshes from %d elements: time per step ~ size^%.3f "
                "(target <= 1.15); time per unit simulated time ~ size^%.3f\n", lx.size(), fitFrom, b, bz);
    csv.comment("exponent_time_per_step," + fmt(b, "%.4f") + ",fit_from_elements," + std::to_string(fitFrom));
    csv.comment("exponent_time_per_unit_time," + fmt(bz, "%.4f"));
  } else {
    std::printf("\n(fewer than two meshes from %d elements: no exponent fit)\n", fitFrom);
  }
  std::printf("total wall time %.1f s; CSV written to %s\n", secondsSince(wall0), csv.path().c_str());
  return 0;
}
