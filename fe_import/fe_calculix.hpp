/// @file
/// Reader of a body exported from CalculiX (ccx): the input deck (.inp, the Abaqus keyword
/// format: *NODE, *ELEMENT, *NSET) and the matrices that *FREQUENCY, SOLVER=MATRIXSTORAGE
/// writes: jobname.sti (stiffness) and jobname.mas (mass), lines "row column value" with
/// 1-based equation numbers, the upper triangle (row <= column) of the symmetric matrix,
/// and jobname.dof, line i "node.direction" (e.g. "12.3": node 12, z) naming what equation
/// i moves; a DOF held by *BOUNDARY has no equation. Also a reader of the nodal result
/// blocks of the .frd file (mode shapes DISP, stresses STRESS, ...). docs/fe-import.md,
/// "CalculiX".
#pragma once

#include <map>
#include <string>
#include <vector>

#include "bodies/fe_body_data.hpp"
#include "bodies/fe_stress.hpp"
#include "core/types.hpp"

namespace flexmbd {

/// The files of one CalculiX matrix export.
struct CalculixFeFiles {
  std::string inp;        ///< the input deck: nodes, elements, node sets
  std::string stiffness;  ///< jobname.sti
  std::string mass;       ///< jobname.mas
  std::string dofs;       ///< jobname.dof
  /// The files of the job `jobname` (a path without extension): jobname.inp, .sti, .mas, .dof.
  static CalculixFeFiles ofJob(const std::string& jobname);
};

/// The body of a CalculiX export: the mesh of the deck (feread::readInpMesh: nodes in
/// ascending label order, element types C3D4/C3D6/C3D8/C3D10/C3D15/C3D20 with suffixes,
/// e.g. C3D8R, C3D20R; *NSET with GENERATE; keywords case-insensitive), equation i the
/// node and direction of line i of the .dof file. Every node needs its three directions:
/// the free matrices (no *BOUNDARY in the exporting deck), every node in an element.
/// @throws InputError naming the file, the line and what was expected: a malformed line
/// of any file, a .dof entry naming a node the deck does not define or a direction other
/// than 1, 2, 3, a (node, direction) given twice or missing, a matrix entry outside the
/// .dof's equations or given twice or below the diagonal, a DOF without stiffness, a
/// non-positive total mass (feread::checkBodyData).
FeBodyData readCalculixFe(const CalculixFeFiles& files);

/// A prestressed stiffness of `body` exported by ccx (docs/fe-import.md, "Spin
/// stiffening"): the deck of the body (the same nodes at the same places) with a *STATIC
/// preload step (e.g. *DLOAD CENTRIF) and a *STEP, PERTURBATION with *FREQUENCY,
/// SOLVER=MATRIXSTORAGE: jobname.sti over the equations of jobname.dof, returned in the
/// body's DOF order (n x n). `held` receives the body's DOF that have no equation (held by
/// *BOUNDARY in the preload run; their rows and columns are zero).
/// @throws InputError naming the file: another mesh, and the .dof and matrix errors of
/// readCalculixFe.
SpMat readCalculixPreloadedStiffness(const CalculixFeFiles& files, const FeBodyData& body, std::vector<int>& held);

/// One result block of a .frd step ("-4  DISP  4  1" and its data lines).
struct FrdBlock {
  std::string name;                           ///< "DISP", "STRESS", "ERROR", ...
  std::vector<std::string> components;        ///< the stored components, in the lines' order
                                              ///< ("D1", "D2", "D3"; "SXX" "SYY" "SZZ" "SXY" "SYZ" "SZX")
  std::map<int, std::vector<double>> values;  ///< node number -> one value per component
};

/// The results of one step (a mode of a frequency analysis, an increment of a static one):
/// the blocks that share its "100C" header's step number.
struct FrdStep {
  int number = 0;        ///< the step number of the header (NUMSTP; the mode number of a frequency analysis)
  int type = 0;          ///< the header's analysis type (ICTYPE): 0 static, 1 time step, 2 frequency, ...
  std::string analysis;  ///< the header's analysis text, trimmed ("MODAL", "STATIC")
  double value = 0.0;    ///< the header's value: a mode's frequency (cycles/time; 0 for lambda < 0), a step's time
  int mode = 0;          ///< the mode number ("1PMODE" parameter line), 0 if not given
  std::map<std::string, FrdBlock> blocks;  ///< by block name
};

/// The nodal results of a CalculiX .frd file (ASCII, as ccx writes it).
struct FrdResults {
  std::map<int, Vec3> nodes;  ///< the node block ("2C"): node number -> coordinates
  std::vector<FrdStep> steps;
};

/// Reads the node block and the nodal result blocks of the ASCII .frd file `path`; the
/// element block and the header's user lines are skipped. Fixed columns as ccx writes
/// them: data lines " -1" + node (I10 in the long format, I5 in the short one) + values
/// (E12.5 each, at most 6 per line, " -2" continuation lines for more); components marked
/// as computed by the viewer (IEXIST = 1, e.g. DISP's "ALL") have no value in the lines.
/// @throws InputError naming the file, the line and what was expected: a binary file, a
/// malformed header or data line, a component count other than the block header's, a
/// node given twice in a block or not in the node block, a node count other than the
/// header's, a block name given twice in a step, a block not closed by " -3", no "9999"
/// at the end (an unfinished run).
FrdResults readCalculixFrd(const std::string& path);

/// The steps of `frd` with both a DISP and a STRESS block (CalculiX *NODE FILE U and
/// *EL FILE S): every node of `data` must have both.
/// @throws InputError naming `owner`, the file and the step: no such step, a node of the
/// body missing from a block.
FeStressSamples stressSamplesFromFrd(const FrdResults& frd, const FeBodyData& data, const std::string& frdPath,
                                     const std::string& owner);

}  // namespace flexmbd
