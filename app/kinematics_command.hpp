/// @file
/// flexmbd kinematics SCENE.json --out DIR: kinematic analysis of a planar linkage
/// (docs/kinematics.md), results per input step in DIR/kinematics.csv and DIR/summary.json.
#pragma once

#include <string>
#include <vector>

namespace flexmbd {

/// Runs the command; `args` are the arguments after "kinematics". Returns the exit
/// status: 0 the run reached the end; 1 it stopped at a singular position (lock, dead
/// or change point; the steps before it are kept); 2 bad command line, scene or model
/// (one line "flexmbd: error: ..." on stderr, no kinematics.csv).
int runKinematicsCommand(const std::vector<std::string>& args);


}  // namespace flexmbd
