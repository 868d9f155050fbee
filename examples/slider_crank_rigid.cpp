// The rigid slider-crank of source document 000 built with the C++ API:
// crank l1 = 1, rod l2 = 2, driven at 1 rad/s; prints the slider against the closed form.
#include <cmath>
#include <cstdio>

#include "builders/planar_builders.hpp"
#include "simulation/simulation.hpp"

int main() {
  using namespace flexmbd;
  System sys;
  //                                    mass inertia  com            position  angle
  const BodyIndex crank = addRigidBody(sys, "crank", {1.0, 0.1, {0.5, 0.0}}, {{0.0, 0.0}, 0.0});
  const BodyIndex rod = addRigidBody(sys, "rod", {1.0, 0.4, {1.0, 0.0}}, {{1.0, 0.0}, 0.0});
  const BodyIndex slider = addRigidBody(sys, "slider", {0.5, 0.01, {0.0, 0.0}}, {{3.0, 0.0}, 0.0});
  addRevoluteJoint(sys, "O1", kGround, {0, 0}, crank, {0, 0});
  addRevoluteJoint(sys, "O2", crank, {1, 0}, rod, {0, 0});
  addRevoluteJoint(sys, "O3", rod, {2, 0}, slider, {0, 0});
  addPrismaticJoint(sys, "P", kGround, {0, 0}, slider, {0, 0}, /*axis=*/{1, 0});
  addBodyCoordinateDriver(sys, "motor", crank, "theta", makeConstantSpeedLaw(1.0));
  sys.finalize();

  SolverSettings settings;  // GGL index-2, rtol 1e-8
  settings.tEnd = 2 * M_PI;
  settings.outputStep = M_PI / 6;
  const int x = sys.coordinateOffset(slider);  // slider.x in q
  const SimulationSummary s = simulate(sys, settings, [&](const OutputSample& o) {
    const double exact = std::cos(o.t) + std::sqrt(4.0 - std::pow(std::sin(o.t), 2));
    std::printf("t = %5.3f   slider x = %.10f   exact %.10f\n", o.t, o.q[x], exact);
  });
  std::printf("%s after %ld steps\n", s.ok ? "done" : s.message.c_str(), s.stats.steps);
  return s.ok ? 0 : 1;
}
