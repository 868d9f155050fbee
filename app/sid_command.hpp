/// @file
/// flexmbd sid SCENE.json --body NAME --out FILE: the Standard Input Data (SID) of a spatial
/// flexible body of a scene, for other multibody codes or for a "sid_body" (docs/fe-import.md,
/// "SID").
#pragma once

#include <string>
#include <vector>

namespace flexmbd {

/// `args` are the arguments after "sid". Writes FILE; prints what it wrote (nodes, elastic
/// coordinates, mass) and, for a beam with geometric stiffening, that its stiffening is
/// written as the spin stiffness linearised about the undeformed beam (linearSpinStiffness). Returns 0; 2 on bad input (one line "flexmbd: error: ..." naming
/// the option, the body or the file).
int runSidCommand(const std::vector<std::string>& args);

}  // namespace flexmbd
