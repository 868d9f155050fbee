// The drift of the constants of a free spatial FFR body's motion over a run (no gravity,
// no damping): energy, linear momentum L = (M v)_R and angular momentum about the world
// origin H = R x L + A (M v)_w. Shared by the beam body's and the imported body's tests.
#pragma once

#include <algorithm>
#include <memory>
#include <vector>

#include "bodies/ffr_body_3d.hpp"
#include "core/system.hpp"
#include "simulation/simulation.hpp"

namespace flexmbd::testsupport {

struct FreeBodyDrift {
  double energy = 0.0, momentum = 0.0, angularMomentum = 0.0;  ///< largest relative changes
  std::size_t outputs = 0;
  SimulationSummary summary;
};

/// Runs `body` alone under `settings` and measures the drifts over the outputs.
inline FreeBodyDrift freeBodyDrift(std::unique_ptr<FfrBody3d> body, SolverSettings settings) {
  const FfrBody3d* b = body.get();
  const int nf = b->numElastic();
  System sys;
  sys.addBody(std::move(body));
  sys.finalize();
  const int oq = sys.coordinateOffset(BodyIndex(1)), ov = sys.velocityOffset(BodyIndex(1));
  std::vector<double> E;
  std::vector<Vec3> L, H;
  settings.progress = false;
  FreeBodyDrift d;
  d.summary = simulate(sys, settings, [&](const OutputSample& o) {
    const VecX q = o.q.segment(oq, 7 + nf), v = o.v.segment(ov, 6 + nf);
    VecX Mv = VecX::Zero(6 + nf);
    b->addMassTimes(q, v, Mv);
    E.push_back(0.5 * v.dot(Mv) + b->internalPotential(q));
    L.push_back(Mv.head<3>());
    H.push_back(Vec3(q.head<3>()).cross(Vec3(Mv.head<3>())) + FfrBody3d::rotationOf(q) * Mv.segment<3>(3));
  });
  d.outputs = E.size();
  for (std::size_t k = 0; k < E.size(); ++k) {
    d.energy = std::max(d.energy, std::abs(E[k] - E[0]) / E[0]);
    d.momentum = std::max(d.momentum, (L[k] - L[0]).norm() / L[0].norm());
    d.angularMomentum = std::max(d.angularMomentum, (H[k] - H[0]).norm() / H[0].norm());
  }
  return d;
}

}  // namespace flexmbd::testsupport
