/// @file
/// `flexmbd run SCENE.json --out DIR` for tensegrity scenes ("model": "tensegrity"):
/// writes DIR/results.csv, DIR/events.csv and DIR/summary.json (docs/tensegrity.md), and
/// with --vtk the frames DIR/vtk/bodies_NNNNNN.vtu and DIR/vtk/bodies.pvd.
#pragma once

#include <optional>
#include <string>

namespace flexmbd {

struct TensegrityRunOptions {
  std::string scenePath;
  std::string outDir;
  std::optional<double> tEnd;  ///< overrides solver.t_end
  std::optional<double> rtol;  ///< massless_cables only: overrides solver.rtol
  std::optional<double> atol;  ///< massless_cables only: overrides solver.atol
  bool quiet = false;
  bool vtk = false;  ///< also write DIR/vtk/bodies_NNNNNN.vtu (nodes and members) and bodies.pvd
};

/// True if SCENE is a tensegrity scene (then runTensegrityCommand handles it).
bool isTensegrityScene(const std::string& scenePath);

/// Exit status as `run`: 0 ok; 1 solver failure (rows up to the failure kept,
/// summary.json "failed" with the step, time and cause); 2 bad input (one line
/// "flexmbd: error: ..." on stderr, no results.csv).
int runTensegrityCommand(const TensegrityRunOptions& options);

}  // namespace flexmbd
