/// @file
/// A quasi-static elastic start (docs/formulations.md, "Why a nodal rod takes so
/// many steps"): the fast elastic modes of flexible bodies begin in their quasi-static
/// deflection under the loads of the initial state (inertia of the frame's motion, joint
/// reactions, applied loads, gravity) and with its rate, instead of undeformed and at rest
/// relative to the frame, which sets them vibrating for the whole run.
#pragma once

#include <vector>

#include "analysis/elastic_modes.hpp"
#include "integrators/initial_conditions.hpp"

namespace flexmbd {

struct QuasiStaticStart {
  ConsistentState state;   ///< consistent at t0, with the fast modes at their quasi-static values
  int modes = 0;           ///< modes (all bodies) started quasi-statically
  int iterations = 0;      ///< fixed-point iterations, positions and rates
  /// Largest modal acceleration left in those modes, as the deflection it stands for:
  /// max_k |eta_k''| / omega_k^2 (units of q_f; 0 for an exact quasi-static state).
  double residual = 0.0;
};

/// The consistent state `start` with every mode k of `modes` whose omega_k > cutoff moved
/// to its quasi-static deflection and rate: eta_k'' = 0 and eta_k''' = 0 at t0 (eta = Phi^T
/// M_ff q_f). Fixed point: eta_k += eta_k'' / omega_k^2 (the deflection whose elastic force
/// K phi_k takes the load that accelerates the mode), the state projected on the
/// constraints again, until the change is below round-off of the elastic coordinates; then
/// the same for the rates with eta_k''' from central differences of the accelerations
/// along the motion. The modes at or below the cutoff keep their given values.
/// @pre start is consistent at t0 (computeConsistentState); cutoff > 0.
/// @throws ModelError if a projection fails (as computeConsistentState).
QuasiStaticStart quasiStaticElasticStart(const System& sys, double t0, const ConsistentState& start,
                                         const std::vector<BodyModes>& modes, double cutoff);

}  // namespace flexmbd
