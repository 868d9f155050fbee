// Benchmark: the cost of adjoint sensitivities. CPU of a plain IDA run and of a
// run with the gradient of one integral output by the adjoint method (forward run, its
// segments recorded again, one backward integration with a quadrature per parameter),
// as a ratio to the plain run, for p = 1, 10 and all parameters, against the target
// of at most 5 runs for 50 parameters; and the forward sensitivities' cost for comparison.
// Models: the elastic slider crank (examples/slider_crank_elastic.json, 8 nodal beam
// elements, 1 revolution at 150 rad/s, int mid.uy^2 dt; 29 parameters: every number of the
// scene but the element count, the beam's length and the joint points on the rod (joints
// attach to its nodes), the output point's y (it must stay on the axis) and the solver's) and a chain of 10
// rigid links swinging under gravity (int tip.x^2 dt over 2 s; 50 parameters: each link's mass, inertia and
// centre of mass, each joint's two points along the links). Each figure is the smallest
// CPU time of `--repeat` runs (the machine is shared: the minimum is the least disturbed).
//
// Usage: bench_adjoint [--repeat N]
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
#include "sensitivity/adjoint_run.hpp"
#include "results/adjoint_results.hpp"
#include "results/results_writer.hpp"
#include "results/sensitivity_results.hpp"

using namespace flexmbd;
using nlohmann::json;

namespace {

using bench::bestOf;
using bench::readText;

double cpuSince(double start) { return bench::cpuSeconds() - start; }

struct Figures {
  double seconds = 0.0;
  long steps = 0, backwardSteps = 0;
  bool ok = false;
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
  return {cpuSince(start), summary.stats.steps, 0, summary.ok};
}

Figures adjointRun(const std::string& text, const std::vector<std::string>& paths, const std::string& output) {
  Scene s = parseSceneText(text);
  s.solver.progress = false;
  const SensitivityScenes perturbed = buildSensitivityScenes(text, "<scene>", s, paths);
  const std::vector<std::string> columns = resultColumns(s);
  std::vector<double> row;
  const double start = bench::cpuSeconds();
  const AdjointSummary summary =
      runAdjointScene(s, perturbed, {output}, [&](const OutputSample& o) { resultRow(s, columns, o, row); });
  if (!summary.run.ok || !summary.backwardOk) {
    std::printf("  failed: %s%s\n", summary.run.message.c_str(), summary.backwardMessage.c_str());
  }
  return {cpuSince(start), summary.run.stats.steps, summary.backwardSteps, summary.run.ok && summary.backwardOk};
}

Figures forwardRun(const std::string& text, const std::vector<std::string>& paths) {
  Scene s = parseSceneText(text);
  s.solver.progress = false;
  const SensitivityScenes perturbed = buildSensitivityScenes(text, "<scene>", s, paths);
  const std::vector<std::string> columns = resultColumns(s);
  std::vector<double> row, d;
  const double start = bench::cpuSeconds();
  const SimulationSummary summary = simulateWithSensitivities(
      s.system, perturbed.parameters, s.solver, {true}, [&](const OutputSample& o, const SensitivitySample& sens) {
        resultRow(s, columns, o, row);
        sensitivityRow(perturbed, columns, sens, d);
      });
  return {cpuSince(start), summary.stats.steps, 0, summary.ok};
}

void benchmark(const char* name, const std::string& text, const std::vector<std::string>& parameters,
               const std::string& output, int repeat) {
  const Figures plain = bestOf(repeat, [&] { return plainRun(text); });
  std::printf("%-22s plain IDA run: %8.4f s CPU, %6ld steps\n", name, plain.seconds, plain.steps);
  for (const std::size_t p : {std::size_t{1}, std::size_t{10}, parameters.size()}) {
    const std::vector<std::string> paths(parameters.begin(), parameters.begin() + static_cast<long>(p));
    const Figures f = bestOf(repeat, [&] { return adjointRun(text, paths, output); });
    std::printf("%-22s adjoint p = %2zu: %8.4f s CPU, %6ld + %6ld backward steps, %5.2f plain runs%s\n", name, p,
                f.seconds, f.steps, f.backwardSteps, f.seconds / plain.seconds, f.ok ? "" : " (FAILED)");
  }
  const std::vector<std::string> four(parameters.begin(), parameters.begin() + 4);
  const Figures f = bestOf(repeat, [&] { return forwardRun(text, four); });
  std::printf("%-22s forward p =  4: %8.4f s CPU, %6ld steps, %5.2f plain runs (for comparison)%s\n", name, f.seconds,
              f.steps, f.seconds / plain.seconds, f.ok ? "" : " (FAILED)");
}

/// A chain of `links` rigid links of 0.2 m hanging from the origin, started horizontal.
json chain(int links) {
  json j;
  j["name"] = "chain of rigid links";
  j["gravity"] = {0.0, -9.81};
  j["bodies"] = json::array();
  j["joints"] = json::array();
  const double l = 0.2;
  for (int k = 0; k < links; ++k) {
    const std::string name = "link" + std::to_string(k);
    j["bodies"].push_back({{"name", name}, {"type", "rigid"}, {"mass", 0.5 + 0.05 * k}, {"inertia", 2e-3 + 1e-4 * k},
                           {"com", {0.1, 0.0}}, {"position", {l * k, 0.0}}, {"angle", 0.0}});
    j["joints"].push_back({{"name", "J" + std::to_string(k)},
                           {"type", "revolute"},
                           {"bodies", {k == 0 ? "ground" : "link" + std::to_string(k - 1), name}},
                           {"points", {{k == 0 ? 0.0 : l, 0.0}, {0.0, 0.0}}}});
  }
  j["outputs"] = json::array({{{"type", "point"}, {"name", "tip"}, {"body", "link" + std::to_string(links - 1)},
                               {"point", {l, 0.0}}}});
  j["solver"] = {{"rtol", 1e-6}, {"atol", 1e-8}, {"t_end", 2.0}, {"output_step", 0.01}};
  return j;
}

}  // namespace

int main(int argc, char** argv) {
  int repeat = 3;
  for (int k = 1; k + 1 < argc; ++k) {
    if (std::strcmp(argv[k], "--repeat") == 0) repeat = std::max(1, std::atoi(argv[k + 1]));
  }
  json elastic = json::parse(readText(std::string(FLEXMBD_SOURCE_DIR) + "/examples/slider_crank_elastic.json"));
  std::vector<std::string> elasticParameters = {
      "bodies[1].section.youngs_modulus", "bodies[1].section.height", "bodies[2].mass", "bodies[0].mass",
      "bodies[1].section.width",          "bodies[1].section.density", "bodies[0].inertia", "bodies[2].inertia",
      "drivers[0].law.speed",             "joints[1].points[0][0]",    "bodies[0].com[0]",
      "bodies[0].com[1]",                 "bodies[1].position[0]",     "bodies[1].position[1]", "bodies[2].position[0]",
      "bodies[2].position[1]",            "outputs[0].point[0]",          "joints[3].axis[1]"};
  for (int jn = 0; jn < 4; ++jn) {
    for (int pt = 0; pt < 2; ++pt) {
      for (int c = 0; c < 2; ++c) {
        const std::string path = "joints[" + std::to_string(jn) + "].points[" + std::to_string(pt) + "][" +
                                 std::to_string(c) + "]";
        const bool onTheRod = (jn == 1 && pt == 1) || (jn == 2 && pt == 0);  // joints attach to the rod's nodes
        if (path != "joints[1].points[0][0]" && !onTheRod) elasticParameters.push_back(path);
      }
    }
  }
  benchmark("elastic slider crank", elastic.dump(), elasticParameters, "integral_square:mid.uy", repeat);
  std::vector<std::string> chainParameters;
  const int links = 10;
  for (int k = 0; k < links; ++k) {
    const std::string b = "bodies[" + std::to_string(k) + "]";
    chainParameters.insert(chainParameters.end(), {b + ".mass", b + ".inertia", b + ".com[0]"});
  }
  for (int k = 0; k < links; ++k) {
    const std::string j = "joints[" + std::to_string(k) + "]";
    chainParameters.insert(chainParameters.end(), {j + ".points[0][0]", j + ".points[1][0]"});
  }
  benchmark("chain of 10 links", chain(links).dump(), chainParameters, "integral_square:tip.x", repeat);
  return 0;
}
