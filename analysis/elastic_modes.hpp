/// @file
/// The natural modes of every flexible body's elastic coordinates with its frame held
/// (K_ff phi = omega^2 M_ff phi, phi^T M_ff phi = 1; GeradinRixen), and where those coordinates sit in the
/// system's q and v: what the automatic integrator choice, the quasi-static elastic start
/// and the modal participation report look at (docs/formulations.md).
#pragma once

#include <string>
#include <vector>

#include "core/system.hpp"

namespace flexmbd {

/// Elastic bodies with more coordinates than this are not analysed (dense symmetric
/// eigenproblem, O(n^3): about 0.1 s at this size); the same limit as the BDF order limit.
inline constexpr int kMaxElasticModesSize = 400;

struct BodyModes {
  BodyIndex body;
  std::string name;
  int coordinateOffset = 0;  ///< first elastic coordinate of the body in q
  int velocityOffset = 0;    ///< first elastic velocity of the body in v
  VecX omega;                ///< natural circular frequencies (rad/s), ascending, size nf
  MatX shapes;               ///< Phi (nf x nf), mass-normalised: Phi^T M_ff Phi = I
  MatX projector;            ///< Phi^T M_ff: modal coordinates eta = Phi^T M_ff q_f
  bool nodal = false;        ///< q_f are nodal displacements (not modal amplitudes)
  int size() const { return static_cast<int>(omega.size()); }
};

/// The modes of every body with elastic coordinates (mass and stiffness matrices given,
/// at most kMaxElasticModesSize coordinates); bodies above the limit are listed in
/// `skipped` if it is not null. `withShapes` false: frequencies only (shapes and
/// projector left empty; about 3 times cheaper).
/// @pre sys is finalized.
std::vector<BodyModes> elasticModes(const System& sys, std::vector<std::string>* skipped = nullptr,
                                    bool withShapes = true);

}  // namespace flexmbd
