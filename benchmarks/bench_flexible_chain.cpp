// Benchmark: cost of a chain of N flexible links against N. A planar
// pendulum chain: N steel links (0.3 m, 8 x 8 mm, 4 beam elements each reduced to 4 normal
// modes under pinned-pinned reference conditions) on revolute joints, the first to the
// ground at the origin, released horizontal under gravity; integrated over --span (default
// 0.05 s) at rtol 1e-6, atol 1e-8, GGL, KLU, by IDA and Radau IIA. Printed: CPU time of the
// integration (set-up apart: the CPU time up to the output at t = 0), per step and per
// simulated second, against N, and the exponents of a least-squares fit in log-log. A
// chain's equations are banded (each link couples only to its neighbours): linear cost
// in N is possible, and is what this measures.
#include <cstdio>

#include <nlohmann/json.hpp>

#include "benchmarks/bench_common.hpp"
#include "benchmarks/bench_scenes.hpp"
#include "core/dae_system.hpp"
#include "simulation/simulation.hpp"
#include "scene/scene.hpp"

using namespace flexmbd;
using namespace flexmbd::bench;

namespace {


nlohmann::json chainScene(int links, int modes, double span, IntegratorKind kind) {
  nlohmann::json j = testmodels::flexibleChainJson(links, modes);
  j["solver"] = {{"rtol", 1e-6}, {"atol", 1e-8}, {"t_end", span}, {"output_step", span},
                 {"integrator", toString(kind)}, {"max_steps", 100000000}};
  return j;
}

struct Row {
  std::string fills;  ///< nnz(L + U) per KLU ordering candidate (orderingFills)
  int size = 0;
  double setup = 0, cpu = 0;
  IntegratorStats stats;
  bool ok = false;
};

Row runCase(int links, int modes, double span, IntegratorKind kind, int repeat) {
  Row r;
  std::vector<double> cpu, setup;
  for (int rep = 0; rep < repeat; ++rep) {
    Scene s = parseScene(chainScene(links, modes, span, kind));
    s.solver.progress = false;
    r.size = DaeSystem(s.system, s.solver.formulation).layout().size;
    if (r.fills.empty()) r.fills = orderingFills(s.system);  // untimed
    const TimedRun t = timedSimulate(s.system, s.solver);
    setup.push_back(t.setup);
    cpu.push_back(t.integration);
    r.ok = t.summary.ok;
    r.stats = t.summary.stats;
  }
  r.setup = median(setup);
  r.cpu = median(cpu);
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  Options opt("bench_flexible_chain",
              "Planar pendulum chain of N flexible links (4 modes each): CPU per step and per simulated second against "
              "N, fitted exponents, by integrator.",
              1);
  int maxLinks = 32, minLinks = 2, modes = 4;
  double span = 0.05;
  std::vector<std::string> integratorNames;
  opt.addInt("--max-links", "longest chain (default 32; powers of two from --min-links)", &maxLinks);
  opt.addInt("--min-links", "shortest chain (default 2)", &minLinks);
  opt.addInt("--modes", "normal modes per link (default 4)", &modes);
  opt.addDouble("--span", "simulated time from t = 0 [s] (default 0.05)", &span);
  opt.addList("--integrator", "ida, radau5 (default both)", &integratorNames);
  opt.parse(argc, argv);
  if (opt.quick) {
    maxLinks = std::min(maxLinks, 8);
    span = std::min(span, 0.01);
  }
  std::vector<IntegratorKind> kinds;
  for (const std::string& n : integratorNames) kinds.push_back(parseIntegrator(n));
  if (kinds.empty()) kinds = {IntegratorKind::Ida, IntegratorKind::Radau5};
  CsvWriter csv(opt.csvPath("bench_flexible_chain.csv"),
                {"integrator", "links", "modes", "dae_size", "steps", "residuals", "jacobians", "setup_seconds",
                 "cpu_seconds", "us_per_step", "cpu_per_simulated_second", "ok", "factor_nnz_klu_mult_frames"});
  std::printf("Planar pendulum chain of flexible links (%d modes each), span %g s, rtol 1e-6, GGL, KLU\n", modes, span);
  std::printf("%-7s %5s %6s %8s %8s %6s %9s %9s %11s %12s\n", "integr.", "links", "size", "steps", "resid.", "jac.",
              "setup [s]", "cpu [s]", "us/step", "s/sim. s");
  for (IntegratorKind kind : kinds) {
    std::vector<double> lx, lstep, lsim;
    for (int n = minLinks; n <= maxLinks; n *= 2) {
      const Row r = runCase(n, modes, span, kind, opt.repeat);
      const double perStep = r.cpu / std::max(1L, r.stats.steps);
      std::printf("%-7s %5d %6d %8ld %8ld %6ld %9.3f %9.3f %11.1f %12.4g%s\n", toString(kind).c_str(), n, r.size,
                  r.stats.steps, r.stats.residualEvals, r.stats.jacobianEvals, r.setup, r.cpu, 1e6 * perStep,
                  r.cpu / span, r.ok ? "" : "  (failed)");
      std::printf("        nnz(L + U) klu / camd multipliers last / camd frames and multipliers last: %s\n",
                  r.fills.c_str());
      std::fflush(stdout);
      csv.row({toString(kind), std::to_string(n), std::to_string(modes), std::to_string(r.size),
               std::to_string(r.stats.steps), std::to_string(r.stats.residualEvals),
               std::to_string(r.stats.jacobianEvals), fmt(r.setup), fmt(r.cpu), fmt(1e6 * perStep),
               fmt(r.cpu / span), r.ok ? "1" : "0", r.fills});
      lx.push_back(std::log(n));
      lstep.push_back(std::log(perStep));
      lsim.push_back(std::log(r.cpu / span));
    }
    if (lx.size() >= 2) {
      const double bs = fitLine(lx, lstep).second, bt = fitLine(lx, lsim).second;
      std::printf("%s: CPU per step ~ N^%.2f, per simulated second ~ N^%.2f (%zu chains)\n", toString(kind).c_str(), bs,
                  bt, lx.size());
      csv.comment(toString(kind) + " exponent_per_step," + fmt(bs, "%.4f"));
      csv.comment(toString(kind) + " exponent_per_simulated_second," + fmt(bt, "%.4f"));
    }
  }
  std::printf("CSV written to %s\n", csv.path().c_str());
  return 0;
}
