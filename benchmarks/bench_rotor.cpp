// The rotor benchmark as EXUDYN's performance test runs it: the rotor with a
// disc of ../shared/data/exudyn-rotor (Abaqus export, 115 nodes) as an "fe_body" with 8
// free-free modes and the stiffness scaled by 0.01, a 0.1 kg unbalance on the disc's rim
// (node 10), spinning at 50 rev/s about its axis (z) on two spring-damper bearings (the
// axis nodes 78 at z = 0 and 77 at z = 0.5 held to the ground by bushings with translational
// stiffness and damping only), gravity along -y, 2 s.
//
// Reports, for each --rtol (atol = rtol * 1e-3 m): CPU time of simulate() per simulated
// second (median of --repeat runs), steps, residuals, Jacobians, and the error of the mid
// node's (node 111, z = 0.25) world displacement against a run at rtol 1e-10: the largest
// distance over the outputs (every 1 ms), relative to the largest displacement of the
// reference.
//
// EXUDYN's figure: 20,000 implicit steps of 1e-4 s, 2.74 s for the 2 s on its
// developers' machine, 4.4 to 5.4 s CPU measured on a machine like ours, a numerical
// Jacobian 41 % of it; target: at least 5 times faster per simulated second at matched
// accuracy.
//
// Usage: bench_rotor [--rtol LIST] [--repeat N] [--t-end T] [--quick] [--csv FILE] [--out-dir DIR]
// Exits 0 with "skipped" when the rotor data is absent.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "benchmarks/bench_common.hpp"
#include "bodies/ffr_body_3d.hpp"
#include "simulation/simulation.hpp"
#include "scene/scene.hpp"

using namespace flexmbd;
using flexmbd::bench::CsvWriter;
using flexmbd::bench::fmt;
using json = nlohmann::json;

namespace {

const std::string kRotorDir = std::string(FLEXMBD_SOURCE_DIR) + "/../shared/data/exudyn-rotor";
constexpr double kPi = 3.14159265358979323846;
constexpr double kSpin = 2.0 * kPi * 50.0;                 // 50 rev/s, rad/s
constexpr double kBearingStiffness = 1e6;                  // N/m per direction and bearing
constexpr double kBearingDamping = 1e3;                    // N s/m
const Vec3 kMidNode(0.0, 0.0, 0.25);                       // node 111

/// The scene (files relative to the data folder: parsed with a source there).
json rotorScene(double tEnd) {
  const json files = {
      {"input", "rotorDiscTest.inp"}, {"mass", "rotorDiscTestMASS1.mtx"}, {"stiffness", "rotorDiscTestSTIF1.mtx"}};
  const json rotor = {{"type", "fe_body"},
                      {"name", "rotor"},
                      {"abaqus", files},
                      {"modes", 8},
                      {"stiffness_scale", 0.01},
                      {"point_masses", {{{"node", 10}, {"mass", 0.1}}}},
                      {"angular_velocity", {0.0, 0.0, kSpin}}};
  auto bearing = [](const char* name, double z) {
    return json{{"type", "bushing"},
                {"name", name},
                {"bodies", {"ground", "rotor"}},
                {"world", {{"point", {0.0, 0.0, z}}}},
                {"stiffness", {kBearingStiffness, kBearingStiffness, kBearingStiffness, 0, 0, 0}},
                {"damping", {kBearingDamping, kBearingDamping, kBearingDamping, 0, 0, 0}}};
  };
  return {{"name", "rotor"},
          {"dimension", 3},
          {"gravity", {0.0, -9.81, 0.0}},
          {"bodies", {rotor}},
          {"forces", {bearing("bearing_left", 0.0), bearing("bearing_right", 0.5)}},
          {"solver", {{"t_end", tEnd}, {"output_step", 1e-3}}}};
}

struct Run {
  double cpu = 0.0;
  IntegratorStats stats;
  std::vector<Vec3> mid;  // world displacement of the mid node at each output
  bool ok = false;
  std::string message;
};

Run runOnce(const Scene& scene, double rtol) {
  const auto& rotor = dynamic_cast<const FfrBody3d&>(scene.system.body(BodyIndex(1)));
  const int node = rotor.resolvePoint(kMidNode, "bench_rotor");
  const FfrPoint3d& p = rotor.invariants().points[node];
  const int oq = scene.system.coordinateOffset(BodyIndex(1));
  const int nf = rotor.numElastic();
  SolverSettings st = scene.solver;
  st.rtol = rtol;
  st.atol = 1e-3 * rtol;
  st.progress = false;
  Run r;
  r.mid.reserve(static_cast<std::size_t>(st.tEnd / st.outputStep) + 2);
  const double c0 = bench::cpuSeconds();
  const SimulationSummary s = simulate(scene.system, st, [&](const OutputSample& o) {
    const VecX q = o.q.segment(oq, 7 + nf);
    const Vec3 x = q.head<3>() + FfrBody3d::rotationOf(q) * (p.position + p.shape * q.tail(nf));
    r.mid.push_back(x - p.position);  // the node's displacement from its undeformed place
  });
  r.cpu = bench::cpuSeconds() - c0;
  r.stats = s.stats;
  r.ok = s.ok;
  r.message = s.message;
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  bench::Options opt("bench_rotor", "EXUDYN's rotor performance test: CPU, steps and error per tolerance", 3);
  std::vector<std::string> rtols;
  double tEnd = 2.0;
  opt.addList("--rtol", "relative tolerances (default 1e-4,1e-5,1e-6,1e-7)", &rtols);
  opt.addDouble("--t-end", "simulated time, s (default 2)", &tEnd);
  opt.parse(argc, argv);
  if (rtols.empty()) rtols = {"1e-4", "1e-5", "1e-6", "1e-7"};
  if (opt.quick) {
    tEnd = 0.2;
    rtols = {"1e-5"};
    opt.repeat = 1;
  }
  if (!std::filesystem::exists(kRotorDir + "/rotorDiscTest.inp")) {
    std::printf("bench_rotor: skipped: no rotor data at %s\n", kRotorDir.c_str());
    return 0;
  }
  const Scene scene = parseSceneText(rotorScene(tEnd).dump(), kRotorDir + "/bench_rotor.json");
  const auto& rotor = dynamic_cast<const FfrBody3d&>(scene.system.body(BodyIndex(1)));
  std::printf("rotor: %.4f kg, %d modes, first %.4f Hz (K x 0.01), spin %.0f rev/s, %.2f s\n",
              rotor.invariants().mass, rotor.numElastic(), std::sqrt(rotor.invariants().kff.coeff(0, 0)) / (2 * kPi),
              kSpin / (2 * kPi), tEnd);

  const Run ref = runOnce(scene, 1e-10);
  if (!ref.ok) {
    std::fprintf(stderr, "bench_rotor: the reference run failed: %s\n", ref.message.c_str());
    return 1;
  }
  double amplitude = 0.0;
  for (const Vec3& d : ref.mid) amplitude = std::max(amplitude, d.norm());
  std::printf("reference (rtol 1e-10): %ld steps, %.3f s CPU, mid-node displacement up to %.3e m\n",
              ref.stats.steps, ref.cpu, amplitude);

  CsvWriter csv(opt.csvPath("bench_rotor.csv"),
                {"rtol", "cpu_s", "cpu_per_simulated_s", "steps", "residuals", "jacobians", "mid_node_error"});
  std::printf("\n%8s %10s %12s %8s %10s %10s %14s\n", "rtol", "CPU s", "CPU s / s", "steps", "residuals", "Jacobians",
              "mid-node err");
  for (const std::string& t : rtols) {
    const double rtol = bench::Options::toDouble(t, "--rtol");
    std::vector<double> cpu;
    Run last;
    for (int k = 0; k < opt.repeat; ++k) {
      last = runOnce(scene, rtol);
      cpu.push_back(last.cpu);
    }
    if (!last.ok) {
      std::printf("%8s failed: %s\n", t.c_str(), last.message.c_str());
      continue;
    }
    double err = 0.0;
    for (std::size_t k = 0; k < std::min(last.mid.size(), ref.mid.size()); ++k) {
      err = std::max(err, (last.mid[k] - ref.mid[k]).norm());
    }
    err /= amplitude;
    const double c = bench::median(cpu);
    std::printf("%8s %10.3f %12.3f %8ld %10ld %10ld %14.2e\n", t.c_str(), c, c / tEnd, last.stats.steps,
                last.stats.residualEvals, last.stats.jacobianEvals, err);
    csv.row({t, fmt(c), fmt(c / tEnd), std::to_string(last.stats.steps), std::to_string(last.stats.residualEvals),
             std::to_string(last.stats.jacobianEvals), fmt(err)});
  }
  std::printf("\nEXUDYN: 20,000 steps of 1e-4 s, 4.4 to 5.4 s CPU for 2 s on a machine like this one, "
              "2.2 to 2.7 s per simulated second\n");
  return 0;
}
