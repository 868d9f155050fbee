// Benchmark: time per step of method 1 (inextensible cables, one LCP per step)
// against the number of cables, for the LCP solvers behind tensegrity/lcp_solver.hpp
// (Siconos lexicographic Lemke and projected Gauss-Seidel).
//
// Model: a hanging cable net, k x k nodes (grid spacing 1 in x-y, mass 1 each) with its
// four corners fixed at z = 0, the others sagged (z = -0.25 k sin(pi i/(k-1)) sin(pi
// j/(k-1)) + 0.05 U(-1,1)), inextensible cables along the grid lines at their natural
// length (2 k (k - 1) cables), gravity -9.81 z and a random initial velocity (seed 1,
// components uniform in [-1, 1]) on every free node: at the first step every cable is
// in the LCP and roughly half of them snap; afterwards cables keep going slack and taut.
// Time step 1e-3, drift projection on (tolerance 1e-12), LCP tolerance 1e-10.
// Time per step = wall time of the run (setup of the stepper included, the mass matrix
// inverse once per run) / number of steps, best of --repeat runs.
//
// Usage: bench_tensegrity [--max-cables N (default 1100: nets of 12 .. 1012 cables)] [--pgs-max-cables N (default 500)]
//                         [--steps N] [--repeat N] [--csv FILE]
//   --pgs-max-cables: PGS is skipped above it (1012 cables: ~24 s/step, 2 min alone).
//   --steps: steps for the smallest net (default 200); larger nets use
//            max(5, steps * 24 / cables) steps so the default run stays short.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cmath>
#include <cstring>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "tensegrity/tensegrity_structure.hpp"
#include "tensegrity/tensegrity_time_stepper.hpp"

using namespace flexmbd;
using Clock = std::chrono::steady_clock;

namespace {

TensegrityStructure hangingNet(int k) {
  TensegrityStructure s(3);
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto id = [k](int i, int j) { return i * k + j; };
  for (int i = 0; i < k; ++i) {
    for (int j = 0; j < k; ++j) {
      const bool corner = (i == 0 || i == k - 1) && (j == 0 || j == k - 1);
      Eigen::Vector3d v = Eigen::Vector3d::Zero();
      if (!corner) v = Eigen::Vector3d(u(rng), u(rng), u(rng));
      // Sagged, slightly irregular shape: a flat net would be in-plane statically
      // indeterminate (W singular); this one is generic (cables independent).
      const double z = -0.25 * k * std::sin(M_PI * i / (k - 1)) * std::sin(M_PI * j / (k - 1)) + 0.05 * u(rng);
      s.addNode("n" + std::to_string(i) + "_" + std::to_string(j), Eigen::Vector3d(i, j, corner ? 0.0 : z), 1.0,
                std::vector<bool>(3, corner), v);
    }
  }
  auto len = [&s](int a, int b) { return (s.node(b).position - s.node(a).position).norm(); };
  for (int i = 0; i < k; ++i) {
    for (int j = 0; j < k; ++j) {
      // natural length = initial length (cables start taut)
      if (i + 1 < k) s.addCable("h" + std::to_string(id(i, j)), id(i, j), id(i + 1, j), 0.0, len(id(i, j), id(i + 1, j)), true);
      if (j + 1 < k) s.addCable("v" + std::to_string(id(i, j)), id(i, j), id(i, j + 1), 0.0, len(id(i, j), id(i, j + 1)), true);
    }
  }
  s.setGravity(Eigen::Vector3d(0.0, 0.0, -9.81));
  s.finalize();
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  int maxCables = 1100, pgsMaxCables = 500, baseSteps = 200, repeat = 1;
  std::string csvPath = "bench_tensegrity.csv";
  for (int a = 1; a + 1 < argc; ++a) {
    if (std::strcmp(argv[a], "--max-cables") == 0) maxCables = std::atoi(argv[a + 1]);
    if (std::strcmp(argv[a], "--pgs-max-cables") == 0) pgsMaxCables = std::atoi(argv[a + 1]);
    if (std::strcmp(argv[a], "--steps") == 0) baseSteps = std::max(1, std::atoi(argv[a + 1]));
    if (std::strcmp(argv[a], "--repeat") == 0) repeat = std::max(1, std::atoi(argv[a + 1]));
    if (std::strcmp(argv[a], "--csv") == 0) csvPath = argv[a + 1];
  }
  std::ofstream csv(csvPath);
  csv << "grid,cables,free_coordinates,solver,steps,ms_per_step,max_lcp_size,mean_lcp_size,"
         "iterations_per_lcp,max_lcp_residual,snaps,drift_before,drift_after,ok\n";
  std::printf("%6s %6s %6s %6s %6s %12s %8s %8s %10s %10s %6s %9s %9s\n", "grid", "cables", "dofs", "solver",
              "steps", "ms/step", "maxLCP", "meanLCP", "iter/LCP", "residual", "snaps", "drift0", "drift1");
  for (int k : {3, 4, 6, 8, 11, 16, 23}) {
    const int cables = 2 * k * (k - 1);
    if (cables > maxCables) break;
    const TensegrityStructure s = hangingNet(k);
    const int steps = std::max(5, baseSteps * 24 / std::max(cables, 24));
    for (LcpMethod m : {LcpMethod::Lemke, LcpMethod::ProjectedGaussSeidel}) {
      if (m == LcpMethod::ProjectedGaussSeidel && cables > pgsMaxCables) continue;
      TimeSteppingSettings set;
      set.timeStep = 1e-3;
      set.tEnd = steps * set.timeStep;
      set.lcp.method = m;
      set.lcp.tolerance = 1e-10;
      set.lcp.maxIterations = 100000;
      double best = 1e300;
      TensegrityRunSummary sum;
      for (int r = 0; r < repeat; ++r) {
        const auto t0 = Clock::now();
        sum = TensegrityTimeStepper(s, set).run({});
        best = std::min(best, std::chrono::duration<double>(Clock::now() - t0).count());
      }
      const double msPerStep = 1e3 * best / std::max(1L, sum.steps);
      const double meanSize = sum.lcpSolves > 0 ? double(sum.lcpSizeSum) / sum.lcpSolves : 0.0;
      const double itPerLcp = sum.lcpSolves > 0 ? double(sum.lcpIterations) / sum.lcpSolves : 0.0;
      std::printf("%3dx%-2d %6d %6d %6s %6ld %12.3f %8d %8.1f %10.1f %10.2e %6d %9.1e %9.1e%s\n", k, k, cables,
                  s.numFreeCoordinates(), toString(m).c_str(), sum.steps, msPerStep, sum.maxLcpSize, meanSize,
                  itPerLcp, sum.maxLcpResidual, sum.snaps, sum.maxDriftBeforeProjection,
                  sum.maxDriftAfterProjection, sum.ok ? "" : "  FAILED");
      if (!sum.ok) std::printf("       %s\n", sum.message.c_str());
      std::fflush(stdout);
      csv << k << "x" << k << ',' << cables << ',' << s.numFreeCoordinates() << ',' << toString(m) << ','
          << sum.steps << ',' << msPerStep << ',' << sum.maxLcpSize << ',' << meanSize << ',' << itPerLcp << ','
          << sum.maxLcpResidual << ',' << sum.snaps << ',' << sum.maxDriftBeforeProjection << ','
          << sum.maxDriftAfterProjection << ',' << (sum.ok ? 1 : 0) << '\n';
    }
  }
  std::printf("CSV written to %s\n", csvPath.c_str());
  return 0;
}
