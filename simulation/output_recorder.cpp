#include "simulation/output_recorder.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "core/system_evaluation.hpp"
#include "integrators/initial_conditions.hpp"
#include "simulation/run_state.hpp"

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

std::string RecordedOutputs::largeDeformationNote(double modelSize) const {
  if (elasticBody < 0 || !(largestElasticRms > kLargeElasticFraction * modelSize)) return "";
  char pct[32];
  std::snprintf(pct, sizeof pct, "%.0f %%", 100.0 * largestElasticRms / modelSize);
  return "body '" + elasticBodyName + "': its elastic displacement reached " + formatValue(largestElasticRms) +
         " (RMS over its mass, at t = " + formatTime(elasticTime) + "), " + pct + " of the model size " +
         formatValue(modelSize) +
         ": beyond the small deformations the floating frame formulation assumes (check the stiffness and its "
         "units: E in Pa, not GPa)";
}

void OutputRecorder::recordElasticDisplacement(double t, const VecX& q) {
  RecordedOutputs& r = recorded_;
  for (int b = 1; b < sys_.numBodies(); ++b) {
    const Body& body = sys_.body(BodyIndex(b));
    const SpMat* mff = body.elasticMatrices().mass;
    if (!mff || mff->rows() == 0 || !(body.mass() > 0.0)) continue;
    const int off = sys_.coordinateOffset(BodyIndex(b)) + body.numFrameCoordinates();
    double qmq = 0.0;  // q_f^T m_ff q_f = int rho |u_f|^2 dV (m_ff of Doc003)
    for (int j = 0; j < mff->outerSize(); ++j) {
      for (SpMat::InnerIterator it(*mff, j); it; ++it) qmq += q[off + it.row()] * it.value() * q[off + j];
    }
    const double rms = std::sqrt(std::max(qmq, 0.0) / body.mass());
    if (rms > r.largestElasticRms) {
      r.largestElasticRms = rms;
      if (r.elasticBody != b) r.elasticBodyName = body.name();
      r.elasticBody = b;
      r.elasticTime = t;
    }
  }
}

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
  recordElasticDisplacement(t, s.q);
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
