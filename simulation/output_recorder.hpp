/// @file
/// The outputs of a run: each state the integrators reach at an output time is completed
/// (accelerations, multipliers), checked (finite values), measured (constraint violations,
/// energy, largest coordinate and speed) and passed to the caller's callback.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/system.hpp"
#include "simulation/simulation.hpp"

namespace flexmbd {

/// A state whose position coordinates exceed this multiple of the model size has
/// diverged: no mechanism of the scene reaches 100 times its own size.
inline constexpr double kDivergedSize = 100.0;

/// `largest`, the largest |position or elastic coordinate|, exceeds kDivergedSize times
/// the model size (false for NaN).
inline bool hasDiverged(double largest, double modelSize) { return largest > kDivergedSize * modelSize; }

/// A flexible body whose RMS elastic displacement exceeds this fraction of the model size
/// has left the small deformations the floating frame formulation assumes (its tip moves
/// some 2 to 3 times the RMS: 10 to 15 % of the size): warned, and named in a failure.
inline constexpr double kLargeElasticFraction = 0.05;

/// What the outputs of a run showed so far.
struct RecordedOutputs {
  double tReached = 0.0;    ///< time of the last output passed to the callback
  double tEvaluating = 0.0; ///< time of the output being evaluated (= tReached once it is passed on)
  OutputSample last;        ///< the last output passed to the callback, for the diagnosis of a failure
  double largestCoordinate = 0.0;  ///< largest |position or elastic coordinate| so far (angles not counted)
  /// Velocity scale of the warnings: largest |translational velocity| and |angular rate| x model size.
  double maxSpeed = 0.0;
  double maxPositionViolation = 0.0;  ///< max over outputs of max |g(q, t)|
  double maxVelocityViolation = 0.0;  ///< max over outputs of max |G v + g_t|
  std::optional<double> energyStart, energyEnd;  ///< only if the model is conservative
  double maxKineticEnergy = 0.0;  ///< largest kinetic energy at an output (conservative models)
  /// The small-deformation check of the floating frame: the largest RMS elastic
  /// displacement of a flexible body over its mass, sqrt(q_f^T m_ff q_f / m) (int rho
  /// |u_f|^2 dV = q_f^T m_ff q_f), the body's index and the output's time.
  double largestElasticRms = 0.0;
  int elasticBody = -1;
  std::string elasticBodyName;
  double elasticTime = 0.0;
  /// The note of a large elastic displacement (largestElasticRms above kLargeElasticFraction
  /// of `modelSize`), naming the body and the ratio; empty if none.
  std::string largeDeformationNote(double modelSize) const;

  /// A coordinate output so far exceeds kDivergedSize times the model size.
  bool diverged(double modelSize) const { return hasDiverged(largestCoordinate, modelSize); }
};

/// Records the outputs of one run of a system.
class OutputRecorder {
 public:
  /// @pre sys is finalized; sys and onOutput outlive the recorder (onOutput may be empty).
  /// @pre `onOutput` outlives the recorder (it is held by reference).
  /// `released`: the DAE's released constraint equations (ascending); the multipliers
  /// recorded are then the minimum-norm ones of the full set (minimumNormMultipliers).
  OutputRecorder(const System& sys, double modelSize, const OutputCallback& onOutput,
                 std::vector<int> released = {});
  OutputRecorder(const OutputRecorder&) = delete;
  OutputRecorder& operator=(const OutputRecorder&) = delete;

  /// The output at (t, q, v): accelerations and multipliers recomputed from the state,
  /// constraint violations and the largest coordinate and speed taken into the maxima,
  /// then the energy; passed to the callback, and kept as the last output.
  /// @pre q has numCoordinates() entries, v numVelocities().
  /// @throws NonFiniteResult naming the first non-finite quantity (positions,
  /// velocities, accelerations, multipliers, energy): the callback is not called. What
  /// computeAccelerations and the callback throw passes through.
  void record(double t, const Eigen::Ref<const VecX>& q, const Eigen::Ref<const VecX>& v);

  const RecordedOutputs& recorded() const { return recorded_; }

 private:
  /// RecordedOutputs::largestElasticRms and its body at the output (t, q).
  void recordElasticDisplacement(double t, const VecX& q);

  const System& sys_;
  const double modelSize_;
  const std::vector<int> released_;
  const OutputCallback& onOutput_;
  const bool conservative_;
  const std::vector<CoordinateKind> kinds_, velocityKinds_;
  RecordedOutputs recorded_;
};

}  // namespace flexmbd
