/// @file
/// Reader of a body exported from Ansys (Mechanical APDL): the mass and stiffness in
/// MatrixMarket coordinate form (as *EXPORT writes them, "real symmetric": the lower
/// triangle), the DOF mapping vector (MatrixMarket array: for each matrix node, in matrix
/// order, its node number), and the nodal coordinates and elements as tab-separated tables
/// with one header line (Mechanical's export; decimal comma accepted). docs/fe-import.md.
#pragma once

#include <string>

#include "bodies/fe_body_data.hpp"

namespace flexmbd {

/// The files of one Ansys export.
struct AnsysFeFiles {
  std::string coordinates;  ///< "node x y z" per line after a header line
  std::string elements;     ///< "element type n1 ... nk" per line after a header line
  std::string dofMap;       ///< MatrixMarket array integer, one node number per matrix node
  std::string mass;         ///< MatrixMarket coordinate real symmetric|general
  std::string stiffness;    ///< as mass
};

/// The body of an Ansys export: matrix rows 3 j + k (k = x, y, z) belong to the node the
/// DOF map names at position j. Element types Tet4, Tet10, Wedge6, Wedge15, Pyramid5,
/// Pyramid13, Hex8, Hex20.
/// @throws InputError naming the file, the line and what was expected: a malformed line
/// or header, a DOF map that is not a permutation of the nodes or whose size does not
/// match the matrices, an unknown element type or node, an entry count differing from the
/// header, an entry above the diagonal of a symmetric file, a non-symmetric "general"
/// matrix (feread::kSymmetryTolerance), a DOF without stiffness, a non-positive total mass.
FeBodyData readAnsysFe(const AnsysFeFiles& files);

}  // namespace flexmbd
