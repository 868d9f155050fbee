/// @file
/// The data of a flexible body exported from a finite element code (Abaqus, Ansys: the
/// readers in fe_import/fe_abaqus.hpp and fe_import/fe_ansys.hpp): nodes, elements, node sets, the
/// degree-of-freedom map and the sparse mass and stiffness matrices. docs/fe-import.md.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "core/types.hpp"

namespace flexmbd {

/// An element of the mesh, for viewing and stresses: its type as the FE code names it
/// ("C3D8", "Hex8") and its nodes (indices into FeBodyData::nodeIds, the code's order).
struct FeElement {
  int id = 0;
  std::string type;
  std::vector<int> nodes;
};

/// What a global degree of freedom (a row of the matrices) moves: node index and direction
/// (0, 1, 2: the translations along x, y, z; 3, 4, 5: the rotations about x, y, z, which
/// the nodes of beams and shells have: 6 DOF per node).
struct FeDof {
  int node = 0;
  int direction = 0;
  bool isRotation() const { return direction >= 3; }
};

struct FeBodyData {
  std::string source;             ///< the files read, for messages
  std::vector<int> nodeIds;       ///< the FE code's node numbers
  std::vector<Vec3> coordinates;  ///< undeformed positions, same order
  std::vector<FeElement> elements;
  std::map<std::string, std::vector<int>> nodeSets;  ///< node indices, by set name
  std::vector<FeDof> dofs;                           ///< one per row of mass and stiffness
  SpMat mass;                                        ///< symmetric, both triangles stored
  SpMat stiffness;                                   ///< symmetric, both triangles stored

  int numNodes() const { return static_cast<int>(nodeIds.size()); }
  int numDofs() const { return static_cast<int>(dofs.size()); }
  /// The index of node number `id`, or -1.
  int nodeIndex(int id) const;
  /// dofIndex()[3 a + k]: the row of node a's translation along k.
  std::vector<int> dofIndex() const;
  /// rotationIndex()[3 a + k]: the row of node a's rotation about k, or -1 (a solid node).
  std::vector<int> rotationIndex() const;
  /// True if some node has rotations (a mesh of beams or shells).
  bool hasRotations() const;
  /// The rows of the DOF of `nodes` (indices into nodeIds; each node's x, y, z in turn, then
  /// its rotations, if it has them), e.g. the held DOF of clampedModes
  /// (bodies/modal_reduction.hpp).
  std::vector<int> dofsOfNodes(const std::vector<int>& nodes) const;
};

}  // namespace flexmbd
