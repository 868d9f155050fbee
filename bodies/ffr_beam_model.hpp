/// @file
/// A beam finite-element mesh as the generator of a flexible body's invariants, one code
/// for planar and spatial bodies (FfrBeamModelT<PlanarBeam> = FfrBeamModel,
/// FfrBeamModelT<SpatialBeam> = FfrBeamModel3d; what differs: bodies/ffr_beam_traits.hpp):
/// nodal inertia shape integrals summed from the elements, reference conditions (B2),
/// optional modal reduction (normal modes, Craig-Bampton, inertia modes), and the
/// (optionally geometrically nonlinear) strain energy. docs/flexible-bodies.md,
/// docs/spatial-flexible.md.
#pragma once

#include <string>
#include <vector>

#include "bodies/beam_mesh.hpp"
#include "bodies/element_basis.hpp"
#include "bodies/ffr_beam_options.hpp"
#include "bodies/ffr_beam_traits.hpp"
#include "core/matrix_sink.hpp"

namespace flexmbd {

template <class Traits>
class FfrBeamModelT {
 public:
  static constexpr int kNodeDofs = Traits::kNodeDofs;        ///< 3 (ux, uy, psi) or 6 (ux..uz, thx..thz)
  static constexpr int kElementDofs = Traits::kElementDofs;  ///< two nodes' coordinates
  using Mesh = typename Traits::Mesh;
  using Element = typename Traits::Element;
  using Point = typename Traits::Point;
  using Invariants = typename Traits::Invariants;
  using MaterialPoint = FfrPointT<Traits::kDim>;
  using Options = typename Traits::Options;
  using SectionForces = typename Traits::SectionForces;
  using SpMatRow = Eigen::SparseMatrix<double, Eigen::RowMajor>;

  /// @throws InputError naming `owner`: empty or disconnected meshes, nodes out of range
  /// or unused, zero-length elements, bad sections (spatial: bad y hints), bad reference
  /// nodes (spatial pinned-pinned: node B off the body x axis through A), reference
  /// conditions that leave a rigid mode or over-constrain the body, bad mode choices.
  FfrBeamModelT(Mesh mesh, const Options& options, const std::string& owner);

  const Invariants& invariants() const { return invariants_; }
  const Mesh& mesh() const { return mesh_; }
  const std::vector<Element>& elements() const { return elements_; }
  bool geometricStiffening() const { return options_.geometricStiffening; }
  /// The nodal invariants (kNodeDofs coordinates per node, node a's at kNodeDofs a ...;
  /// no reference conditions, so K_ff is singular): the dimension's inertia shape
  /// integrals, m_ff, K_ff, D_ff summed from the elements. Built on each call.
  Invariants nodalInvariants() const;
  /// Nodal displacements (kNodeDofs per node, body frame) = basis() * q_f.
  const SpMatRow& basis() const { return basis_; }
  int numElastic() const { return static_cast<int>(basis_.cols()); }
  /// Natural frequencies (rad/s) of the body with its frame held fixed, ascending:
  /// K_ff phi = omega^2 m_ff phi (GeradinRixen; dense: for tests and small models).
  VecX naturalFrequencies() const;
  /// Craig-Bampton: the nodal coordinate (kNodeDofs node + k) of each constraint mode,
  /// i.e. of the first elastic coordinates q_1..q_nc (q_k is that nodal displacement);
  /// empty for the other reductions.
  const std::vector<int>& constraintModeCoordinates() const { return constraintDofs_; }
  /// Craig-Bampton: the natural frequencies (rad/s) of the kept fixed-interface modes
  /// (interface held), which are q_nc+1..; empty for the other reductions.
  const VecX& fixedInterfaceFrequencies() const { return fixedInterfaceFrequencies_; }
  /// The number of inertia modes (FfrBeamOptionsT::inertiaModes), the last elastic
  /// coordinates; 0 without them.
  int numInertiaModes() const { return numInertiaModes_; }

  /// Strain energy U(q_f) (J): 1/2 q_f^T K_ff q_f, or with geometric stiffening the sum
  /// of the elements' strain energies.
  double strainEnergy(const VecX& qf) const;
  VecX strainEnergyGradient(const VecX& qf) const;
  /// Sparse, with the same structure for every q_f (the Jacobian pattern is fixed).
  SpMat strainEnergyHessian(const VecX& qf) const;
  /// out += scale * dU/dq_f, without allocating (the body's elastic force).
  void addStrainEnergyGradient(const ConstVecRef& qf, double scale, Eigen::Ref<VecX> out) const;
  /// K(row0 + i, col0 + j) += scale * d2U/dq_f,i dq_f,j, every entry of each element's
  /// block written (fixed structure), without allocating.
  void addStrainEnergyHessian(const ConstVecRef& qf, double scale, const MatrixSink& K, int row0, int col0) const;

  /// Element and local coordinate xi in [0, 1] of a body-frame point on the beam axis.
  /// @return false if no element passes within 1e-9 (relative) of the point.
  bool locate(const Point& point, int& element, double& xi) const;
  /// Position, shape and rotation shape of the axis point of element `element` at xi.
  /// @throws std::out_of_range for a bad element index.
  MaterialPoint materialPoint(int element, double xi) const;
  /// Section forces at (element, xi) for q_f (plane: axial force and bending moment;
  /// space: BeamSectionForces3d, element frame): the element's stiffness times the nodal
  /// displacements basis() q_f. A reduced body gives only what its basis holds: normal
  /// bending modes carry no axial strain, while Craig-Bampton constraint modes hold the
  /// exact static response to loads at the interface nodes (docs/flexible-bodies.md,
  /// "Section forces of reduced bodies").
  SectionForces sectionForces(const VecX& qf, int element, double xi) const;

 private:
  using ElementBasis = flexmbd::ElementBasis<kElementDofs>;
  using ElementVector = typename Traits::ElementVector;
  using ElementMatrix = typename Traits::ElementMatrix;

  // ----- construction stages ----------------------------------------------------------
  /// The elements of the mesh (topology checked).
  void buildElements(const std::string& owner);
  /// The bytes this model and a run of it take, about (requireMemory before building).
  double memoryEstimate() const;
  /// Rows C of the reference conditions C q_n = 0 (Doc003, B2; kNodeDofs x nodal coordinates).
  MatX referenceConditions(const Invariants& nodal, const std::string& owner) const;
  /// B2 times the modal basis P (normal modes or Craig-Bampton, then inertia modes), or
  /// B2 unchanged without a reduction.
  SpMat reduced(SpMat B2, const Invariants& nodal, const std::string& owner);
  /// basis_, the element bases and the invariants with the nodes' shapes, from `B`.
  void setBasis(const SpMat& B, const Invariants& nodal, const std::string& owner);

  /// Row of node `node`'s coordinate k in the nodal coordinates.
  static int dof(int node, int k) { return kNodeDofs * node + k; }
  /// The nodal rows of element e's coordinates (node 1, then node 2).
  typename Traits::ElementRows elementRows(int element) const;
  /// Element nodal coordinates in element axes (T B q_f), without allocating.
  ElementVector elementCoordinates(int element, const ConstVecRef& qf) const;

  Mesh mesh_;
  Options options_;
  std::vector<Element> elements_;
  SpMatRow basis_;
  std::vector<ElementBasis> elementBases_;  // per element, built once with basis_
  Invariants invariants_;
  std::vector<int> constraintDofs_;  // Craig-Bampton: nodal coordinate of each constraint mode
  VecX fixedInterfaceFrequencies_;   // Craig-Bampton: of the kept fixed-interface modes
  int numInertiaModes_ = 0;
};

extern template class FfrBeamModelT<PlanarBeam>;
extern template class FfrBeamModelT<SpatialBeam>;

/// The planar beam model: 3 coordinates per node, BeamElement2d, FfrInvariants.
using FfrBeamModel = FfrBeamModelT<PlanarBeam>;
/// The spatial beam model: 6 coordinates per node, BeamElement3d, FfrInvariants3d.
using FfrBeamModel3d = FfrBeamModelT<SpatialBeam>;

}  // namespace flexmbd
