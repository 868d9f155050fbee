// Benchmark: kinematic analysis (source document 000) of the slider-crank (l1 = 1,
// l2 = 2) and the four-bar (30/60/80/100 cm), 60 steps per revolution, residual below
// 1e-13, with the Newton corrector (D L1 at every iterate) and the document's modified
// Newton (D L1 of the reference position). Prints iterations per step, the residual
// reached and the time per step (median over repeats, assembly excluded).
//
// Usage: bench_kinematics [--repeat N]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "linkage/kinematic_analysis.hpp"
#include "linkage/kinematics_scene.hpp"

using namespace flexmbd;
using Clock = std::chrono::steady_clock;

int main(int argc, char** argv) {
  int repeat = 200;
  for (int k = 1; k + 1 < argc; ++k) {
    if (std::strcmp(argv[k], "--repeat") == 0) repeat = std::max(1, std::atoi(argv[k + 1]));
  }
  std::printf("%-14s %-16s %6s %10s %10s %12s %14s\n", "mechanism", "corrector", "steps", "iter/step",
              "iter min-max", "max residual", "time/step [us]");
  for (const char* name : {"slider_crank", "four_bar"}) {
    const std::string path = std::string(FLEXMBD_SOURCE_DIR) + "/examples/kinematics_" + name + ".json";
    for (CorrectorKind kind : {CorrectorKind::Newton, CorrectorKind::ModifiedNewton}) {
      KinematicsScene scene = loadKinematicsScene(path);
      scene.settings.corrector = kind;
      const KinematicAnalysis analysis(scene.linkage, scene.settings);
      std::vector<double> times;
      KinematicSummary summary;
      for (int r = 0; r < repeat; ++r) {
        long sink = 0;
        const auto t0 = Clock::now();
        summary = analysis.run([&](const KinematicState& s) { sink += s.iterations; });
        times.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
        if (sink < 0) std::printf("?");
      }
      std::nth_element(times.begin(), times.begin() + times.size() / 2, times.end());
      const double perStep = times[times.size() / 2] / scene.settings.steps;
      char range[32];
      std::snprintf(range, sizeof range, "%d-%d", summary.minIterations, summary.maxIterations);
      std::printf("%-14s %-16s %6d %10.2f %10s %12.2e %14.2f%s\n", name,
                  kind == CorrectorKind::Newton ? "newton" : "modified_newton", scene.settings.steps,
                  summary.meanIterations, range, summary.maxResidual, perStep * 1e6,
                  summary.ok ? "" : "  (stopped)");
    }
  }
  return 0;
}
