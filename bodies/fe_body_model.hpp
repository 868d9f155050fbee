/// @file
/// A spatial floating-frame-of-reference body from a finite element mesh (FeBodyData from
/// fe_import/fe_abaqus.hpp, fe_import/fe_ansys.hpp or fe_import/fe_calculix.hpp): the inertia invariants
/// (FfrInvariants3d) computed from the FE mass matrix and the nodal coordinates (solid
/// elements, 3 DOF per node: exact; beams and shells, 6 DOF per node: exact for the rigid
/// motions, the rest lumped at the nodes), reduced to free-free normal modes about mean
/// axes or by Craig-Bampton. docs/fe-import.md.
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

/// An interface frame over a node set (docs/fe-import.md, "Interfaces"): a point with a
/// translation and a small rotation of its own, where joints and forces attach.
///  - Rigid (RBE2): the set moves rigidly with the frame, u_a = u_I + theta_I x (X_a - X_I);
///    the set's nodal DOF (nodes with rotations: theta_a = theta_I too) are replaced by the
///    frame's 6 before the modes are computed (the
///    interface stiffens the body).
///  - Averaging (RBE3): the frame carries the set's mean translation and least-squares
///    rotation, u_c = sum u_a / n, theta_I = H^-1 sum r_a x u_a with r_a = X_a - X_c,
///    H = sum (|r_a|^2 1 - r_a r_a^T), and u_I = u_c + theta_I x (X_I - X_c); adds no
///    stiffness or mass.
/// The set must not lie on one line (H singular: the rotation about the line undefined),
/// except a rigid set whose nodes all have rotations (one node is enough: its own frame).
enum class FeInterfaceKind { Rigid, Averaging };
struct FeInterface {
  std::string name;
  std::vector<int> nodes;  ///< indices into FeBodyData::nodeIds, at least 3, not collinear
  FeInterfaceKind kind = FeInterfaceKind::Averaging;
  bool atCentroid = true;   ///< the frame's point X_I: the set's centroid X_c, or `point`
  Vec3 point = Vec3::Zero();
};

/// How the nodal model is reduced.
///  - FreeFree: `modes` free-free normal modes on mean axes (Tisserand frame).
///  - CraigBampton (CraigBampton1968): the frame follows the rigid interface named
///    `reference` (its 6 DOF held: the reference conditions); the coordinates are the 6
///    constraint modes of every other rigid interface (static shapes, psi = -K_ii^-1 K_ib,
///    exact for static loads there) and `modes` fixed-interface modes (every rigid
///    interface held; M never factored, clampedModes).
enum class FeReduction { FreeFree, CraigBampton };

/// Centrifugal stiffening from the FE code's prestressed stiffness (docs/fe-import.md,
/// "Spin stiffening"): K_pre, exported with the body held at the Craig-Bampton reference
/// interface and spinning at `spin` (rad/s, body axes, about an axis through the frame
/// origin), includes the stress stiffness K_sigma and the spin softening -|spin|^2 M_perp
/// (M_perp = sum_kl (delta_kl - e_k e_l) S_kl, e = spin / |spin|), which the FFR body
/// has of its own through the S_kl. So K_sigma = K_pre - K + |spin|^2 M_perp, and the
/// stresses of a spin w scale with (w . e)^2: G_kl = e_k e_l K_sigma / |spin|^2
/// (FfrInvariants3d::spinStiffness).
struct FeSpinStiffening {
  SpMat preloadedStiffness;  ///< K_pre in the data's DOF order (n x n); empty: none
  std::vector<int> heldDofs;  ///< the DOF the preload run held (no equation in its export)
  Vec3 spin = Vec3::Zero();   ///< the spin of the preload run, rad/s, body axes
};

struct FeBodyOptions {
  int modes = 8;                ///< free-free elastic modes kept (the six rigid ones dropped)
  double stiffnessScale = 1.0;  ///< K multiplied by it (EXUDYN's ScaleStiffnessMatrix; > 0)
  double dampingRatio = 0.0;    ///< modal damping: D_ff = diag(2 zeta omega_i), in [0, 1] (GeradinRixen, 2.3)
  std::vector<FePointMass> pointMasses;
  std::vector<FeInterface> interfaces;  ///< their points follow the nodes' in the invariants
  FeReduction reduction = FeReduction::FreeFree;
  std::string reference;  ///< Craig-Bampton: the rigid interface the frame follows
  /// Append the static responses to the inertia loads of the frame's rigid motion
  /// (FfrInvariants3d::inertiaLoads: translation and the linear acceleration fields of
  /// rotation), less what the modes hold: the quasi-static deformation by the body's own
  /// inertia (a spinning rotor's stretch) is then held exactly. Free-free: with inertia
  /// relief (freeStaticResponses); Craig-Bampton: with the reference interface held.
  bool inertiaModes = false;
  FeSpinStiffening spinStiffening;  ///< Craig-Bampton only
};

class FeBodyModel {
 public:
  /// @throws InputError naming `owner`: a point mass at no node or not positive, a damping
  /// ratio outside [0, 1], a solid mesh's mass matrix that couples directions or differs
  /// between them (expected a solid element mass M(a k, b l) = delta_kl m_ab, to 1e-10 of
  /// its largest entry; meshes with rotations are lumped instead), a stiffness that does not vanish on the nodes' rigid motions
  /// (coordinates or DOF map not those of the matrices; to 1e-8), a bad scale or mode
  /// count, or the eigensolver's errors (freeFreeModes).
  FeBodyModel(const FeBodyData& data, const FeBodyOptions& options, std::string owner);

  /// The invariants in the nodal DOF (matrix order; a rigid interface's set replaced by its
  /// frame's 6 DOF, appended), no reference conditions: K_ff singular (six rigid modes), so
  /// not a body by itself. Points: the nodes (in node order), then the interfaces.
  const FfrInvariants3d& nodalInvariants() const { return nodal_; }
  /// The map from those DOF to the matrices' 3 N (identity without rigid interfaces).
  const SpMat& nodalMap() const { return map_; }
  /// The index of interface `k` among the invariants' points (numNodes + k).
  int interfacePoint(int k) const { return firstInterface_ + k; }
  /// The invariants in the free-free modal coordinates (m_ff = I, K_ff = diag(omega^2); GeradinRixen).
  const FfrInvariants3d& invariants() const { return reduced_; }
  /// The modes (nodal DOF x modes, columns M-normalised, M-orthogonal to the rigid motions).
  const MatX& basis() const { return basis_; }
  /// Their natural frequencies, rad/s (Craig-Bampton: of the fixed-interface modes, which
  /// follow the 6 constraint modes of each boundary interface in the basis; inertia
  /// modes, if any, come last).
  const VecX& naturalFrequencies() const { return omega_; }
  /// The six dropped rigid-body eigenvalues (rad^2/s^2; round-off of zero; free-free only).
  const VecX& rigidEigenvalues() const { return rigidEigenvalues_; }

  /// The rigid motions of the nodes (3 N x 6, matrix order): translations along x, y, z,
  /// then rotations about the body axes through the origin (e_k x X_a at node a).
  static MatX rigidBodyModes(const FeBodyData& data);

 private:
  /// The interfaces (FeInterface): the rigid ones' condensation of nodal_ (map_, and the
  /// rigid motions `R` into the condensed DOF), then every interface's point appended.
  void addInterfaces(const FeBodyData& d, const FeBodyOptions& options, MatX& R);
  /// basis_ and omega_ of the Craig-Bampton reduction (FeReduction::CraigBampton).
  void reduceCraigBampton(const FeBodyOptions& options);
  /// nodal_.spinStiffness from options.spinStiffening (matrix DOF order, before the
  /// interfaces condense it).
  void addSpinStiffening(const FeBodyData& d, const FeBodyOptions& options);
  /// basis_ extended by the inertia modes (FeBodyOptions::inertiaModes); `R` the rigid
  /// motions of the nodal DOF (free-free).
  void addInertiaModes(const FeBodyOptions& options, const MatX& R);
  /// D_ff = diag(2 zeta omega) on the normal modes (firstNormal_ ...), none elsewhere (GeradinRixen, 2.3).
  void addModalDamping(double zeta);

  std::string owner_;
  FfrInvariants3d nodal_, reduced_;
  SpMat map_;
  int firstInterface_ = 0;
  std::vector<int> masterColumn_;  // per interface: its first column in nodal_ (rigid), or -1
  std::vector<int> held_;          // Craig-Bampton: the reference interface's DOF in nodal_
  int firstNormal_ = 0;            // the first normal mode's column in basis_
  MatX basis_;
  VecX omega_, rigidEigenvalues_;
};

}  // namespace flexmbd
