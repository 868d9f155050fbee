// A beam finite-element mesh as the generator of a flexible body's invariants:
// nodal inertia shape integrals summed from the elements, reference conditions (B2),
// optional modal reduction, and the (optionally geometrically nonlinear) strain energy.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "bodies/element_basis.hpp"
#include "bodies/ffr_invariants.hpp"
#include "bodies/modal_reduction.hpp"
#include "elements/beam_element_2d.hpp"

namespace flexmbd {

/// Nodes (body frame, undeformed) and two-node beam elements.
struct BeamMesh2d {
  struct Element {
    int node1 = 0, node2 = 0;
    BeamSection section;
  };
  std::vector<Vec2> nodes;
  std::vector<Element> elements;
  /// A straight beam of `length` along the body x axis from `origin`, n equal elements.
  static BeamMesh2d straight(double length, int numElements, const BeamSection& section,
                             const Vec2& origin = Vec2::Zero());
};

/// Reference conditions (document 003): what fixes the body frame in the body.
struct ReferenceConditions {
  enum class Type {
    PinnedPinned,  ///< node A fixed in the frame, node B on the chord A-B (the frame's x axis)
    Clamped,       ///< node A fixed in the frame, its cross-section rotation zero (tangent frame)
    FreeFree,      ///< mean-axis conditions: int rho u_f dV = 0, int rho u0 x u_f dV = 0
  };
  Type type = Type::PinnedPinned;
  int nodeA = 0;
  int nodeB = -1;  ///< pinned-pinned only; -1: the last node
};

struct FfrBeamOptions {
  ReferenceConditions reference;
  /// Modal reduction: 0 keeps every nodal coordinate; n > 0 keeps the first n modes
  /// (under the reference conditions); `modeSet` (1-based) keeps a chosen set instead.
  /// Craig-Bampton: the fixed-interface modes.
  int modes = 0;
  std::vector<int> modeSet;
  ModalReduction reduction = ModalReduction::Normal;
  /// Craig-Bampton only (required there): the interface nodes, e.g. the joints' nodes.
  std::vector<int> interfaceNodes;
  /// With a reduction: add the static responses to the inertia loads of the frame's rigid
  /// motion (translation S-bar^T, centrifugal I1, angular acceleration J0; at most 4),
  /// so that the quasi-static deformation by the body's own inertia is held exactly
  /// (withStaticModes, bodies/modal_reduction.hpp).
  bool inertiaModes = false;
  /// Second-order axial strain in the strain energy (stiffening by axial load), as the
  /// element-averaged membrane strain u' + (1/2l) int v'^2 dx (locking-free); off: the
  /// linear FFR model (docs/flexible-bodies.md).
  bool geometricStiffening = false;
};

class FfrBeamModel {
 public:
  /// @throws InputError naming `owner`: empty or disconnected meshes, zero-length
  /// elements, bad sections, bad reference nodes, reference conditions that leave a
  /// rigid mode or over-constrain the body, bad mode choices.
  FfrBeamModel(BeamMesh2d mesh, const FfrBeamOptions& options, const std::string& owner);

  const FfrInvariants& invariants() const { return invariants_; }
  const BeamMesh2d& mesh() const { return mesh_; }
  const std::vector<BeamElement2d>& elements() const { return elements_; }
  bool geometricStiffening() const { return options_.geometricStiffening; }
  using SpMatRow = Eigen::SparseMatrix<double, Eigen::RowMajor>;
  /// Nodal displacements (ux, uy, psi per node, body frame) = basis() * q_f.
  const SpMatRow& basis() const { return basis_; }
  int numElastic() const { return static_cast<int>(basis_.cols()); }
  /// Natural frequencies (rad/s) of the body with its frame held fixed, ascending:
  /// K_ff phi = omega^2 m_ff phi.
  VecX naturalFrequencies() const;
  /// Craig-Bampton: the nodal coordinate (3 node + k, k = ux, uy, psi) of each constraint
  /// mode, i.e. of the first elastic coordinates q_1..q_nc (q_k is that nodal
  /// displacement); empty for the other reductions.
  const std::vector<int>& constraintModeCoordinates() const { return constraintDofs_; }
  /// Craig-Bampton: the natural frequencies (rad/s) of the kept fixed-interface modes
  /// (interface held), which are q_nc+1..; empty for the other reductions.
  const VecX& fixedInterfaceFrequencies() const { return fixedInterfaceFrequencies_; }
  /// The number of inertia modes (FfrBeamOptions::inertiaModes), the last elastic
  /// coordinates; 0 without them.
  int numInertiaModes() const { return numInertiaModes_; }

  double strainEnergy(const VecX& qf) const;
  VecX strainEnergyGradient(const VecX& qf) const;
  /// Sparse, with the same structure for every q_f (the Jacobian pattern is fixed).
  SpMat strainEnergyHessian(const VecX& qf) const;

  /// Element and local coordinate xi in [0, 1] of a body-frame point on the beam axis.
  /// @return false if no element passes within 1e-9 (relative) of the point.
  bool locate(const Vec2& point, int& element, double& xi) const;
  /// Shape of an arbitrary material point on element `element` at xi.
  FfrPoint materialPoint(int element, double xi) const;
  /// Axial force and bending moment at (element, xi) for the elastic coordinates q_f:
  /// the element's stiffness times the nodal displacements basis() q_f. A reduced body
  /// gives only what its basis holds: normal bending modes carry no axial strain, while
  /// Craig-Bampton constraint modes hold the exact static response to loads at the
  /// interface nodes (docs/flexible-bodies.md, "Section forces of reduced bodies").
  Vec2 sectionForces(const VecX& qf, int element, double xi) const;

 private:
  /// The rows of basis() of an element's six nodal coordinates (bodies/element_basis.hpp).
  using ElementBasis = flexmbd::ElementBasis<6>;
  ElementBasis elementBasis(int element) const;
  /// Element nodal displacements in element axes (T B q_f).
  BeamElement2d::Vec6 elementCoordinates(int element, const ElementBasis& eb, const VecX& qf) const;

  BeamMesh2d mesh_;
  FfrBeamOptions options_;
  std::vector<BeamElement2d> elements_;
  SpMatRow basis_;
  std::vector<ElementBasis> elementBases_;  // per element, built once with basis_
  FfrInvariants invariants_;
  std::vector<int> constraintDofs_;  // Craig-Bampton: nodal coordinate of each constraint mode
  VecX fixedInterfaceFrequencies_;   // Craig-Bampton: of the kept fixed-interface modes
  int numInertiaModes_ = 0;
};

}  // namespace flexmbd
