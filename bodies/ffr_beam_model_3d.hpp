// A spatial beam finite-element mesh as the generator of a spatial flexible body's
// invariants (FfrInvariants3d): nodal inertia shape integrals summed from the elements'
// element-frame integrals, reference conditions (B2), optional modal reduction, and the
// (optionally geometrically nonlinear) strain energy. The spatial counterpart of
// FfrBeamModel (bodies/ffr_beam_model.hpp); docs/spatial-flexible.md.
#pragma once

#include <string>
#include <vector>

#include "bodies/element_basis.hpp"
#include "bodies/ffr_invariants_3d.hpp"
#include "bodies/modal_reduction.hpp"
#include "core/matrix_sink.hpp"
#include "elements/beam_element_3d.hpp"

namespace flexmbd {

/// Nodes (body frame, undeformed) and two-node spatial beam elements.
struct BeamMesh3d {
  struct Element {
    int node1 = 0, node2 = 0;
    BeamSection3d section;
    /// The element's y axis hint (body frame): made orthogonal to the element axis, it
    /// is the section's y axis (BeamElement3d).
    Vec3 yHint = Vec3::UnitY();
  };
  std::vector<Vec3> nodes;
  std::vector<Element> elements;
  /// A straight beam of `length` along the body x axis from `origin`, n equal elements,
  /// every element with the y axis hint `yHint`.
  /// @throws InputError unless numElements >= 1 and length > 0.
  static BeamMesh3d straight(double length, int numElements, const BeamSection3d& section,
                             const Vec3& origin = Vec3::Zero(), const Vec3& yHint = Vec3::UnitY());
};

/// Reference conditions in space (document 003, B2): six conditions on the nodal
/// coordinates that fix the body frame in the body.
struct ReferenceConditions3d {
  enum class Type {
    /// Node A: its three translations and three rotations zero. The frame is the tangent
    /// frame of the cross-section at A.
    Clamped,
    /// Chord frame: node A's three translations zero, node B's two translations
    /// transverse to the body x axis zero, and the twist (rotation about x) at A zero.
    /// Node B must lie on the body x axis through A (the mesh puts the chord along x).
    PinnedPinned,
    /// Mean axes (Tisserand / Buckens): int rho u_f dV = 0 and int rho u0 x u_f dV = 0,
    /// exactly on the nodal coordinates.
    FreeFree,
  };
  Type type = Type::Clamped;
  int nodeA = 0;
  int nodeB = -1;  ///< pinned-pinned only; -1: the last node
};

struct FfrBeamOptions3d {
  ReferenceConditions3d reference;
  /// Modal reduction: 0 keeps every nodal coordinate; n > 0 keeps the first n modes
  /// (under the reference conditions, mass-normalised); `modeSet` (1-based) keeps a
  /// chosen set instead. Craig-Bampton: the fixed-interface modes (0: Guyan).
  int modes = 0;
  std::vector<int> modeSet;
  /// Normal modes, or Craig-Bampton (ModalReduction, bodies/modal_reduction.hpp): one
  /// static constraint mode per coordinate of the `interfaceNodes` (6 per node) not
  /// already held by the reference conditions, then the fixed-interface modes.
  ModalReduction reduction = ModalReduction::Normal;
  /// Craig-Bampton only (required there): the interface nodes, e.g. the joints' nodes.
  std::vector<int> interfaceNodes;
  /// With a reduction: add the static responses to the inertia loads of the frame's rigid
  /// motion (translation S-bar^T, and int rho N^T u0_k of every linear field W u0 of
  /// the rotation's accelerations alpha x u0 + omega x (omega x u0): at most 12).
  bool inertiaModes = false;
  /// Element-averaged second-order membrane strain in the strain energy (BeamElement3d,
  /// locking-free); off: the linear FFR model.
  bool geometricStiffening = false;
  /// The elements' beam theory (BeamTheory): Rayleigh adds the sections' rotary inertia
  /// of bending (and its second-order rotation, R_kl and H_i).
  BeamTheory theory = BeamTheory::EulerBernoulli;
};

class FfrBeamModel3d {
 public:
  /// @throws InputError naming `owner`: empty or disconnected meshes, nodes out of range
  /// or unused, zero-length elements, bad y hints or sections, bad reference nodes (or,
  /// pinned-pinned, node B off the body x axis through A), reference conditions that
  /// leave a rigid mode or over-constrain the body, bad mode choices.
  FfrBeamModel3d(BeamMesh3d mesh, const FfrBeamOptions3d& options, const std::string& owner);

  const FfrInvariants3d& invariants() const { return invariants_; }
  const BeamMesh3d& mesh() const { return mesh_; }
  const std::vector<BeamElement3d>& elements() const { return elements_; }
  bool geometricStiffening() const { return options_.geometricStiffening; }
  using SpMatRow = Eigen::SparseMatrix<double, Eigen::RowMajor>;
  /// Nodal displacements (ux, uy, uz, thx, thy, thz per node, body frame) = basis() * q_f
  /// (6 nodes x numElastic()).
  const SpMatRow& basis() const { return basis_; }
  int numElastic() const { return static_cast<int>(basis_.cols()); }
  /// Natural frequencies (rad/s) of the body with its frame held fixed, ascending:
  /// K_ff phi = omega^2 m_ff phi (dense: for tests and small models).
  VecX naturalFrequencies() const;
  /// Craig-Bampton: the nodal coordinate (6 node + k, k = ux, uy, uz, thx, thy, thz) of
  /// each constraint mode, i.e. of q_1..q_nc (q_k is that nodal displacement); empty
  /// for the other reductions.
  const std::vector<int>& constraintModeCoordinates() const { return constraintDofs_; }
  /// Craig-Bampton: natural frequencies (rad/s) of the kept fixed-interface modes
  /// (q_nc+1..); empty for the other reductions.
  const VecX& fixedInterfaceFrequencies() const { return fixedInterfaceFrequencies_; }
  /// The number of inertia modes (FfrBeamOptions3d::inertiaModes), the last elastic
  /// coordinates; 0 without them.
  int numInertiaModes() const { return numInertiaModes_; }

  /// Strain energy U(q_f) (J), the sum of the elements' (BeamElement3d::strainEnergy).
  double strainEnergy(const VecX& qf) const;
  VecX strainEnergyGradient(const VecX& qf) const;
  /// Sparse, with the same structure for every q_f (the Jacobian pattern is fixed).
  SpMat strainEnergyHessian(const VecX& qf) const;
  /// out += scale * dU/dq_f, without allocating (the body's elastic force).
  void addStrainEnergyGradient(const ConstVecRef& qf, double scale, Eigen::Ref<VecX> out) const;
  /// K(offset + i, offset2 + j) += scale * d2U/dq_f,i dq_f,j, every entry of each
  /// element's block written (fixed structure), without allocating.
  void addStrainEnergyHessian(const ConstVecRef& qf, double scale, const MatrixSink& K, int row0, int col0) const;

  /// Element and local coordinate xi in [0, 1] of a body-frame point on the beam axis.
  /// @return false if no element passes within 1e-9 (relative) of the point.
  bool locate(const Vec3& point, int& element, double& xi) const;
  /// Position, shape and rotation shape of the axis point of element `element` at xi.
  /// @throws std::out_of_range for a bad element index.
  FfrPoint3d materialPoint(int element, double xi) const;
  /// Section forces (element frame, BeamSectionForces3d) at (element, xi) for q_f: the
  /// element's stiffness times the nodal displacements basis() q_f, so a reduced body
  /// gives what its basis holds (Craig-Bampton: the exact static response to loads at
  /// the interface nodes; docs/spatial-flexible.md).
  BeamSectionForces3d sectionForces(const VecX& qf, int element, double xi) const;

 private:
  /// The rows of basis() of an element's twelve nodal coordinates (bodies/element_basis.hpp).
  using ElementBasis = flexmbd::ElementBasis<12>;
  ElementBasis elementBasis(int element) const;
  /// Element nodal coordinates in element axes (T B q_f).
  BeamElement3d::Vec12 elementCoordinates(int element, const ConstVecRef& qf) const;

  BeamMesh3d mesh_;
  FfrBeamOptions3d options_;
  std::vector<BeamElement3d> elements_;
  SpMatRow basis_;
  std::vector<ElementBasis> elementBases_;  // per element, built once with basis_
  FfrInvariants3d invariants_;
  std::vector<int> constraintDofs_;  // Craig-Bampton: nodal coordinate of each constraint mode
  VecX fixedInterfaceFrequencies_;   // Craig-Bampton: of the kept fixed-interface modes
  int numInertiaModes_ = 0;
};

}  // namespace flexmbd
