// Benchmark: the elastic slider-crank (examples/slider_crank_elastic.json) over one
// revolution at rtol 1e-6: steps, CPU time and midpoint deflection peak for nodal models
// and modal reductions ("model only what a scene needs").
// Usage: bench_elastic_slider_crank [--repeat N] [--quick] [--csv FILE] [--out-dir DIR]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "benchmarks/bench_common.hpp"
#include "problems/ffr_test_models.hpp"

using namespace flexmbd;

int main(int argc, char** argv) {
  bench::Options opt("bench_elastic_slider_crank",
                     "Elastic slider-crank, one revolution: nodal against modal models and coarser meshes.", 3);
  opt.parse(argc, argv);
  if (opt.quick) opt.repeat = 1;
  const int repeat = opt.repeat;
  const std::string csvPath = opt.csvPath("bench_elastic_slider_crank.csv");
  struct Case {
    int N, modes;
  };
  std::vector<Case> cases = {{8, 0}, {8, 2}, {8, 4}, {2, 0}, {4, 0}};
  if (opt.quick) cases = {{2, 0}, {8, 2}};  // the 8-element nodal run alone takes seconds
  std::printf("Elastic slider-crank, one revolution (0.0419 s at 150 rad/s), rtol 1e-6, atol 1e-8, GGL, KLU\n");
  std::printf("time: median wall time of %d runs (initialisation included)\n\n", repeat);
  std::printf("%-4s %-6s %8s %8s %8s %8s %10s %14s %10s\n", "N", "modes", "unknowns", "steps", "res", "jac",
              "time [s]", "peak mid [m]", "vs N=8");
  std::ofstream csv(csvPath);
  csv << "elements,modes,dae_size,steps,residual_evals,jacobian_evals,seconds,peak_midpoint_deflection\n";
  double reference = NAN, referenceTime = NAN;
  for (const Case& c : cases) {
    std::vector<double> times;
    double peak = 0;
    SimulationSummary summary;
    int size = 0;
    for (int r = 0; r < repeat; ++r) {
      Scene s = testmodels::elasticSliderCrank(c.N, 1.0, c.modes, 1.0, 1e-6, 1e-8);
      const OutputRequest& mid = s.outputs.at(0);
      size = 2 * s.system.numCoordinates() + 2 * s.system.numConstraintEquations();
      peak = 0;
      const auto t0 = bench::Clock::now();
      summary = simulate(s.system, s.solver, [&](const OutputSample& o) {
        peak = std::max(peak, std::abs(mid.evaluate(s.system, o.q, o.v)[1]));
      });
      times.push_back(bench::secondsSince(t0));
    }
    const double t = bench::median(times);
    if (c.N == 8 && c.modes == 0) {
      reference = peak;
      referenceTime = t;
    }
    std::printf("%-4d %-6s %8d %8ld %8ld %8ld %10.4f %14.6e %9.2f%%  (time x%.3f)\n", c.N,
                c.modes ? std::to_string(c.modes).c_str() : "nodal", size, summary.stats.steps,
                summary.stats.residualEvals, summary.stats.jacobianEvals, t, peak,
                100 * (peak - reference) / reference, t / referenceTime);
    csv << c.N << "," << c.modes << "," << size << "," << summary.stats.steps << "," << summary.stats.residualEvals
        << "," << summary.stats.jacobianEvals << "," << t << "," << peak << "\n";
  }
  std::printf("\nCSV written to %s\n", csvPath.c_str());
  return 0;
}
