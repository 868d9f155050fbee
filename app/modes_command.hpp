/// @file
/// flexmbd modes SCENE --out DIR [--at T] [--count N] [--sweep NAME:FROM:TO:N]: the
/// linearised equations of motion about a state of the scene, their modes, and a Campbell
/// diagram over a speed range (docs/modes.md).
#pragma once

#include <string>
#include <vector>

namespace flexmbd {

/// `args` are the arguments after "modes". Writes DIR/modes.csv, DIR/mode_shapes.csv,
/// DIR/vtk/mode_NN.pvd (+ .vtu frames), with --sweep DIR/campbell.csv and campbell.png;
/// prints a table and the natural frequencies of every beam body's model. Returns 0;
/// 1 if a solver failed (the simulation to --at T, an eigensolver that did not converge:
/// SolverError) or the plot failed; 2 on bad input (one line "flexmbd: error: ..."
/// naming the option, key, body or driver).
int runModesCommand(const std::vector<std::string>& args);

}  // namespace flexmbd
