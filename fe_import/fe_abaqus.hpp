/// @file
/// Reader of a body exported from Abaqus: the input file (.inp: *Node, *Element, *Nset)
/// and the matrices written by *MATRIX GENERATE / *MATRIX OUTPUT, in either format:
/// FORMAT=MATRIX INPUT (Abaqus's default: lines "node, DOF, node, DOF, value", DOF 1 to 6)
/// or FORMAT=COORDINATE (lines "row column value", 1-based global DOF numbers).
/// docs/fe-import.md.
#pragma once

#include <string>
#include <vector>

#include "bodies/fe_body_data.hpp"

namespace flexmbd {

/// The body of `inpPath` with the mass and stiffness of `massPath`, `stiffnessPath`.
/// Mesh: fe_import/fe_inp.hpp (solids, beams, shells, MASS, ROTARYI). DOF map:
///  - MATRIX INPUT: the (node, DOF) pairs the two files name, ordered by node label, then
///    DOF; one triangle (mirrored) or both (checked) stored;
///  - COORDINATE: 3 DOF per node (x y z) for a solid mesh, 6 (x y z and the rotations) for a
///    mesh of beams and shells, over the nodes in ascending label order (Abaqus's numbering
///    of a single-instance model); both triangles stored.
/// Every node must have its three translations and either none or all three rotations.
/// @throws InputError naming the file, the line and what was expected: a malformed line,
/// an unknown element type, a node used but not defined, a label given twice, a matrix
/// entry outside the DOF or given twice, a DOF outside 1 to 6, the two matrices in
/// different formats, COORDINATE for a mesh mixing solids with beams or shells, a
/// non-symmetric matrix (feread::kSymmetryTolerance), a DOF without stiffness, a
/// non-positive total mass.
FeBodyData readAbaqusFe(const std::string& inpPath, const std::string& massPath, const std::string& stiffnessPath);

/// The stiffness of `body` prestressed by a preload (docs/fe-import.md, "Spin
/// stiffening"), exported by Abaqus's *MATRIX GENERATE in a perturbation step after the
/// preload step, in FORMAT=MATRIX INPUT (the DOF it names are those the run kept), as a
/// matrix in `body`'s DOF order; `held` gets the body's DOF the file does not name (the
/// preload run's supports; their rows and columns are zero).
/// @throws InputError naming the file and line: another format, a node or DOF the body does
/// not have, and the matrix errors of readAbaqusFe.
SpMat readAbaqusPreloadedStiffness(const std::string& path, const FeBodyData& body, std::vector<int>& held);

}  // namespace flexmbd
