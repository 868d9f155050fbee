/// @file
/// flexmbd view DIR: one self-contained HTML page that animates a run (or the mode shapes
/// of `flexmbd modes`) in the browser, with plots of chosen results columns
/// (viewer/html_viewer.hpp; docs/viewer.md).
#pragma once

#include <string>
#include <vector>

namespace flexmbd {

/// `args` are the arguments after "view". Writes the page (DIR/view.html unless --out)
/// and prints its path, size and what it draws. Returns 0; 2 on bad input (one line
/// "flexmbd: error: ..." naming the folder, file, option or column); 1 if the page cannot
/// be written.
int runViewCommand(const std::vector<std::string>& args);

}  // namespace flexmbd
