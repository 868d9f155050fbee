/// @file
/// A tensegrity (pin-jointed truss): point-mass nodes in 2D or 3D, struts (axially
/// elastic bars with their own mass), tension-only cables (elastic or inextensible),
/// fixed node coordinates, gravity and nodal loads with time laws. Doc001 (Tamba & Kanno;
/// docs/tensegrity.md).
///
/// Build phase: add nodes and members, then finalize(); afterwards the structure is
/// frozen and its evaluations are pure functions of (t, x, v).
/// Coordinates: the full vector x has dimension() entries per node, node by node
/// ([x0, y0, (z0), x1, ...]); the free coordinates (not fixed) are the unknowns of the
/// integrators, in the order of freeCoordinates().
#pragma once

#include <string>
#include <vector>

#include "core/time_law.hpp"
#include "core/types.hpp"
#include "tensegrity/bar_element.hpp"

namespace flexmbd {

struct TensegrityNode {
  std::string name;
  VecX position;            ///< dimension() entries
  VecX velocity;            ///< initial velocity, dimension() entries
  double mass = 0.0;        ///< point mass at the node (>= 0)
  std::vector<bool> fixed;  ///< per axis: the coordinate is held at its initial value
};

struct TensegrityStrut {
  std::string name;
  int nodeI = -1, nodeJ = -1;
  double axialStiffness = 0.0;  ///< EA > 0
  double naturalLength = 0.0;   ///< > 0
  double mass = 0.0;            ///< >= 0, distributed by massModel
  BarMassModel massModel = BarMassModel::Lumped;
  double radius = 0.0;          ///< for contact detection (>= 0)
};

struct TensegrityCable {
  std::string name;
  int nodeI = -1, nodeJ = -1;
  double axialStiffness = 0.0;  ///< EA > 0 (ignored when inextensible)
  double naturalLength = 0.0;   ///< > 0
  bool inextensible = false;
  double radius = 0.0;          ///< for contact detection (>= 0)
};

struct TensegrityLoad {
  std::string name;
  int node = -1;
  std::vector<TimeLawPtr> components;  ///< dimension() entries; null = no force on that axis
};

/// A member (strut or cable) seen as a segment, for contact detection.
struct MemberRef {
  bool isStrut = true;
  int index = -1;
};

class TensegrityStructure {
 public:
  /// @throws InputError unless dimension is 2 or 3.
  explicit TensegrityStructure(int dimension);

  // ----- build phase (each throws InputError naming the object on invalid data) -----
  int addNode(const std::string& name, const VecX& position, double mass, std::vector<bool> fixed,
              const VecX& velocity);
  int addStrut(const std::string& name, int nodeI, int nodeJ, double axialStiffness, double naturalLength,
               double mass, BarMassModel massModel, double radius = 0.0);
  int addCable(const std::string& name, int nodeI, int nodeJ, double axialStiffness, double naturalLength,
               bool inextensible, double radius = 0.0);
  void addLoad(const std::string& name, int node, std::vector<TimeLawPtr> components);
  void setGravity(const VecX& g);
  /// Largest number of struts meeting at one node (default 1: the document's definition
  /// of a tensegrity, "at most one strut per node"). @throws InputError if < 1.
  void setMaxStrutsPerNode(int n);
  /// Changes a cable's natural length (prestress, release experiments). Allowed before
  /// and after finalize(). @throws InputError if not > 0.
  void setCableNaturalLength(int cable, double naturalLength);
  void setStrutNaturalLength(int strut, double naturalLength);

  /// Checks the model and freezes it. Rules (InputError otherwise): every member joins
  /// two different nodes; no two members join the same pair of nodes; at most
  /// maxStrutsPerNode struts per node; every free coordinate carries mass (nodal or from
  /// a strut); initial velocities of fixed coordinates are zero; members have non-zero
  /// initial length.
  void finalize();
  bool finalized() const { return finalized_; }

  // ----- queries -----
  int dimension() const { return dim_; }
  int numNodes() const { return static_cast<int>(nodes_.size()); }
  int numStruts() const { return static_cast<int>(struts_.size()); }
  int numCables() const { return static_cast<int>(cables_.size()); }
  const TensegrityNode& node(int i) const { return nodes_.at(i); }
  const TensegrityStrut& strut(int i) const { return struts_.at(i); }
  const TensegrityCable& cable(int i) const { return cables_.at(i); }
  const std::vector<TensegrityLoad>& loads() const { return loads_; }
  const VecX& gravity() const { return gravity_; }
  int findNode(const std::string& name) const;  ///< -1 if absent
  bool allCablesInextensible() const;
  bool anyCableInextensible() const;
  std::string memberName(const MemberRef& m) const;
  std::vector<MemberRef> members() const;
  /// Node indices of a member.
  std::pair<int, int> memberNodes(const MemberRef& m) const;
  double memberRadius(const MemberRef& m) const;

  // ----- after finalize() -----
  int numCoordinates() const { return dim_ * numNodes(); }
  int numFreeCoordinates() const { return static_cast<int>(free_.size()); }
  /// Full-vector indices of the free coordinates.
  const std::vector<int>& freeCoordinates() const { return free_; }
  /// Free index of a full coordinate index, -1 if that coordinate is fixed.
  int freeIndexOf(int fullIndex) const { return freeIndexOf_.at(fullIndex); }
  VecX initialPositions() const;   ///< full
  VecX initialVelocities() const;  ///< full
  /// Full vector from the free part, fixed coordinates from `fullTemplate`.
  VecX expand(const VecX& freePart, const VecX& fullTemplate) const;
  VecX restrict(const VecX& full) const;

  /// Constant full mass matrix (nodal masses + strut masses), numCoordinates() square.
  const MatX& fullMassMatrix() const { return massFull_; }
  /// Its free-free block: positive definite after finalize().
  const MatX& massMatrix() const { return massFree_; }

  /// External nodal forces at time t (gravity M g and loads), full vector.
  VecX externalForces(double t) const;
  /// The loads' part of externalForces (no gravity): the forces whose work is the input
  /// of energy that potentialEnergy does not contain.
  VecX loadForces(double t) const;
  /// Elastic forces of struts and of elastic cables, g(x) = dU/dx (full vector): the
  /// equations of motion read M a = f(t) - g(x) - B_c^T tau (inextensible part; Doc001).
  VecX internalForces(const VecX& x) const;
  /// Current cable lengths.
  VecX cableLengths(const VecX& x) const;
  /// Axial force of strut i at positions x, N = EA (l - l0) / l0 (BarElement, Doc001; tension
  /// positive, a compressed strut negative). No allocation.
  double strutForce(const VecX& x, int i) const;
  /// Length of strut i at positions x.
  double strutLength(const VecX& x, int i) const;
  /// Tensions of the elastic cables at positions x (inextensible: 0).
  VecX elasticCableTensions(const VecX& x) const;
  /// Length gradient of cable c restricted to the free coordinates (row of B_c).
  RowVecX cableGradientFree(const VecX& x, int c) const;
  /// The same row as (free index, value) pairs: at most 2 dimension() entries.
  std::vector<std::pair<int, double>> cableGradientEntries(const VecX& x, int c) const;

  double kineticEnergy(const VecX& vFull) const;
  /// Strut strain energy + elastic cable energy + gravity potential -x^T M g (loads
  /// given by time laws are not included: they need not derive from a potential).
  double potentialEnergy(const VecX& x) const;

 private:
  void requireBuild(const char* what) const;
  void requireNode(int i, const std::string& owner) const;
  template <int D>
  void addInternalForces(const VecX& x, VecX& g) const;

  int dim_;
  int maxStrutsPerNode_ = 1;
  bool finalized_ = false;
  std::vector<TensegrityNode> nodes_;
  std::vector<TensegrityStrut> struts_;
  std::vector<TensegrityCable> cables_;
  std::vector<TensegrityLoad> loads_;
  VecX gravity_;
  std::vector<int> free_;
  std::vector<int> freeIndexOf_;  ///< full index -> free index, -1 if fixed
  MatX massFull_, massFree_;
};

}  // namespace flexmbd
