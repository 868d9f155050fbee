// Benchmark: cost of a spatial flexible body against its mesh.
// examples/spatial_slider_crank_elastic.json with its rod meshed by 8, 16, ..., N spatial
// beam elements (nodal, or reduced to --modes modes), integrated from t = 0 over --span
// (default 0.01 s as in the issue) at rtol 1e-6, atol 1e-8 (the scene's), GGL, KLU, by
// IDA and by Radau IIA: CPU time per step, per residual, per Jacobian and per simulated
// second against the number of unknowns of the DAE, and the exponent of a least-squares
// fit in log-log. Set-up (consistent initial state, DAE pattern, the first output) is
// timed apart (CPU time up to the output at t = 0) and not in the per-step figures. Peak memory (VmHWM of the process) is printed after each case; cases
// run in increasing size, so it grows with the largest mesh run so far.
#include <cstdio>
#include <fstream>

#include <nlohmann/json.hpp>

#include "benchmarks/bench_common.hpp"
#include "benchmarks/bench_scenes.hpp"
#include "core/dae_system.hpp"
#include "core/system_evaluation.hpp"
#include "simulation/simulation.hpp"
#include "scene/scene.hpp"

using namespace flexmbd;
using namespace flexmbd::bench;

namespace {


/// Peak resident memory of this process [MB] (Linux /proc/self/status, VmHWM).
double peakMemoryMb() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  }
  return NAN;
}

/// The example scene with `elements` rod elements (and `modes` modes if > 0).
Scene sceneWith(int elements, int modes, double span, IntegratorKind kind) {
  nlohmann::json j = testmodels::spatialElasticCrankJson(elements, modes);
  j["solver"]["t_end"] = span;
  j["solver"]["output_step"] = span;
  j["solver"]["integrator"] = toString(kind);
  j["solver"]["max_steps"] = 100000000;
  j["outputs"] = nlohmann::json::array();
  Scene s = parseScene(j);
  s.solver.progress = false;
  return s;
}

struct Row {
  std::string fills;  ///< nnz(L + U) per KLU ordering candidate (orderingFills)
  int elements = 0, size = 0;
  double cpu = 0, setup = 0, perStep = 0, perResidual = 0;  ///< cpu: integration only
  IntegratorStats stats;
  bool ok = false;
};

Row runCase(int elements, int modes, double span, IntegratorKind kind, int repeat) {
  Row r;
  r.elements = elements;
  std::vector<double> cpu, setup;
  for (int rep = 0; rep < repeat; ++rep) {
    Scene s = sceneWith(elements, modes, span, kind);
    r.size = DaeSystem(s.system, s.solver.formulation).layout().size;
    if (r.fills.empty()) r.fills = orderingFills(s.system);  // untimed
    const TimedRun t = timedSimulate(s.system, s.solver);
    setup.push_back(t.setup);
    cpu.push_back(t.integration);
    r.ok = t.summary.ok;
    r.stats = t.summary.stats;
  }
  r.cpu = median(cpu);
  r.setup = median(setup);
  r.perStep = r.cpu / std::max(1L, r.stats.steps);
  r.perResidual = r.cpu / std::max(1L, r.stats.residualEvals);
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  Options opt("bench_spatial_scaling",
              "Spatial elastic slider crank, rod of 8 to N spatial beam elements: CPU per step and per simulated "
              "second against the DAE size, fitted exponent, by integrator.",
              1);
  int maxElements = 128, minElements = 8, modes = 0;
  double span = 0.01;
  std::vector<std::string> integratorNames;
  opt.addInt("--max-elements", "largest mesh (default 128; powers of two from --min-elements)", &maxElements);
  opt.addInt("--min-elements", "smallest mesh (default 8)", &minElements);
  opt.addInt("--modes", "reduce the rod to this many normal modes (default 0: nodal)", &modes);
  opt.addDouble("--span", "simulated time from t = 0 [s] (default 0.01)", &span);
  opt.addList("--integrator", "ida, radau5 (default both)", &integratorNames);
  opt.parse(argc, argv);
  if (opt.quick) {
    maxElements = std::min(maxElements, 16);
    span = std::min(span, 1e-3);
  }
  std::vector<IntegratorKind> kinds;
  for (const std::string& n : integratorNames) kinds.push_back(parseIntegrator(n));
  if (kinds.empty()) kinds = {IntegratorKind::Ida, IntegratorKind::Radau5};
  CsvWriter csv(opt.csvPath("bench_spatial_scaling.csv"),
                {"integrator", "elements", "modes", "dae_size", "steps", "residuals", "jacobians", "setup_seconds",
                 "cpu_seconds",
                 "us_per_step", "us_per_residual_eval", "cpu_per_simulated_second", "peak_mb", "ok", "factor_nnz_klu_mult_frames"});
  std::printf("Spatial elastic slider crank (examples/spatial_slider_crank_elastic.json), rod %s, span %g s, "
              "rtol 1e-6, GGL, KLU; CPU per step includes residuals, Jacobians, factorisations and solves\n",
              modes > 0 ? (std::to_string(modes) + " modes").c_str() : "nodal", span);
  std::printf("%-7s %5s %6s %8s %8s %6s %9s %9s %11s %11s %12s %8s\n", "integr.", "elem", "size", "steps", "resid.",
              "jac.", "setup [s]", "cpu [s]", "us/step", "us/resid.", "s/sim. s", "peak MB");
  for (IntegratorKind kind : kinds) {
    std::vector<double> lx, ly;
    for (int n = minElements; n <= maxElements; n *= 2) {
      const Row r = runCase(n, modes, span, kind, opt.repeat);
      const double mb = peakMemoryMb();
      std::printf("%-7s %5d %6d %8ld %8ld %6ld %9.3f %9.3f %11.1f %11.2f %12.4g %8.1f%s\n", toString(kind).c_str(), n,
                  r.size, r.stats.steps, r.stats.residualEvals, r.stats.jacobianEvals, r.setup, r.cpu, 1e6 * r.perStep,
                  1e6 * r.perResidual, r.cpu / span, mb, r.ok ? "" : "  (failed)");
      std::printf("        nnz(L + U) klu / camd multipliers last / camd frames and multipliers last: %s\n",
                  r.fills.c_str());
      std::fflush(stdout);
      csv.row({toString(kind), std::to_string(n), std::to_string(modes), std::to_string(r.size),
               std::to_string(r.stats.steps), std::to_string(r.stats.residualEvals),
               std::to_string(r.stats.jacobianEvals), fmt(r.setup), fmt(r.cpu), fmt(1e6 * r.perStep), fmt(1e6 * r.perResidual),
               fmt(r.cpu / span), fmt(mb), r.ok ? "1" : "0", r.fills});
      lx.push_back(std::log(r.size));
      ly.push_back(std::log(r.perStep));
    }
    if (lx.size() >= 2) {
      const double b = fitLine(lx, ly).second;
      std::printf("%s: CPU per step ~ size^%.2f (%zu meshes)\n", toString(kind).c_str(), b, lx.size());
      csv.comment(toString(kind) + " exponent_per_step," + fmt(b, "%.4f"));
    }
  }
  std::printf("CSV written to %s\n", csv.path().c_str());
  return 0;
}
