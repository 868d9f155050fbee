/// @file
/// Reader of a body exported from Abaqus: the input file (.inp: *Node, *Element, *Nset)
/// and the matrices written by *MATRIX GENERATE / *MATRIX OUTPUT, FORMAT=COORDINATE
/// (.mtx: lines "row column value", 1-based global DOF numbers, both triangles).
/// docs/fe-import.md.
#pragma once

#include <string>

#include "bodies/fe_body_data.hpp"

namespace flexmbd {

/// The body of `inpPath` with the mass and stiffness of `massPath`, `stiffnessPath`.
/// Nodes: every *Node line "label, x, y, z" (labels unique; the DOF numbers of the
/// matrices run 3 per node, x y z, over the nodes in ascending label order, Abaqus's
/// numbering of a single-instance model); *Element, type=C3D4/C3D6/C3D8/C3D10/C3D15/C3D20
/// (with suffixes R, I, H, M, T: e.g. C3D8R) lines "label, n1, ..." (continued on the next
/// line after a trailing comma); *Nset, nset=NAME [, generate] (also *Node, nset=); other
/// keywords and their data are skipped.
/// @throws InputError naming the file, the line and what was expected: a malformed line,
/// an unknown element type, a node used but not defined, a label given twice, a matrix
/// entry outside 3 x (number of nodes) or given twice, a non-symmetric matrix
/// (feread::kSymmetryTolerance), a DOF without stiffness, a non-positive total mass.
FeBodyData readAbaqusFe(const std::string& inpPath, const std::string& massPath, const std::string& stiffnessPath);

}  // namespace flexmbd
