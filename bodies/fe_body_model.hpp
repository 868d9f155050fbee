// A spatial floating-frame-of-reference body from a finite element mesh of solid elements
// (3 translational DOF per node, FeBodyData from io/fe_abaqus.hpp or io/fe_ansys.hpp):
// the inertia invariants (FfrInvariants3d) computed from the FE mass matrix and the nodal
// coordinates, reduced to free-free normal modes about mean axes. docs/fe-import.md.
#pragma once

#include <string>
#include <vector>

#include "bodies/fe_body_data.hpp"
#include "bodies/ffr_invariants_3d.hpp"

namespace flexmbd {

/// A point mass lumped at a node of the mesh (an unbalance, a sensor, a bolt): added to
/// the node's m_aa, so to its three diagonal entries of M, before the modes are computed.
struct FePointMass {
  int node = 0;       ///< index into FeBodyData::nodeIds (not the FE code's number)
  double mass = 0.0;  ///< kg, > 0
};

struct FeBodyOptions {
  int modes = 8;                ///< free-free elastic modes kept (the six rigid ones dropped)
  double stiffnessScale = 1.0;  ///< K multiplied by it (EXUDYN's ScaleStiffnessMatrix; > 0)
  double dampingRatio = 0.0;    ///< modal damping: D_ff = diag(2 zeta omega_i), in [0, 1]
  std::vector<FePointMass> pointMasses;
};

class FeBodyModel {
 public:
  /// @throws InputError naming `owner`: a point mass at no node or not positive, a damping
  /// ratio outside [0, 1], a mass matrix that couples directions or differs
  /// between them (expected a solid element mass M(a k, b l) = delta_kl m_ab, to 1e-10 of
  /// its largest entry), a stiffness that does not vanish on the nodes' rigid motions
  /// (coordinates or DOF map not those of the matrices; to 1e-8), a bad scale or mode
  /// count, or the eigensolver's errors (freeFreeModes).
  FeBodyModel(const FeBodyData& data, const FeBodyOptions& options, std::string owner);

  /// The invariants in all 3 N nodal DOF (matrix order), no reference conditions: K_ff
  /// singular (six rigid modes), so not a body by itself.
  const FfrInvariants3d& nodalInvariants() const { return nodal_; }
  /// The invariants in the free-free modal coordinates (m_ff = I, K_ff = diag(omega^2)).
  const FfrInvariants3d& invariants() const { return reduced_; }
  /// The modes (3 N x modes, columns M-normalised, M-orthogonal to the rigid motions).
  const MatX& basis() const { return basis_; }
  /// Their natural frequencies, rad/s.
  const VecX& naturalFrequencies() const { return omega_; }
  /// The six dropped rigid-body eigenvalues (rad^2/s^2; round-off of zero).
  const VecX& rigidEigenvalues() const { return rigidEigenvalues_; }

  /// The rigid motions of the nodes (3 N x 6, matrix order): translations along x, y, z,
  /// then rotations about the body axes through the origin (e_k x X_a at node a).
  static MatX rigidBodyModes(const FeBodyData& data);

 private:
  std::string owner_;
  FfrInvariants3d nodal_, reduced_;
  MatX basis_;
  VecX omega_, rigidEigenvalues_;
};

}  // namespace flexmbd
