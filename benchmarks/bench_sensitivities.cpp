// Benchmark: the cost of forward sensitivities. CPU of a plain IDA run and of
// runs with p = 1, 2, 4 parameters (IDAS, staggered corrector, sensitivity error control
// on; and p = 4 with it off), each as a ratio to the plain run, against the target of about 1 + 0.5 p
// runs. Models: the rigid slider crank (examples/slider_crank_rigid.json, 10 revolutions)
// and the elastic one (examples/slider_crank_elastic.json, 8 nodal beam elements, 1
// revolution at 150 rad/s). Each figure is the smallest CPU time of `--repeat` runs (the
// machine is shared: the minimum is the least disturbed); outputs are formed as the
// command line forms them (results row, and its derivative columns).
//
// Usage: bench_sensitivities [--repeat N]
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench_common.hpp"
#include "sensitivity/sensitivity_run.hpp"
#include "results/results_writer.hpp"
#include "results/sensitivity_results.hpp"

using namespace flexmbd;

namespace {

using bench::bestOf;
using bench::readText;

double cpuSince(double start) { return bench::cpuSeconds() - start; }

struct Figures {
  double seconds = 0.0;
  long steps = 0;
};

Figures plainRun(const std::string& text) {
  Scene s = parseSceneText(text);
  s.solver.progress = false;
  s.solver.integrator = IntegratorKind::Ida;
  const std::vector<std::string> columns = resultColumns(s);
  std::vector<double> row;
  const double start = bench::cpuSeconds();
  const SimulationSummary summary =
      simulate(s.system, s.solver, [&](const OutputSample& o) { resultRow(s, columns, o, row); });
  return {cpuSince(start), summary.stats.steps};
}

Figures sensitivityRun(const std::string& text, const std::vector<std::string>& paths, bool errorControl = true) {
  Scene s = parseSceneText(text);
  s.solver.progress = false;
  const SensitivityScenes perturbed = buildSensitivityScenes(text, "<scene>", s, paths);
  const std::vector<std::string> columns = resultColumns(s);
  std::vector<double> row, d;
  const double start = bench::cpuSeconds();
  const SimulationSummary summary = simulateWithSensitivities(
      s.system, perturbed.parameters, s.solver, {errorControl}, [&](const OutputSample& o, const SensitivitySample& sens) {
        resultRow(s, columns, o, row);
        sensitivityRow(perturbed, columns, sens, d);
      });
  return {cpuSince(start), summary.stats.steps};
}

void benchmark(const char* name, const std::string& text, const std::vector<std::string>& parameters, int repeat) {
  const Figures plain = bestOf(repeat, [&] { return plainRun(text); });
  std::printf("%-22s p = 0: %8.4f s CPU, %6ld steps (plain IDA run)\n", name, plain.seconds, plain.steps);
  for (const std::size_t p : {1u, 2u, 4u}) {
    const std::vector<std::string> paths(parameters.begin(), parameters.begin() + static_cast<long>(p));
    const Figures f = bestOf(repeat, [&] { return sensitivityRun(text, paths); });
    std::printf("%-22s p = %zu: %8.4f s CPU, %6ld steps, %5.2f plain runs (target 1 + 0.5 p = %.1f)\n", name, p,
                f.seconds, f.steps, f.seconds / plain.seconds, 1.0 + 0.5 * static_cast<double>(p));
  }
  // the same with the sensitivities out of the error test: the plain run's steps
  const Figures off = bestOf(repeat, [&] { return sensitivityRun(text, parameters, false); });
  std::printf("%-22s p = %zu: %8.4f s CPU, %6ld steps, %5.2f plain runs (sensitivities out of the error test)\n", name,
              parameters.size(), off.seconds, off.steps, off.seconds / plain.seconds);
}

}  // namespace

int main(int argc, char** argv) {
  int repeat = 3;
  for (int k = 1; k + 1 < argc; ++k) {
    if (std::strcmp(argv[k], "--repeat") == 0) repeat = std::max(1, std::atoi(argv[k + 1]));
  }
  nlohmann::json rigid = nlohmann::json::parse(readText(std::string(FLEXMBD_SOURCE_DIR) + "/examples/slider_crank_rigid.json"));
  rigid["solver"]["t_end"] = 10 * 6.283185307179586;
  benchmark("rigid slider crank", rigid.dump(), {"bodies[2].mass", "joints[2].points[0][0]", "bodies[1].mass", "bodies[1].inertia"},
            repeat);
  nlohmann::json elastic =
      nlohmann::json::parse(readText(std::string(FLEXMBD_SOURCE_DIR) + "/examples/slider_crank_elastic.json"));
  elastic["solver"]["t_end"] = 0.041887902047863905;
  benchmark("elastic slider crank", elastic.dump(),
            {"bodies[2].mass", "bodies[1].section.youngs_modulus", "bodies[1].section.height", "bodies[0].mass"}, repeat);
  return 0;
}
