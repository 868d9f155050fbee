// flexmbd: the command line.
//   flexmbd run SCENE.json --out DIR [--t-end T] [--rtol R] [--atol A] [--format csv|hdf5] [--quiet]
//                                    [--sensitivity PATH ...] [--no-sensitivity-error-control]
//                                    [--adjoint KIND:COLUMN ...]
//     (scenes with "model": "tensegrity": app/tensegrity_command.cpp)
//   flexmbd kinematics SCENE.json --out DIR [...]   (app/kinematics_command.cpp)
//   flexmbd summary DIR                              (app/summary_command.cpp)
//   flexmbd plot DIR [DIR ...] [--columns A,B] [...] (app/plot_command.cpp)
//   flexmbd modes SCENE.json --out DIR [...]         (app/modes_command.cpp)
//   flexmbd sid SCENE.json --body NAME --out FILE    (app/sid_command.cpp)
//   flexmbd view DIR [--out FILE.html] [...]         (app/view_command.cpp)
//   flexmbd --help | --version
// Exit status: 0 ok; 1 the solver failed during the run (the rows up to the failure are
// kept in DIR/results.csv or results.h5, DIR/summary.json says "failed"); 2 bad input (command line,
// scene file, model that cannot be set up): one line "flexmbd: error: ..." on stderr,
// no results.csv.
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <exception>
#include <filesystem>
#include <iostream>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "app/command_line.hpp"
#include "app/kinematics_command.hpp"
#include "app/modes_command.hpp"
#include "app/sid_command.hpp"
#include "app/plot_command.hpp"
#include "app/summary_command.hpp"
#include "app/tensegrity_command.hpp"
#include "app/view_command.hpp"
#include "core/errors.hpp"
#include "core/number_text.hpp"
#include "simulation/simulation.hpp"
#include "results/output_lock.hpp"
#include "scene/json_reader.hpp"
#include "results/results_writer.hpp"
#include "scene/scene.hpp"
#include "results/adjoint_results.hpp"
#include "results/sensitivity_results.hpp"
#include "results/vtk_writer.hpp"

#ifndef FLEXMBD_VERSION
#define FLEXMBD_VERSION "0.1.0"  // keep in step with project(VERSION) in CMakeLists.txt
#endif

namespace {

using namespace flexmbd;
using namespace flexmbd::cli;

using cli::kExitOk;
constexpr int kExitSolverFailure = cli::kExitFailure;
using cli::kExitInputError;

const char* const kUsage =
    "usage: flexmbd run SCENE.json --out DIR [--t-end T] [--rtol R] [--atol A]\n"
    "                   [--format csv|hdf5] [--vtk] [--quiet]\n"
    "                   [--sensitivity PATH ...] [--no-sensitivity-error-control]\n"
    "                   [--adjoint KIND:COLUMN ...]\n"
    "       flexmbd kinematics SCENE.json --out DIR [--steps N] [--tolerance T]\n"
    "                          [--corrector newton|modified_newton] [--quiet]\n"
    "       flexmbd summary DIR\n"
    "       flexmbd plot DIR [DIR ...] [--columns A,B] [--x COLUMN] [--out FILE.png]\n"
    "                    [--labels L1,L2] [--title TEXT] [--deg]\n"
    "       flexmbd modes SCENE.json --out DIR [--at T] [--count N] [--steady]\n"
    "                     [--sweep NAME:FROM:TO:N] [--solver auto|dense|sparse]\n"
    "                     [--sensitivity PATH ...]\n"
    "       flexmbd sid SCENE.json --body NAME --out FILE.SID_FEM\n"
    "       flexmbd view DIR [--out FILE.html] [--columns A,B] [--scene SCENE.json]\n"
    "                    [--max-frames N]\n"
    "       flexmbd --help\n"
    "       flexmbd --version\n"
    "\n"
    "run simulates the model described by SCENE.json: a multibody model, planar or spatial\n"
    "(\"dimension\": 3), of rigid and flexible bodies (see docs/scene-format.md), or a\n"
    "tensegrity structure (\"model\": \"tensegrity\", docs/tensegrity.md); it writes\n"
    "DIR/results.csv (one row per output time; results.h5 with --format hdf5) and\n"
    "DIR/summary.json.\n"
    "\n"
    "options of run:\n"
    "  --out DIR    output directory (created if needed; required)\n"
    "  --t-end T    end time, overrides solver.t_end of the scene\n"
    "  --rtol R     relative tolerance, overrides solver.rtol; without --atol it also\n"
    "               scales every absolute tolerance by R / solver.rtol\n"
    "  --atol A     absolute tolerance of frame positions (m), overrides solver.atol and\n"
    "               scales the class tolerances the scene sets (atol_angle, atol_elastic,\n"
    "               atol_velocity) by A / solver.atol; unset classes follow atol by their\n"
    "               defaults: angles atol (in rad), velocities atol per second,\n"
    "               elastic coordinates atol (docs/scene-format.md).\n"
    "               So tightening either tightens every output; summary.json lists the\n"
    "               tolerances used under \"tolerances\"\n"
    "  --format F   results file: csv (default, DIR/results.csv) or hdf5 (DIR/results.h5:\n"
    "               dataset /results, rows x columns, and /columns, the CSV header names)\n"
    "  --vtk        also write DIR/vtk/bodies_NNNNNN.vtu per output and bodies.pvd (ParaView;\n"
    "               bodies, or the nodes and members of a tensegrity scene)\n"
    "  --quiet, -q  no progress display\n"
    "  --sensitivity PATH  (repeatable) forward sensitivities with respect to the scene's\n"
    "               number at PATH (a dotted path such as bodies[1].mass or\n"
    "               forces[0].stiffness): results get a column d<column>/d<PATH> per\n"
    "               column, summary.json \"sensitivities\" the gradients of the final and\n"
    "               largest values (IDAS; docs/sensitivities.md)\n"
    "  --no-sensitivity-error-control  the sensitivities out of the local error test\n"
    "  --adjoint KIND:COLUMN  (repeatable) instead of the derivative columns: the gradient\n"
    "               of the integral output KIND:COLUMN with respect to every --sensitivity\n"
    "               parameter by the adjoint method (one backward run per output, whatever\n"
    "               the number of parameters); KIND integral (int c dt), integral_square\n"
    "               (int c^2 dt), final (c(T)) or ks (ks:COLUMN:RHO, a smooth maximum) of a\n"
    "               coordinate, velocity or scene output column;\n"
    "               summary.json \"sensitivities\" gets the values and gradients\n"
    "  --help, -h   this text\n"
    "\n"
    "kinematics analyses the linkage of SCENE.json (see docs/kinematics.md) step by step in\n"
    "its input and writes DIR/kinematics.csv (positions, transfer functions, velocities,\n"
    "accelerations, corrector iterations and residual per step) and DIR/summary.json.\n"
    "options of kinematics: --out DIR (required); --steps N, --tolerance T, --corrector C\n"
    "override analysis.steps, .tolerance, .corrector of the scene; --quiet, -q as for run\n"
    "(kinematics has no progress display).\n"
    "\n"
    "summary prints DIR/summary.json of a run (run or kinematics) as a short report.\n"
    "\n"
    "plot draws results columns of one or more runs (DIR/results.csv, or kinematics.csv)\n"
    "into a PNG with /usr/bin/python3 and matplotlib (scripts/plot_results.py; see\n"
    "docs/results.md): --columns the columns (default: the rigid body coordinates), --x the\n"
    "column of the horizontal axis (default t, or alpha), --out the PNG (default\n"
    "DIR/plot.png), --labels one legend label per DIR, --title, --deg angles in degrees.\n"
    "Units follow from the column names; the path of the PNG is printed.\n"
    "\n"
    "modes linearises the equations of motion of SCENE.json (planar or spatial) about its\n"
    "consistent state at t_start (solved for static equilibrium if at rest; --at T: the\n"
    "state simulated to T) and writes DIR/modes.csv (frequencies, damping ratios,\n"
    "eigenvalues), DIR/mode_shapes.csv (one column per mode) and DIR/vtk/mode_NN.pvd; it\n"
    "prints them with the natural frequencies of every beam body's model. --count N modes\n"
    "(default 10). --sweep NAME:FROM:TO:N: the modes at N speeds of the constant_speed\n"
    "driver or of the initial spin of the body NAME, DIR/campbell.csv and campbell.png\n"
    "(see docs/modes.md). --steady: the state is the steady motion at the initial velocities\n"
    "(accelerations zero: a rotor stretched by its centrifugal load), solved by Newton.\n"
    "--solver: dense (Eigen), sparse (Spectra shift-invert) or auto (dense up to 400\n"
    "independent coordinates). --sensitivity PATH (repeatable): the derivatives of the\n"
    "modes.csv columns with respect to the scene number at PATH (eigenvalue sensitivities,\n"
    "docs/modes.md), columns d<column>/d<PATH>.\n"
    "\n"
    "sid writes the Standard Input Data (SID, Wallrapp 1994) of the spatial flexible body\n"
    "NAME of SCENE.json to FILE: a reduced body for other multibody codes, or for a\n"
    "\"sid_body\" of a flexmbd scene (see docs/fe-import.md, \"SID\").\n"
    "\n"
    "view writes one HTML page (DIR/view.html, or --out) that animates the run in DIR in\n"
    "a browser, offline (three.js inside): bodies, joints and the ground, a colour map\n"
    "of deflection or section forces, play/pause, speed, a time slider, plots of results\n"
    "columns with a cursor (--columns, default the scene's outputs or body positions).\n"
    "For a folder of flexmbd modes it animates each mode shape. The scene is the one the\n"
    "run recorded in summary.json (--scene to give another); --max-frames N draws at\n"
    "most N of the output times (default 1000). See docs/viewer.md.\n"
    "\n"
    "A scene of the other command is refused with a message naming the command it is for.\n"
    "\n"
    "exit status: 0 success; 1 solver failure during the run, or kinematics stopped at a\n"
    "singular position (results up to there are kept), or the eigensolver of modes did not\n"
    "converge, or plot could not draw (no matplotlib); 2 invalid command line, scene or\n"
    "model (nothing is integrated), a missing or malformed summary.json, an unknown\n"
    "results column.\n";


struct Options {
  bool help = false;
  bool version = false;
  std::string scenePath;
  std::string outDir;
  std::optional<double> tEnd, rtol, atol;
  bool quiet = false;
  bool vtk = false;  ///< also write DIR/vtk/bodies_*.vtu and bodies.pvd
  ResultsFormat format = ResultsFormat::Csv;  ///< --format
  std::vector<std::string> sensitivities;  ///< --sensitivity PATH (repeatable), in order
  bool sensitivityErrorControl = true;     ///< off with --no-sensitivity-error-control
  std::vector<std::string> adjoint;        ///< --adjoint KIND:COLUMN (repeatable), in order
};

/// Takes the repeatable --sensitivity PATH (or --sensitivity=PATH) out of `args` into `o`.
void takeSensitivityOptions(std::vector<std::string>& args, Options& o) {
  o.sensitivities = cli::takeRepeatedOption(args, "--sensitivity", cli::kSensitivityPathNeeded);
  o.adjoint = cli::takeRepeatedOption(args, "--adjoint",
                                      "an integral output KIND:COLUMN (e.g. --adjoint integral_square:slider.x)");
  std::vector<std::string> rest;
  for (const std::string& a : args) {
    if (a == "--no-sensitivity-error-control") {
      o.sensitivityErrorControl = false;
    } else {
      rest.push_back(a);
    }
  }
  args = rest;
}

/// Significant digits of times and CPU seconds in messages (fmt, core/number_text.hpp).
constexpr int kNumberDigits = 6;

Options parseCommandLine(int argc, char** argv) {
  Options o;
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty()) throw UsageError("no command given (try 'flexmbd --help')");
  for (const auto& a : args) {
    if (a == "--help" || a == "-h") {
      o.help = true;
      return o;
    }
  }
  if (args[0] == "--version" || args[0] == "-V") {
    if (args.size() > 1) throw UsageError("--version takes no arguments");
    o.version = true;
    return o;
  }
  if (args[0] == "help") {
    o.help = true;
    return o;
  }
  if (args[0] != "run") {
    throw UsageError("unknown command '" + args[0] +
                     "' (expected 'run', 'kinematics', 'summary', 'plot', 'modes', 'sid', 'view', '--help' or '--version')");
  }
  takeSensitivityOptions(args, o);
  const cli::SplitArguments split =
      cli::splitArguments({args.begin() + 1, args.end()},
                          cli::withCommon(cli::kCommonValueOptions, {"--t-end", "--rtol", "--atol", "--format"}),
                          cli::withCommon(cli::kCommonFlags, {{"--vtk", "--vtk"}}), "run: ");
  o.quiet = split.flags.count("--quiet") > 0;
  o.vtk = split.flags.count("--vtk") > 0;
  for (const auto& [name, value] : split.values) {
    if (name == "--out") {
      if (value.empty()) throw UsageError("option --out needs a directory");
      o.outDir = value;
    } else if (name == "--t-end") {
      o.tEnd = parseNumberOption(name, value);
    } else if (name == "--format") {
      try {
        o.format = parseResultsFormat(value);
      } catch (const std::invalid_argument&) {
        throw UsageError("option --format expects csv or hdf5, got '" + value + "'");
      }
    } else if (name == "--rtol") {
      o.rtol = parsePositiveOption(name, value);
    } else {
      o.atol = parsePositiveOption(name, value);
    }
  }
  const std::vector<std::string>& positional = split.positional;
  if (positional.empty()) throw UsageError("run: missing the scene file (flexmbd run SCENE.json --out DIR)");
  if (positional.size() > 1) {
    throw UsageError("run: expected one scene file, got " + std::to_string(positional.size()) + " arguments ('" +
                     positional[0] + "', '" + positional[1] + "', ...)");
  }
  o.scenePath = positional[0];
  if (o.outDir.empty()) throw UsageError("run: missing --out DIR (the output directory)");
  return o;
}


/// Input error once the output directory is known: no results.csv, a summary.json that
/// says why (best effort: a failure to write it must not hide the original error).
int reportInputError(const std::filesystem::path& outDir, const std::string& message) {
  try {
    removeStaleResults(outDir);
    writeInputErrorSummary(outDir, oneLine(message));
  } catch (...) {
  }
  printError(message);
  return kExitInputError;
}

/// The run with forward sensitivities (docs/sensitivities.md): each output row with its
/// d<column>/d<parameter> values, their gradients summarised (runSensitivityScene).
SimulationSummary runWithSensitivities(const Scene& scene, const SensitivityScenes& sensitivities, bool errorControl,
                                       ResultsWriter& writer, std::optional<VtkWriter>& vtk,
                                       SensitivitySummary& gradients) {
  return runSensitivityScene(scene, sensitivities, errorControl,
                             [&](const OutputSample& sample, const std::vector<double>& derivatives) {
                               writer.write(sample, derivatives);
                               gradients.add(writer.lastRow(), derivatives);
                               if (vtk) vtk->write(sample);
                               if (sample.t < scene.solver.tEnd) stopIfSignalled(sample.t);
                             });
}

/// What the run computes besides its results: the command line's --sensitivity and
/// --adjoint lists, each where given and the scene's "sensitivity" lists otherwise; the
/// error control off if either says so (docs/sensitivities.md, "Requesting sensitivities").
/// @throws InputError: adjoint outputs without parameters, or with the error control off.
SensitivityRequest sensitivityRequest(const Options& o, const SensitivityRequest& scene) {
  SensitivityRequest r;
  r.parameters = o.sensitivities.empty() ? scene.parameters : o.sensitivities;
  r.adjoint = o.adjoint.empty() ? scene.adjoint : o.adjoint;
  r.errorControl = o.sensitivityErrorControl && scene.errorControl;
  if (!r.adjoint.empty() && r.parameters.empty()) {
    throw InputError("option --adjoint needs the parameters of its gradients: one --sensitivity PATH or more (or the "
                     "scene's sensitivity.parameters)");
  }
  if (!r.adjoint.empty() && !r.errorControl) {
    throw InputError(std::string(o.sensitivityErrorControl ? "the scene's sensitivity.error_control false"
                                                           : "option --no-sensitivity-error-control") +
                     " is for the forward sensitivities, not with adjoint outputs (" +
                     (o.adjoint.empty() ? "the scene's sensitivity.adjoint" : "--adjoint") + ")");
  }
  return r;
}

int runCommand(const Options& o) {
  if (isTensegrityScene(o.scenePath)) {  // "model": "tensegrity" (app/tensegrity_command.cpp)
    if (!o.sensitivities.empty() || !o.adjoint.empty()) {
      printError("--sensitivity and --adjoint are not available for tensegrity scenes (forward sensitivities run on the DAE "
                 "integrator IDAS: multibody scenes only)");
      return kExitInputError;
    }
    if (o.format != ResultsFormat::Csv) {
      printError("--format hdf5 is not available for tensegrity scenes (their results are results.csv and "
                 "events.csv)");
      return kExitInputError;
    }
    return runTensegrityCommand({o.scenePath, o.outDir, o.tEnd, o.rtol, o.atol, o.quiet, o.vtk});
  }
  const std::filesystem::path outDir(o.outDir);
  // One run at a time in DIR, before anything is written there (results/output_lock.hpp).
  std::optional<OutputLock> lock;
  try {
    lock.emplace(outDir);
  } catch (const std::exception& e) {
    printError(e.what());
    return kExitInputError;
  }

  // ----- input: scene, overrides, settings (exit 2 on any error) -----
  std::optional<Scene> scene;
  std::optional<SensitivityScenes> sensitivities;
  SensitivityRequest request;
  try {
    scene.emplace(loadScene(o.scenePath));
    SolverSettings& s = scene->solver;
    if (o.tEnd) {
      if (!(*o.tEnd > s.tStart)) {
        throw InputError("option --t-end must be > t_start (" + fmt(s.tStart, kNumberDigits) + ") of the scene, got " +
                         fmt(*o.tEnd, kNumberDigits));
      }
      s.tEnd = *o.tEnd;
    }
    overrideTolerances(s, o.rtol, o.atol);  // every class scaled together (simulation/tolerances.hpp)
    s.progress = !o.quiet;
    checkSolverSettings(s);
    request = sensitivityRequest(o, scene->sensitivity);
    if (!request.parameters.empty()) {  // the scene read again with each parameter one and two steps up and down
      sensitivities.emplace(
          buildSensitivityScenes(jsonread::readSceneFile(o.scenePath), o.scenePath, *scene, request.parameters));
      for (const std::string& spec : request.adjoint) integralOutput(spec, *scene, *sensitivities);  // refused before the run
    }
  } catch (const std::exception& e) {
    return reportInputError(outDir, e.what());
  }

  std::optional<ResultsWriter> writer;
  std::optional<VtkWriter> vtk;
  std::vector<std::string> sceneColumns;
  try {
    writer.emplace(outDir, *scene, o.format);
    sceneColumns = writer->columns();
    if (sensitivities && request.adjoint.empty()) {
      writer->addColumns(sensitivityColumns(sceneColumns, sensitivities->parameters));
    }
    if (o.vtk) {
      vtk.emplace(std::filesystem::path(outDir) / "vtk", scene->system, "bodies", 4, scene->geometry, scene->feBodies);
      for (const std::string& b : vtk->bodiesNotDrawn()) {
        std::cerr << "flexmbd: warning: --vtk: body \"" << oneLine(b)
                  << "\" has no points to draw (a flexible_invariants body without \"points\"); it is not in "
                     "the VTK frames"
                  << std::endl;
      }
    }
  } catch (const OutputWriteError& e) {  // a full disk (exit 1, README)
    printError(e.what());
    return kExitSolverFailure;
  } catch (const std::exception& e) {  // --vtk where DIR/vtk is a file, ...
    return reportInputError(outDir, e.what());
  }

  // ----- the run -----
  SimulationSummary summary;
  std::optional<SensitivitySummary> gradients;
  std::optional<nlohmann::json> adjointSummary;
  try {
    const StopOnSignals stop;  // a signal stops the run within its step
    if (!request.adjoint.empty()) {
      const AdjointSummary adjoint = runAdjointScene(*scene, *sensitivities, request.adjoint, [&](const OutputSample& sample) {
        writer->write(sample);
        if (vtk) vtk->write(sample);
        if (sample.t < scene->solver.tEnd) stopIfSignalled(sample.t);
      });
      summary = adjoint.run;
      adjointSummary = adjointJson(adjoint, *sensitivities);
      if (summary.ok && !adjoint.backwardOk) {  // the run's rows are kept; the gradients are not there
        summary.ok = false;
        summary.message = "the adjoint (backward) integration failed: " + adjoint.backwardMessage;
      }
    } else if (sensitivities) {
      gradients.emplace(sceneColumns, sensitivities->parameters);
      summary = runWithSensitivities(*scene, *sensitivities, request.errorControl, *writer, vtk, *gradients);
    } else {
      summary = simulateKeepingFailures(scene->system, scene->solver, [&](const OutputSample& sample) {
        writer->write(sample);
        if (vtk) vtk->write(sample);
        if (sample.t < scene->solver.tEnd) stopIfSignalled(sample.t);  // the last row: the run is complete
      });
    }
  } catch (const InputError& e) {
    // Includes ModelError: the model cannot be set up (assembly, redundant or
    // conflicting constraints). Nothing was integrated.
    return reportInputError(outDir, o.scenePath + ": " + e.what());
  }

  // The time of the last row written, not of the row whose write failed.
  if (summary.outputFailed) summary.tReached = writer->rowsWritten() > 0 ? writer->lastTime() : scene->solver.tStart;
  for (const std::string& w : summary.warnings) std::cerr << "flexmbd: warning: " << oneLine(w) << std::endl;
  const std::string kept = writer->rowsWritten() > 0
                               ? "results up to t = " + fmt(writer->lastTime(), kNumberDigits) + " kept in " +
                                     writer->resultsPath().string()
                               : "no results were written";
  const int failureStatus = summary.interruptedBySignal ? 128 + summary.interruptedBySignal : kExitSolverFailure;
  // The first error is reported first: a failed results file, then the summary's own.
  const std::string what = summary.interruptedBySignal || summary.outputFailed ? summary.message
                                                                               : "solver failure: " + summary.message;
  try {
    const nlohmann::json sensitivitySummary =
        adjointSummary ? *adjointSummary : gradients ? gradients->toJson(request.errorControl) : nlohmann::json();
    writeSummary(outDir, summary, *scene, o.scenePath, adjointSummary || gradients ? &sensitivitySummary : nullptr);
  } catch (const std::exception& e) {
    printError((summary.ok ? std::string() : what + " (" + kept + "); ") + "cannot write the summary: " + e.what());
    return summary.ok ? kExitSolverFailure : failureStatus;
  }

  if (!summary.ok) {
    printError(what + " (" + kept + ")");
    return failureStatus;
  }
  std::cout << "flexmbd: ok: t = " << fmt(summary.tReached, kNumberDigits) << " reached, " << summary.stats.steps
            << " steps, " << fmt(summary.cpuSeconds, kNumberDigits) << " s CPU; results in "
            << writer->resultsPath().string() << std::endl;
  if (scene->solver.integrator == IntegratorKind::Automatic) {
    std::cout << "flexmbd: integrator " << toString(summary.integrator) << " (auto: " << summary.integratorReason << ")"
              << std::endl;
  }
  return kExitOk;
}

int mainImpl(int argc, char** argv) {
  if (argc >= 2 && std::string(argv[1]) == "kinematics") {
    const std::vector<std::string> rest(argv + 2, argv + argc);
    bool help = false;
    for (const auto& a : rest) help = help || a == "--help" || a == "-h";
    if (!help) return runKinematicsCommand(rest);  // same exit statuses 0/1/2
  }
  if (argc >= 2 && std::string(argv[1]) == "sid") {
    const std::vector<std::string> rest(argv + 2, argv + argc);
    bool help = false;
    for (const auto& a : rest) help = help || a == "--help" || a == "-h";
    if (!help) return runSidCommand(rest);
  }
  if (argc >= 2 && std::string(argv[1]) == "view") {
    const std::vector<std::string> rest(argv + 2, argv + argc);
    bool help = false;
    for (const auto& a : rest) help = help || a == "--help" || a == "-h";
    if (!help) return runViewCommand(rest);
  }
  if (argc >= 2 && std::string(argv[1]) == "modes") {
    const std::vector<std::string> rest(argv + 2, argv + argc);
    bool help = false;
    for (const auto& a : rest) help = help || a == "--help" || a == "-h";
    if (!help) return runModesCommand(rest);
  }
  if (argc >= 2 && (std::string(argv[1]) == "summary" || std::string(argv[1]) == "plot")) {
    const std::vector<std::string> rest(argv + 2, argv + argc);
    bool help = false;
    for (const auto& a : rest) help = help || a == "--help" || a == "-h";
    if (!help) return std::string(argv[1]) == "summary" ? runSummaryCommand(rest) : runPlotCommand(rest);
  }
  Options o;
  try {
    o = parseCommandLine(argc, argv);
  } catch (const std::exception& e) {
    printError(e.what());
    return kExitInputError;
  }
  if (o.help) {
    std::cout << kUsage;
    return kExitOk;
  }
  if (o.version) {
    std::cout << "flexmbd " << FLEXMBD_VERSION << std::endl;
    return kExitOk;
  }
  return runCommand(o);
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return mainImpl(argc, argv);
  } catch (const InputError& e) {
    printError(e.what());
    return kExitInputError;
  } catch (const std::exception& e) {
    printError(std::string("unexpected failure: ") + e.what());
    return kExitSolverFailure;
  } catch (...) {
    printError("unexpected failure (unknown exception)");
    return kExitSolverFailure;
  }
}
