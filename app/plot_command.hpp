/// @file
/// flexmbd plot DIR [DIR ...] [--columns A,B] [--x COLUMN] [--out FILE.png] [--labels L1,L2]
/// [--title T] [--deg]: results columns drawn to a PNG (docs/results.md).
#pragma once

#include <string>
#include <vector>

namespace flexmbd {

/// `args` are the arguments after "plot". Checks the directories and the column names
/// (exit 2, one line "flexmbd: error: ..." naming close matches), then runs
/// scripts/plot_results.py with Debian's /usr/bin/python3 (matplotlib from
/// python3-matplotlib) and returns its exit status: 0 the PNG was written (its path on
/// stdout); 1 it could not plot (no Python, no matplotlib, the file not written).
int runPlotCommand(const std::vector<std::string>& args);

/// Runs the plotting script `scriptName` of scripts/ (found and interpreted as for plot:
/// `<bin>/../share/flexmbd/`, then the source tree's scripts/; $FLEXMBD_PYTHON or
/// /usr/bin/python3) with `args`: its exit status, 0 or 2, any other failure 1.
/// @throws std::runtime_error if the script cannot be found or started.
int runPythonScript(const std::string& scriptName, const std::vector<std::string>& args);

}  // namespace flexmbd
