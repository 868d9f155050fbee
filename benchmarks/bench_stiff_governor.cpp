// End error against the tolerance on the free A05 stiff flyball governor
// (docs/stability.md, section 7; tests/test_stiff_spatial_accuracy.cpp asserts the bound).
// The governor of examples/flyball_governor.json without its motor, spun at 2 pi rad/s from
// the 30 deg configuration, 2 s, outputs every 0.01 s; variants: "soft" (k and c / 100),
// "driven" (the motor kept, at 2 pi rad/s). Reference: radau at rtol 1e-11 (atol 1e-13).
// Per run: the largest end-position error of any body's frame origin (m), its ratio to
// rtol, the part of it that is the right arm's phase about the axis (m), steps, CPU s.
//
//   bench_stiff_governor [free|soft|driven] [integrators...]   (default: free auto ida radau5 radau)
//   an integrator "ida-index1" runs IDA with formulation index1
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "simulation/simulation.hpp"
#include "simulation/tolerances.hpp"
#include "scene/scene.hpp"

using namespace flexmbd;
using nlohmann::json;

namespace {

json governor(const std::string& variant) {
  std::ifstream in(std::string(FLEXMBD_SOURCE_DIR) + "/examples/flyball_governor.json");
  json j = json::parse(in);
  const double speed = 2.0 * M_PI;
  if (variant == "driven") {
    j["drivers"][0]["law"]["speed"] = speed;  // the consistent start projects the velocities
  } else {
    const double f = speed / j["drivers"][0]["law"]["speed"].get<double>();
    for (auto& b : j["bodies"]) {
      for (const char* key : {"velocity", "angular_velocity"}) {
        if (b.contains(key)) {
          for (auto& x : b[key]) x = x.get<double>() * f;
        }
      }
    }
    j.erase("drivers");
  }
  if (variant == "soft") {
    for (auto& force : j["forces"]) {
      force["stiffness"] = force["stiffness"].get<double>() / 100;
      force["damping"] = force["damping"].get<double>() / 100;
    }
  }
  j["solver"]["t_end"] = 2.0;
  j["solver"]["output_step"] = 0.01;
  return j;
}

struct Result {
  VecX p;  ///< x, y, z of every body's frame origin at the end
  SimulationSummary s;
  double cpu = 0.0;
  int arm = 0;  ///< index of arm_right's x in p
};

Result run(json j, const std::string& integrator, double rtol, double atol = 0.0) {
  std::string integ = integrator;
  if (integ == "ida-index1") integ = "ida", j["solver"]["formulation"] = "index1";
  j["solver"]["integrator"] = integ;
  Scene sc = parseScene(j);
  sc.solver.progress = false;
  overrideTolerances(sc.solver, rtol, atol > 0.0 ? std::optional<double>(atol) : std::nullopt);
  VecX last;
  Result r;
  const auto t0 = std::chrono::steady_clock::now();
  r.s = simulate(sc.system, sc.solver, [&](const OutputSample& o) { last = o.q; });
  r.cpu = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const int nb = sc.system.numBodies();
  r.p.resize(3 * nb);
  for (int b = 0; b < nb; ++b) r.p.segment<3>(3 * b) = last.segment<3>(sc.system.coordinateOffset(BodyIndex{b}));
  r.arm = 3 * sc.system.findBody("arm_right").value;
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string variant = argc > 1 ? argv[1] : "free";
  std::vector<std::string> integrators;
  for (int i = 2; i < argc; ++i) integrators.push_back(argv[i]);
  if (integrators.empty()) integrators = {"auto", "ida", "radau5", "radau"};
  const json j = governor(variant);
  const Result ref = run(j, "radau", 1e-11, 1e-13);
  const Result check = run(j, "radau", 1e-12, 1e-14);
  std::printf("# %s governor: reference radau rtol 1e-11; against rtol 1e-12: %.2e m\n", variant.c_str(),
              (ref.p - check.p).cwiseAbs().maxCoeff());
  std::printf("# integrator (used)  rtol  end_error_m  ratio  phase_part_m  steps  cpu_s\n");
  const auto phase = [](const Result& r) { return std::atan2(r.p[r.arm + 1], r.p[r.arm]); };
  const double radius = std::hypot(ref.p[ref.arm], ref.p[ref.arm + 1]);
  for (const std::string& integ : integrators) {
    for (double rtol : {1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10}) {
      const Result r = run(j, integ, rtol);
      if (!r.s.ok) {
        std::printf("%s rtol %.0e: failed: %s\n", integ.c_str(), rtol, r.s.message.c_str());
        continue;
      }
      const double err = (r.p - ref.p).cwiseAbs().maxCoeff();
      double dphi = std::remainder(phase(r) - phase(ref), 2.0 * M_PI);
      std::printf("%-10s (%s)  %.0e  %.2e  %8.1f  %.2e  %6ld  %.3f\n", integ.c_str(),
                  toString(r.s.integrator).c_str(), rtol, err, err / rtol, std::abs(dphi) * radius, r.s.stats.steps,
                  r.cpu);
    }
  }
  return 0;
}
