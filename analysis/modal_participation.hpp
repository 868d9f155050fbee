/// @file
/// Modal participation of the flexible bodies over a run: per mode of
/// each body (frame held, analysis/elastic_modes.hpp) the largest amplitude and energy
/// reached at the outputs, the modes that carry the motion, and a warning when a nodal body
/// moves in so few slow modes that a reduced model would be much cheaper.
#pragma once

#include <string>
#include <vector>

#include "analysis/elastic_modes.hpp"

namespace flexmbd {

/// A mode "carries" a body's motion when its largest energy reaches this fraction of the
/// sum of the modes' largest energies: 1e-4 (displacements of 1 % of the largest mode's).
inline constexpr double kCarryingEnergyFraction = 1e-4;
/// A nodal body is reported as cheaper reduced when the modes that carry its motion are at
/// most this fraction of its coordinates and its fastest carrying mode is this factor below
/// its fastest mode (the step of an integrator that resolves the body scales with it): 1/4, 20.
inline constexpr double kReducibleCoordinateFraction = 0.25;
inline constexpr double kReducibleFrequencyRatio = 20.0;

struct ModeParticipation {
  double omega = 0.0;         ///< rad/s
  double maxAmplitude = 0.0;  ///< largest |eta_k| max_i |phi_ik| over the outputs (units of q_f)
  double maxEnergy = 0.0;     ///< largest (eta_k'^2 + omega_k^2 eta_k^2) / 2 over the outputs (J)
};

struct BodyParticipation {
  std::string body;
  bool nodal = false;
  std::vector<ModeParticipation> modes;  ///< ascending frequency
  std::vector<int> carrying;             ///< 1-based numbers of the modes that carry the motion
};

/// Accumulates the modal content of the outputs of a run.
class ModalParticipation {
 public:
  /// @pre sys is finalized.
  explicit ModalParticipation(const System& sys);
  /// One output state (q: coordinates, v: velocities of the system).
  void add(const VecX& q, const VecX& v);
  std::vector<BodyParticipation> result() const;
  /// One line per nodal body that would be much cheaper reduced (see the constants above).
  std::vector<std::string> warnings() const;

 private:
  std::vector<BodyModes> modes_;
  std::vector<VecX> shapeSize_;  // per body: max_i |phi_ik| per mode
  std::vector<VecX> maxEta_, maxEnergy_;
  VecX eta_, etaDot_;  // scratch of add(), sized to the largest body
};

}  // namespace flexmbd
