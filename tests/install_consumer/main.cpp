// The outside project of the install test: a pendulum built through the C++ API of the
// installed package and run for 0.1 s, checked against small-angle physics and energy
// conservation; then the same pendulum as a scene (JSON text) written to results.h5 by the
// library's ResultsWriter, so the link pulls in the io layer and its private libraries.
// Usage: consumer OUTPUT_DIR. Exit 0 and "install consumer: ok" when every check holds.
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "bodies/rigid_body_2d.hpp"
#include "builders/planar_builders.hpp"
#include "core/system_evaluation.hpp"
#include "simulation/simulation.hpp"
#include "results/results_writer.hpp"
#include "scene/scene.hpp"

namespace {

constexpr double kMass = 2.0, kInertiaCom = 0.05, kLength = 0.8, kGravity = 9.81;
constexpr double kPhi0 = 0.01;  // rad from the downward vertical: small-angle regime

int failures = 0;

void check(bool ok, const char* what, double got, double expected) {
  std::printf("%s %s: %.12g (expected %.12g)\n", ok ? "ok  " : "FAIL", what, got, expected);
  if (!ok) ++failures;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace flexmbd;
  if (argc != 2) {
    std::fprintf(stderr, "usage: consumer OUTPUT_DIR\n");
    return 2;
  }
  // Frame at the pivot, centre of mass at (L, 0) in the body: angle = phi - pi/2.
  System sys;
  sys.setGravity(Vec2(0.0, -kGravity));
  const BodyIndex bob = addRigidBody(sys, "bob", {kMass, kInertiaCom, {kLength, 0.0}}, {{0, 0}, kPhi0 - M_PI / 2});
  addRevoluteJoint(sys, "pivot", kGround, {0, 0}, bob, {0, 0});
  sys.finalize();

  SolverSettings settings;
  settings.tEnd = 0.1;
  settings.outputStep = 0.01;
  settings.rtol = 1e-10;
  settings.atol = 1e-12;
  settings.progress = false;
  const int theta = sys.coordinateOffset(bob) + 2;
  const double pivotInertia = kInertiaCom + kMass * kLength * kLength;
  const double omega = std::sqrt(kMass * kGravity * kLength / pivotInertia);
  double maxPhaseError = 0.0, energy0 = NAN, maxEnergyDrift = 0.0;
  int samples = 0;
  const SimulationSummary summary = simulate(sys, settings, [&](const OutputSample& o) {
    const double phi = o.q[theta] + M_PI / 2;
    maxPhaseError = std::max(maxPhaseError, std::abs(phi - kPhi0 * std::cos(omega * o.t)));
    const double energy = kineticEnergy(sys, o.q, o.v) + potentialEnergy(sys, o.q);
    if (std::isnan(energy0)) energy0 = energy;
    maxEnergyDrift = std::max(maxEnergyDrift, std::abs(energy - energy0));
    ++samples;
  });
  check(summary.ok, "run ok", summary.tReached, 0.1);
  check(samples == 11, "output samples", samples, 11);
  // The small-angle solution phi0 cos(omega t) is off by O(phi0^3): 1e-6 rad here.
  check(maxPhaseError < 1e-4 * kPhi0, "max |phi - phi0 cos(omega t)| / phi0", maxPhaseError / kPhi0, 0.0);
  check(maxEnergyDrift < 1e-8 * kMass * kGravity * kLength, "max energy drift / (m g L)",
        maxEnergyDrift / (kMass * kGravity * kLength), 0.0);

  // The same model as a scene, through the io layer, to results.h5.
  const char* sceneText = R"({
    "name": "install consumer pendulum", "gravity": [0.0, -9.81],
    "bodies": [{"name": "bob", "type": "rigid", "mass": 2.0, "inertia": 0.05, "com": [0.8, 0.0],
                "position": [0.0, 0.0], "angle": -1.5607963267948966}],
    "joints": [{"name": "pivot", "type": "revolute", "bodies": ["ground", "bob"],
                "points": [[0.0, 0.0], [0.0, 0.0]]}],
    "solver": {"t_end": 0.1, "output_step": 0.01, "rtol": 1e-10, "atol": 1e-12}
  })";
  Scene scene = parseSceneText(sceneText, "consumer scene");
  scene.solver.progress = false;
  const std::filesystem::path out(argv[1]);
  ResultsWriter writer(out, scene, parseResultsFormat("hdf5"));
  const SimulationSummary sceneSummary =
      simulate(scene.system, scene.solver, [&](const OutputSample& o) { writer.write(o); });
  writeSummary(out, sceneSummary, scene);
  check(sceneSummary.ok, "scene run ok", sceneSummary.tReached, 0.1);
  check(writer.rowsWritten() == 11, "rows in results.h5", writer.rowsWritten(), 11);
  check(std::filesystem::file_size(out / "results.h5") > 0, "results.h5 size > 0",
        static_cast<double>(std::filesystem::file_size(out / "results.h5")), 1.0);

  if (failures) {
    std::printf("install consumer: %d checks failed\n", failures);
    return 1;
  }
  std::printf("install consumer: ok\n");
  return 0;
}
