// The elastic slider-crank: rigid crank 0.15 m driven at 150 rad/s, steel connecting rod
// 0.30 m, 8 mm x 8 mm, meshed with N beam elements (floating frame of reference,
// pinned-pinned reference conditions), slider of half the rod's mass.
// Usage: example_slider_crank_elastic [N elements = 8] [revolutions = 1] [modes = 0: all]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>

#include "bodies/ffr_body_2d.hpp"
#include "builders/planar_builders.hpp"
#include "simulation/simulation.hpp"

int main(int argc, char** argv) {
  using namespace flexmbd;
  const int N = argc > 1 ? std::atoi(argv[1]) : 8;
  const double revolutions = argc > 2 ? std::atof(argv[2]) : 1.0;
  const int modes = argc > 3 ? std::atoi(argv[3]) : 0;
  const double crankLength = 0.15, rodLength = 0.30, speed = 150.0;

  // The rod: a beam mesh along its frame's x axis, pinned-pinned between its end nodes.
  const BeamSection steel = rectangularSection(0.008, 0.008, /*E=*/2e11, /*rho=*/7870);
  FfrBeamOptions options;
  options.reference.type = ReferenceConditions::Type::PinnedPinned;  // nodes 0 and N
  options.modes = modes;
  auto rodModel = std::make_shared<FfrBeamModel>(BeamMesh2d::straight(rodLength, N, steel), options, "rod");
  const double rodMass = rodModel->invariants().mass;

  System sys;
  const BodyIndex crank = addRigidBody(sys, "crank", {0.1, 1e-4, {crankLength / 2, 0}}, {{0, 0}, 0.0});
  const BodyIndex rod = sys.addBody(std::make_unique<FfrBody2d>("rod", rodModel, FrameState2d{{crankLength, 0}, 0.0}));
  const BodyIndex slider =
      addRigidBody(sys, "slider", {rodMass / 2, 1e-6, {0, 0}}, {{crankLength + rodLength, 0}, 0.0});
  addRevoluteJoint(sys, "O1", kGround, {0, 0}, crank, {0, 0});
  addRevoluteJoint(sys, "O2", crank, {crankLength, 0}, rod, {0, 0});
  addRevoluteJoint(sys, "O3", rod, {rodLength, 0}, slider, {0, 0});
  addPrismaticJoint(sys, "P", kGround, {0, 0}, slider, {0, 0}, {1, 0});
  addBodyCoordinateDriver(sys, "motor", crank, "theta", makeConstantSpeedLaw(speed));
  sys.finalize();

  SolverSettings settings;
  settings.rtol = 1e-6;
  settings.atol = 1e-8;
  settings.tEnd = revolutions * 2 * M_PI / speed;
  settings.outputStep = settings.tEnd / (72 * revolutions);
  // the midpoint of the rod, for its transverse deflection in the rod frame
  int element = 0;
  double xi = 0;
  rodModel->locate({rodLength / 2, 0}, element, xi);
  const FfrPoint mid = rodModel->materialPoint(element, xi);
  const int qf = sys.coordinateOffset(rod) + 3, xs = sys.coordinateOffset(slider);
  double peak = 0;
  const SimulationSummary s = simulate(sys, settings, [&](const OutputSample& o) {
    const VecX q = o.q.segment(qf, rodModel->numElastic());
    const double w = (mid.shape * q)[1];
    const double axial = rodModel->sectionForces(q, element, xi)[0];
    peak = std::max(peak, std::abs(w));
    std::printf("t = %.5f  slider x = %.6f m  midpoint deflection = %+.4e m  axial force = %+.3f N\n", o.t,
                o.q[xs], w, axial);
  });
  std::printf("%s: %ld steps, %.3f s CPU, midpoint deflection peak %.4e m\n", s.ok ? "done" : s.message.c_str(),
              s.stats.steps, s.cpuSeconds, peak);
  return s.ok ? 0 : 1;
}
