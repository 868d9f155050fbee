// Benchmark of the spatial flexible body: the elastic slider crank of
// examples/slider_crank_elastic.json (8 rod elements, nodal, and 2 modes) as the planar
// model and rebuilt of spatial bodies in the x-y plane with an FfrBody3d rod
// (problems/ffr3d_crank_models.hpp: revolute bearing, spherical crank pin, universal joint at
// the slider, prismatic rail, angle driver; the rod's 3D section with the planar A and
// in-plane I).
//
// (a) Cost of one residual and one Jacobian (DaeSystem::residual / jacobian with a scratch
//     of makeScratch(), the Jacobian into JacobianSink::sparse of the DAE's pattern,
//     cj = 1e6 as bench_micro) at each model's consistent initial state (t = 0, the same
//     physical state). Rounds interleave the models; a ratio spatial / planar is the
//     median over the rounds of the ratio within a round.
// (b) One revolution of each at the example's settings (rtol 1e-6, atol 1e-8): CPU time of
//     simulate(), steps, residuals, Jacobians (median of --repeat runs).
//
// Usage: bench_spatial_flexible [--rounds N] [--repeat N] [--quick] [--skip-runs]
//                               [--csv FILE] [--out-dir DIR] [--loop MODEL:KIND:N]
// --loop only makes N evaluations (KIND residual or jacobian) of one model (planar8,
// spatial8, planar2m, spatial2m) and exits: instructions per call under callgrind as the
// difference of two counts,
//   valgrind --tool=callgrind build/benchmarks/bench_spatial_flexible --loop spatial8:residual:200
// and the same with :0; (program totals' difference) / 200 is the figure of the README.
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "benchmarks/bench_common.hpp"
#include "core/dae_system.hpp"
#include "integrators/initial_conditions.hpp"
#include "simulation/simulation.hpp"
#include "problems/ffr3d_crank_models.hpp"
#include "problems/ffr_test_models.hpp"

using namespace flexmbd;
using flexmbd::bench::CsvWriter;
using flexmbd::bench::fmt;
using flexmbd::bench::median;

namespace {

double cpuNow() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

constexpr double kTime = 0.0, kCj = 1e6;

struct Model {
  std::string key, name;
  std::unique_ptr<Scene> planar;
  std::unique_ptr<test3d::ElasticCrank3d> spatial;
  std::unique_ptr<DaeSystem> dae;
  std::unique_ptr<DaeScratch> scratch;
  VecX y, yp, F;
  std::vector<double> values;
  std::vector<double> tRes, tJac;  // per round [s]
  const System& sys() const { return planar ? planar->system : spatial->sys; }
  SolverSettings solver() const {
    // the example's settings, one revolution
    Scene s = testmodels::elasticSliderCrank(8, 1.0, 0, 1.0, 1e-6, 1e-8);
    return s.solver;
  }
};

Model makeModel(const std::string& key) {
  Model m;
  m.key = key;
  const bool modal = key.find("2m") != std::string::npos;
  const int modes = modal ? 2 : 0;
  if (key.rfind("planar", 0) == 0) {
    m.name = modal ? "planar, 8 elements, 2 modes" : "planar, 8 nodal elements";
    m.planar = std::make_unique<Scene>(testmodels::elasticSliderCrank(8, 1.0, modes, 1.0, 1e-6, 1e-8));
  } else {
    m.name = modal ? "spatial, 8 elements, 2 in-plane modes" : "spatial, 8 nodal elements";
    m.spatial = test3d::planarElasticCrank3d(test3d::planarCrankRod3d(8, modes), true);
  }
  const System& sys = m.sys();
  const ConsistentState cs = computeConsistentState(sys, kTime, sys.initialCoordinates(), sys.initialVelocities());
  m.dae = std::make_unique<DaeSystem>(sys, Formulation::Ggl);
  m.dae->packState(cs.q, cs.v, cs.a, cs.lambda, m.y, m.yp);
  m.scratch = m.dae->makeScratch();
  m.F.setZero(m.dae->size());
  m.values.assign(m.dae->pattern().nonZeros(), 0.0);
  return m;
}

void residual(Model& m) { m.dae->residual(kTime, m.y.data(), m.yp.data(), m.F.data(), *m.scratch); }

void jacobian(Model& m) {
  std::fill(m.values.begin(), m.values.end(), 0.0);
  JacobianSink sink = JacobianSink::sparse(m.values.data(), m.dae->pattern());
  m.dae->jacobian(kTime, m.y.data(), m.yp.data(), kCj, sink, *m.scratch);
}

double cpuPerCall(Model& m, bool jac, int n) {
  const double c0 = cpuNow();
  for (int i = 0; i < n; ++i) jac ? jacobian(m) : residual(m);
  return (cpuNow() - c0) / n;
}

}  // namespace

int main(int argc, char** argv) {
  bench::Options opt("bench_spatial_flexible",
                     "Spatial flexible bodies: residual and Jacobian cost of the elastic slider crank with an FfrBody3d rod "
                     "against the planar rod (8 elements, nodal and 2 modes), and one revolution of each",
                     3);
  int rounds = 7;
  bool skipRuns = false;
  std::string loop;
  opt.addInt("--rounds", "interleaved timing rounds of the evaluations (default 7)", &rounds);
  opt.flag("--skip-runs", "only the evaluation costs, not the revolutions", &skipRuns);
  opt.addString("--loop", "MODEL:KIND:N: N residual or jacobian evaluations of one model, no timing (callgrind)", &loop);
  opt.parse(argc, argv);
  if (!loop.empty()) {
    const size_t a = loop.find(':'), b = loop.rfind(':');
    if (a == std::string::npos || a == b) {
      std::fprintf(stderr, "bench_spatial_flexible: --loop MODEL:KIND:N\n");
      return 2;
    }
    Model m = makeModel(loop.substr(0, a));
    const bool jac = loop.substr(a + 1, b - a - 1) == "jacobian";
    const int n = bench::Options::toInt(loop.substr(b + 1), "--loop");
    for (int i = 0; i < n; ++i) jac ? jacobian(m) : residual(m);
    return 0;
  }
  if (opt.quick) rounds = std::min(rounds, 2);
  std::vector<Model> models;
  for (const char* key : {"planar8", "spatial8", "planar2m", "spatial2m"}) models.push_back(makeModel(key));
  const int nRes = opt.quick ? 2000 : 20000, nJac = opt.quick ? 500 : 5000;
  for (Model& m : models) cpuPerCall(m, false, nRes / 10);  // warm-up
  for (int round = 0; round < rounds; ++round) {
    for (Model& m : models) {
      m.tRes.push_back(cpuPerCall(m, false, nRes));
      m.tJac.push_back(cpuPerCall(m, true, nJac));
    }
  }
  std::printf(
      "\nOne residual and one Jacobian (sparse, into the DAE's pattern, cj = 1e6) of the elastic slider crank,\n"
      "GGL, at the consistent initial state; scratch of makeScratch(); CPU time, median of %d interleaved\n"
      "rounds (%d residuals, %d Jacobians per round and model); ratio: median over the rounds of\n"
      "spatial / planar (same mesh, same reduction) within the round\n\n",
      rounds, nRes, nJac);
  std::printf("%-40s %4s %4s %4s %5s %6s %9s %9s %8s %9s %9s\n", "model", "nq", "nv", "m", "size", "nnz", "res [us]",
              "jac [us]", "jac/res", "res ratio", "jac ratio");
  CsvWriter csv(opt.csvPath("bench_spatial_flexible.csv"), {"model", "nq", "nv", "m", "dae_size", "nnz", "residual_us",
                                                            "jacobian_us", "residual_ratio", "jacobian_ratio"});
  for (size_t k = 0; k < models.size(); ++k) {
    const Model& m = models[k];
    const Model& ref = models[k - k % 2];  // the planar model of the pair
    std::vector<double> rr, rj;
    for (int r = 0; r < rounds; ++r) {
      rr.push_back(m.tRes[r] / ref.tRes[r]);
      rj.push_back(m.tJac[r] / ref.tJac[r]);
    }
    const DaeLayout& L = m.dae->layout();
    const double tr = median(m.tRes), tj = median(m.tJac);
    std::printf("%-40s %4d %4d %4d %5d %6lld %9.2f %9.2f %8.2f %9.2f %9.2f\n", m.name.c_str(), L.nq, L.nv, L.m, L.size,
                static_cast<long long>(m.dae->pattern().nonZeros()), 1e6 * tr, 1e6 * tj, tj / tr, median(rr),
                median(rj));
    csv.row({m.name, std::to_string(L.nq), std::to_string(L.nv), std::to_string(L.m), std::to_string(L.size),
             std::to_string(m.dae->pattern().nonZeros()), fmt(1e6 * tr), fmt(1e6 * tj), fmt(median(rr), "%.3f"),
             fmt(median(rj), "%.3f")});
  }
  if (!skipRuns) {
    std::printf(
        "\nOne revolution at the example's settings (rtol 1e-6, atol 1e-8, 72 outputs), CPU time of simulate(),\n"
        "median of %d runs (interleaved); ratio: spatial / planar\n\n",
        opt.repeat);
    std::printf("%-40s %9s %7s %7s %6s %6s %6s\n", "model", "CPU [s]", "steps", "res", "jac", "etf", "ratio");
    std::vector<std::vector<double>> times(models.size());
    std::vector<IntegratorStats> stats(models.size());
    for (int r = 0; r < (opt.quick ? 1 : opt.repeat); ++r) {
      for (size_t k = 0; k < models.size(); ++k) {
        if (opt.quick && models[k].key.find("2m") == std::string::npos) continue;  // nodal runs take seconds
        SolverSettings st = models[k].solver();
        st.progress = false;
        const SimulationSummary s = simulate(models[k].sys(), st, nullptr);
        times[k].push_back(s.cpuSeconds);
        stats[k] = s.stats;
      }
    }
    CsvWriter rcsv(opt.csvPath("bench_spatial_flexible_runs.csv", false),
                   {"model", "cpu_s", "steps", "residual_evals", "jacobian_evals", "error_test_failures", "ratio"});
    for (size_t k = 0; k < models.size(); ++k) {
      if (times[k].empty()) continue;
      const double t = median(times[k]), ref = median(times[k - k % 2]);
      std::printf("%-40s %9.4f %7ld %7ld %6ld %6ld %6.2f\n", models[k].name.c_str(), t, stats[k].steps,
                  stats[k].residualEvals, stats[k].jacobianEvals, stats[k].errorTestFailures, t / ref);
      rcsv.row({models[k].name, fmt(t), std::to_string(stats[k].steps), std::to_string(stats[k].residualEvals),
                std::to_string(stats[k].jacobianEvals), std::to_string(stats[k].errorTestFailures), fmt(t / ref, "%.3f")});
    }
  }
  std::printf("\nCSV written to %s\n", csv.path().c_str());
  return 0;
}
