#include "integrators/output_recorder.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/system_evaluation.hpp"
#include "integrators/initial_conditions.hpp"
#include "integrators/run_state.hpp"

namespace flexmbd {
namespace {

/// The first non-finite part of an output ("positions", "velocities", "accelerations",
/// "multipliers"), or nullptr.
const char* firstNonFinite(const OutputSample& s) {
  return !s.q.allFinite() ? "positions" : !s.v.allFinite() ? "velocities" : !s.a.allFinite() ? "accelerations"
         : !s.lambda.allFinite() ? "multipliers" : nullptr;
}

}  // namespace

OutputRecorder::OutputRecorder(const System& sys, double modelSize, const OutputCallback& onOutput,
                               std::vector<int> released)
    : sys_(sys), modelSize_(modelSize), released_(std::move(released)), onOutput_(onOutput), conservative_(isConservative(sys)),
      kinds_(sys.coordinateKinds()), velocityKinds_(sys.velocityKinds()) {}

void OutputRecorder::record(double t, const Eigen::Ref<const VecX>& q, const Eigen::Ref<const VecX>& v) {
  RecordedOutputs& r = recorded_;
  r.tEvaluating = t;
  OutputSample s;
  s.t = t;
  s.q = q;
  s.v = v;
  for (size_t k = 0; k < kinds_.size(); ++k) {
    if (kinds_[k] != CoordinateKind::Angle) r.largestCoordinate = std::max(r.largestCoordinate, std::fabs(s.q[k]));
  }
  // Accelerations and multipliers recomputed from the state (q, v): as accurate as the
  // state itself, unlike the interpolated y' (docs/formulations.md).
  computeAccelerations(sys_, t, s.q, s.v, s.a, s.lambda, released_);
  for (size_t k = 0; k < velocityKinds_.size(); ++k) {
    const double scale = velocityKinds_[k] == CoordinateKind::Angle ? modelSize_ : 1.0;
    r.maxSpeed = std::max(r.maxSpeed, std::fabs(s.v[k]) * scale);
  }
  if (sys_.numConstraintEquations() > 0) {
    VecX g;
    MatX G;
    evaluateConstraints(sys_, s.q, t, &g, released_.empty() ? nullptr : &G);
    // a redundant set's reactions are not unique: the minimum-norm ones with the same resultant
    if (!released_.empty()) s.lambda = minimumNormMultipliers(G, s.lambda);
    r.maxPositionViolation = std::max(r.maxPositionViolation, g.lpNorm<Eigen::Infinity>());
    r.maxVelocityViolation =
        std::max(r.maxVelocityViolation, velocityConstraintResidual(sys_, s.q, s.v, t).lpNorm<Eigen::Infinity>());
  }
  if (const char* bad = firstNonFinite(s)) {
    throw NonFiniteResult(std::string("non-finite ") + bad + " at t = " + formatTime(t));
  }
  if (conservative_) {
    const double K = kineticEnergy(sys_, s.q, s.v);
    const double E = K + potentialEnergy(sys_, s.q);
    if (!std::isfinite(E)) throw NonFiniteResult("non-finite energy at t = " + formatTime(t));
    r.maxKineticEnergy = std::max(r.maxKineticEnergy, K);
    if (!r.energyStart) r.energyStart = E;
    r.energyEnd = E;
  }
  r.tReached = t;
  if (onOutput_) onOutput_(s);
  r.last = std::move(s);
}

}  // namespace flexmbd
