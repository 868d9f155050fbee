/// @file
/// The mesh part of an input deck in the Abaqus keyword format, which Abaqus and CalculiX
/// share (fe_import/fe_abaqus.hpp, fe_import/fe_calculix.hpp): *Node, *Element, *Nset.
/// docs/fe-import.md.
#pragma once

#include <string>

#include "bodies/fe_body_data.hpp"

namespace flexmbd::feread {

/// Which element types a deck may hold: solids only (CalculiX, whose exports number the
/// nodes of the solids it expands beams and shells into), or solids, beams and shells.
enum class InpElements { Solids, SolidsBeamsShells };

/// The nodes (ascending label order), elements and node sets of the deck `path`; no DOF
/// map and no matrices. Keywords and parameter names are case-insensitive. Nodes: every
/// *Node line "label, x, y, z" (labels unique); *Element, type=C3D4/C3D6/C3D8/C3D10/
/// C3D15/C3D20 (with suffixes R, I, H, M, T: e.g. C3D20R), B31/B32/B33 (suffix H),
/// S3/S3R/S4/S4R/S8R, MASS, ROTARYI (the last five groups with `kinds` SolidsBeamsShells
/// only), lines "label, n1, ..."
/// (continued on the next lines until the type's node count); *Nset, nset=NAME
/// [, generate] (also *Node, nset=); *Include is refused (not followed); other keywords
/// and their data are skipped.
/// @throws InputError naming the file, the line and what was expected: a malformed line,
/// an unknown element type, a node used but not defined, a label given twice, no nodes.
FeBodyData readInpMesh(const std::string& path, InpElements kinds);

}  // namespace flexmbd::feread
