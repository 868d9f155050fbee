/// @file
/// flexmbd summary DIR: the run's DIR/summary.json printed readably (docs/results.md).
#pragma once

#include <string>
#include <vector>

namespace flexmbd {

/// `args` are the arguments after "summary": DIR (or the summary.json file itself).
/// Prints the summary of a run of `flexmbd run` (multibody or tensegrity) or of
/// `flexmbd kinematics` on stdout and returns 0; returns 2 with one line
/// "flexmbd: error: ..." on stderr when DIR/summary.json is missing or malformed.
int runSummaryCommand(const std::vector<std::string>& args);

}  // namespace flexmbd
