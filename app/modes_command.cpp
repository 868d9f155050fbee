// flexmbd modes: linearisation and modal analysis from the command line (docs/modes.md).
#include "app/modes_command.hpp"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/command_line.hpp"
#include "app/plot_command.hpp"
#include "bodies/ffr_body_2d.hpp"
#include "bodies/ffr_body_3d.hpp"
#include "core/errors.hpp"
#include "core/number_text.hpp"
#include "analysis/linearization.hpp"
#include "sensitivity/modal_sensitivity.hpp"
#include "sensitivity/sensitivity_run.hpp"
#include "simulation/reference_by_run.hpp"
#include "simulation/simulation.hpp"
#include "scene/json_reader.hpp"
#include "results/output_lock.hpp"
#include "scene/scene.hpp"
#include "results/sensitivity_results.hpp"
#include "results/vtk_writer.hpp"

namespace flexmbd {
namespace {

namespace fs = std::filesystem;

using cli::kExitOk;
using cli::kExitFailure;
using cli::kExitInputError;
/// Frames of the VTK animation of one mode shape (one period).
constexpr int kShapeFrames = 16;
/// Largest displacement of the drawn mode shapes, as a fraction of the model's size.
constexpr double kShapeAmplitude = 0.05;
/// Largest rotation (rad) of the drawn mode shapes when no length moves.
constexpr double kShapeAngle = 0.1;

/// --sweep NAME:FROM:TO:N
struct Sweep {
  std::string name;
  double from = 0.0, to = 0.0;
  int points = 0;
};

struct ModesCommandOptions {
  std::string scenePath, outDir;
  std::optional<double> at;
  int count = 10;
  std::optional<Sweep> sweep;
  bool quiet = false;
  bool steady = false;  ///< --steady: solveSteadyMotion instead of the consistent state
  EigenSolverKind solver = EigenSolverKind::Automatic;  ///< --solver
  std::vector<std::string> sensitivities;  ///< --sensitivity PATH (repeatable), in order
};

EigenSolverKind parseSolver(const std::string& text) {
  if (text == "auto") return EigenSolverKind::Automatic;
  if (text == "dense") return EigenSolverKind::Dense;
  if (text == "sparse") return EigenSolverKind::Sparse;
  throw cli::UsageError("option --solver expects auto, dense or sparse, got '" + text + "'");
}

int parseCount(const std::string& text) {
  const double x = cli::parseNumberOption("--count", text);
  if (x != std::floor(x) || x < 1 || x > 10000) {
    throw cli::UsageError("option --count expects a whole number 1..10000, got '" + text + "'");
  }
  return static_cast<int>(x);
}

Sweep parseSweep(const std::string& text) {
  // the name may hold ':': the last three fields are FROM, TO, N
  std::vector<std::string> parts;
  std::string rest = text;
  for (int k = 0; k < 3; ++k) {
    const auto c = rest.rfind(':');
    if (c == std::string::npos) {
      throw cli::UsageError("option --sweep expects NAME:FROM:TO:N (a driver or body name, the speed range in rad/s "
                            "and the number of speeds), got '" + text + "'");
    }
    parts.insert(parts.begin(), rest.substr(c + 1));
    rest = rest.substr(0, c);
  }
  if (rest.empty()) throw cli::UsageError("option --sweep: the driver or body name is empty in '" + text + "'");
  Sweep s;
  s.name = rest;
  s.from = cli::parseNumberOption("--sweep (FROM)", parts[0]);
  s.to = cli::parseNumberOption("--sweep (TO)", parts[1]);
  const double n = cli::parseNumberOption("--sweep (N)", parts[2]);
  if (n != std::floor(n) || n < 1 || n > 1000) {
    throw cli::UsageError("option --sweep: N must be a whole number 1..1000, got '" + parts[2] + "'");
  }
  s.points = static_cast<int>(n);
  return s;
}

ModesCommandOptions parseOptions(std::vector<std::string> args) {
  std::vector<std::string> sensitivities = cli::takeRepeatedOption(args, "--sensitivity", cli::kSensitivityPathNeeded);
  const cli::SplitArguments split = cli::splitArguments(
      args, cli::withCommon(cli::kCommonValueOptions, {"--at", "--count", "--sweep", "--solver"}),
      cli::withCommon(cli::kCommonFlags, {{"--steady", "--steady"}}), "modes: ");
  ModesCommandOptions o;
  o.sensitivities = std::move(sensitivities);
  o.quiet = split.flags.count("--quiet") > 0;
  o.steady = split.flags.count("--steady") > 0;
  for (const auto& [name, value] : split.values) {
    if (name == "--out") {
      if (value.empty()) throw cli::UsageError("option --out needs a directory");
      o.outDir = value;
    } else if (name == "--at") {
      o.at = cli::parseNumberOption(name, value);
    } else if (name == "--count") {
      o.count = parseCount(value);
    } else if (name == "--solver") {
      o.solver = parseSolver(value);
    } else {
      o.sweep = parseSweep(value);
    }
  }
  if (split.positional.empty()) throw cli::UsageError("modes: missing the scene file (flexmbd modes SCENE.json --out DIR)");
  if (split.positional.size() > 1) {
    throw cli::UsageError("modes: expected one scene file, got " + std::to_string(split.positional.size()) +
                          " arguments ('" + split.positional[0] + "', '" + split.positional[1] + "', ...)");
  }
  o.scenePath = split.positional[0];
  if (o.outDir.empty()) throw cli::UsageError("modes: missing --out DIR (the output directory)");
  if (o.at && o.sweep) throw cli::UsageError("modes: --at and --sweep cannot be combined (a sweep linearises at t_start)");
  if (o.at && o.steady) throw cli::UsageError("modes: --at and --steady cannot be combined (--steady solves for the state)");
  if (!o.sensitivities.empty() && o.sweep) {
    throw cli::UsageError("modes: --sensitivity and --sweep cannot be combined (the eigenvalue sensitivities are of "
                          "one linearisation; run modes --sensitivity at each speed)");
  }
  if (!o.sensitivities.empty() && o.at) {
    throw cli::UsageError("modes: --sensitivity and --at cannot be combined (the state reached by a simulation would "
                          "be differentiated through two runs' integration errors; the sensitivities are about the "
                          "consistent state, its equilibrium or --steady)");
  }
  return o;
}

std::string readText(const std::string& path) { return jsonread::readSceneFile(path); }

std::string number(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.12g", x);
  return buf;
}

/// The sparse solver, and any model too large for the dense one, takes the sparse
/// (coordinate-partitioning) basis; the others the orthonormal one.
BasisKind basisFor(const System& sys, EigenSolverKind solver) {
  const bool sparse = solver == EigenSolverKind::Sparse ||
                      (solver == EigenSolverKind::Automatic && sys.numVelocities() > kDenseModesLimit);
  return sparse ? BasisKind::CoordinatePartitioning : BasisKind::Svd;
}

/// Redundant constraints handled as a run of the scene would ("redundant_constraints":
/// "resolve" releases the dependent equations, "refuse" names them in a ModelError).
ReleasedEquations releasedFor(const SolverSettings& s) {
  return ReleasedEquations{s.redundantConstraints == RedundantConstraints::Resolve, {}};
}

/// The state at t_start: the consistent state (an equilibrium if at rest), or with
/// `steady` the steady motion at the initial velocities.
ReferenceState initialReference(const Scene& scene, bool steady) {
  const System& sys = scene.system;
  return steady ? solveSteadyMotion(sys, scene.solver.tStart, sys.initialCoordinates(), sys.initialVelocities())
                : referenceStateAt(sys, scene.solver.tStart, sys.initialCoordinates(), sys.initialVelocities(),
                                   releasedFor(scene.solver));
}

/// The state to linearise about: initialReference, or the state reached by simulating to `at`.
/// @throws SolverError if that simulation fails.
ReferenceState findReference(const Scene& scene, std::optional<double> at, bool steady, bool quiet) {
  if (!at) return initialReference(scene, steady);
  if (!(*at > scene.solver.tStart)) {
    throw InputError("option --at must be > t_start (" + fmt(scene.solver.tStart, 6) + ") of the scene, got " +
                     fmt(*at, 6));
  }
  return referenceStateByRun(scene.system, scene.solver, *at, !quiet);
}

/// The failure to write `file`, with the system's reason.
std::runtime_error writeFailure(const fs::path& file) {
  return std::runtime_error("cannot write " + file.string() + ": " + std::strerror(errno));
}

/// The derivatives of the modes with respect to one parameter (--sensitivity).
struct ParameterModeDerivatives {
  std::string path;
  std::vector<ModeDerivative> modes;
};

/// The columns of modes.csv after index; each parameter adds d<column>/d<PATH> for them.
const std::vector<std::string> kModeColumns = {"frequency_hz", "omega_rad_s", "damping_ratio", "real", "imag"};

void writeModesCsv(const fs::path& file, const std::vector<Mode>& modes,
                   const std::vector<ParameterModeDerivatives>& derivatives) {
  std::ofstream out(file);
  out << "index";
  for (const std::string& c : kModeColumns) out << ',' << c;
  for (const ParameterModeDerivatives& p : derivatives) {
    for (const std::string& c : kModeColumns) out << ",d" << c << "/d" << p.path;
  }
  out << '\n';
  for (size_t k = 0; k < modes.size(); ++k) {
    const Mode& m = modes[k];
    out << k + 1 << ',' << number(m.frequencyHz) << ',' << number(m.omega) << ',' << number(m.dampingRatio) << ','
        << number(m.eigenvalue.real()) << ',' << number(m.eigenvalue.imag());
    for (const ParameterModeDerivatives& p : derivatives) {
      const ModeDerivative& d = p.modes[k];
      out << ',' << number(d.frequencyHz) << ',' << number(d.omega) << ',' << number(d.dampingRatio) << ','
          << number(d.eigenvalue.real()) << ',' << number(d.eigenvalue.imag());
    }
    out << '\n';
  }
  if (!out) throw writeFailure(file);
}

/// The eigenvalue sensitivities (sensitivity/modal_sensitivity.hpp) of `modes` with respect
/// to each parameter: each perturbed scene's reference state found as the base's
/// (initialReference: its consistent state or equilibrium, or --steady), linearised.
/// @throws InputError naming the parameter when its perturbed model has no such state.
std::vector<ParameterModeDerivatives> modeSensitivities(const SensitivityScenes& scenes, bool steady,
                                                        const LinearizedSystem& lin, const ReducedSystem& red,
                                                        const std::vector<Mode>& modes) {
  std::vector<ParameterModeDerivatives> out;
  for (std::size_t i = 0; i < scenes.parameters.size(); ++i) {
    const SensitivityParameter& p = scenes.parameters[i];
    try {
      std::array<LinearizedSystem, kStencilPoints> perturbed;
      for (std::size_t j = 0; j < kStencilPoints; ++j) {
        const Scene& s = *scenes.perturbed[i][j];
        perturbed[j] = linearize(s.system, initialReference(s, steady));
      }
      out.push_back({p.name, modeDerivatives(lin, red, modes, perturbed, p.step)});
    } catch (const InputError& e) {
      throw InputError("sensitivity parameter '" + p.name + "': the model at " + p.name + " = " + fmt(p.value) +
                       " +- " + fmt(p.step) + " or +- " + fmt(2.0 * p.step) +
                       " (the steps of the five-point difference): " + e.what());
    }
  }
  return out;
}

/// Each parameter's derivatives of the listed frequencies on one line.
void printDerivatives(const std::vector<ParameterModeDerivatives>& derivatives) {
  for (const ParameterModeDerivatives& p : derivatives) {
    std::printf("d frequency_hz / d %s:", cli::oneLine(p.path).c_str());
    for (size_t k = 0; k < std::min<size_t>(p.modes.size(), 6); ++k) std::printf(" %.6g", p.modes[k].frequencyHz);
    std::printf("%s\n", p.modes.size() > 6 ? " ..." : "");
  }
}

void writeShapesCsv(const fs::path& file, const std::vector<Mode>& modes, const std::vector<std::string>& names) {
  std::ofstream out(file);
  out << "velocity";
  for (size_t k = 0; k < modes.size(); ++k) out << ",mode_" << k + 1;
  out << '\n';
  for (size_t i = 0; i < names.size(); ++i) {
    out << names[i];
    for (const Mode& m : modes) out << ',' << number(m.shape[static_cast<Eigen::Index>(i)].real());
    out << '\n';
  }
  if (!out) throw writeFailure(file);
}

/// Scale of a drawn mode shape: its largest length entry moves kShapeAmplitude of the
/// model's size (its largest angle kShapeAngle if it moves no length).
double shapeScale(const System& sys, const VecX& shape) {
  const std::vector<CoordinateKind> kinds = sys.velocityKinds();
  double lengths = 0.0, angles = 0.0;
  for (Eigen::Index k = 0; k < shape.size(); ++k) {
    (kinds[k] == CoordinateKind::Angle ? angles : lengths) = std::max(kinds[k] == CoordinateKind::Angle ? angles : lengths,
                                                                      std::abs(shape[k]));
  }
  if (lengths > 1e-12 * std::max(angles, 1e-300)) return kShapeAmplitude * sys.characteristicLength() / lengths;
  return angles > 0.0 ? kShapeAngle / angles : 0.0;
}

/// The states drawn for mode k: one period of its shape, kShapeFrames of them,
/// q = q_ref (+) c Re(shape e^{i phi}).
std::vector<VecX> shapeStates(const System& sys, const ReferenceState& ref, const Mode& mode) {
  std::vector<VecX> states;
  const double c = shapeScale(sys, mode.shape.real());
  for (int f = 0; f < kShapeFrames; ++f) {
    const double phi = 2 * M_PI * f / kShapeFrames;
    states.push_back(sys.applyIncrement(ref.q, c * (mode.shape * std::exp(std::complex<double>(0.0, phi))).real()));
  }
  return states;
}

/// DIR/vtk/mode_NN.pvd (one period of each mode shape) and DIR/mode_states.csv (the same
/// states: mode, phase as a fraction of the period, then the coordinates; `flexmbd view`
/// animates them).
void writeShapeStates(const fs::path& dir, const Scene& scene, const ReferenceState& ref,
                      const std::vector<Mode>& modes) {
  const System& sys = scene.system;
  const fs::path csv = dir / "mode_states.csv";
  std::ofstream out(csv);
  out << "mode,phase";
  for (const std::string& n : sys.coordinateNames()) out << ',' << n;
  out << '\n';
  for (size_t k = 0; k < modes.size(); ++k) {
    char prefix[32];
    std::snprintf(prefix, sizeof prefix, "mode_%02zu", k + 1);
    VtkWriter vtk(dir / "vtk", sys, prefix, 4, scene.geometry, scene.feBodies);
    const std::vector<VecX> states = shapeStates(sys, ref, modes[k]);
    for (int f = 0; f < kShapeFrames; ++f) {
      OutputSample s;
      s.t = static_cast<double>(f) / kShapeFrames;  // the fraction of the period
      s.q = states[f];
      s.v = VecX::Zero(sys.numVelocities());
      s.a = VecX::Zero(sys.numVelocities());
      s.lambda = ref.lambda;
      vtk.write(s);
      out << k + 1 << ',' << number(s.t);
      for (Eigen::Index i = 0; i < s.q.size(); ++i) out << ',' << number(s.q[i]);
      out << '\n';
    }
  }
  if (!out) throw writeFailure(csv);
}

/// DIR/modes.json: the scene file (absolute) and the time of the reference state.
void writeModesJson(const fs::path& dir, const std::string& scenePath, double t) {
  nlohmann::ordered_json j;
  std::error_code ec;
  const fs::path absolute = fs::absolute(scenePath, ec);
  j["scene_file"] = ec ? scenePath : absolute.lexically_normal().string();
  j["t"] = t;
  const fs::path file = dir / "modes.json";
  std::ofstream out(file);
  out << j.dump(2) << '\n';
  if (!out) throw writeFailure(file);
}

void printTable(const std::vector<Mode>& modes) {
  std::printf("  mode   frequency (Hz)   omega (rad/s)   damping ratio   eigenvalue\n");
  for (size_t k = 0; k < modes.size(); ++k) {
    const Mode& m = modes[k];
    std::printf("  %4zu   %14.6g   %13.6g   %13.4g   %.6g %+.6gi\n", k + 1, m.frequencyHz, m.omega, m.dampingRatio,
                m.eigenvalue.real(), m.eigenvalue.imag());
  }
}

/// The natural frequencies of each beam body's model under its reference conditions
/// (frame held fixed; FfrBeamModel::naturalFrequencies).
void printBeamFrequencies(const System& sys, int count) {
  for (int b = 0; b < sys.numBodies(); ++b) {
    const Body& body = sys.body(BodyIndex(b));
    VecX w;
    if (const auto* f2 = dynamic_cast<const FfrBody2d*>(&body); f2 && f2->beamModel()) {
      w = f2->beamModel()->naturalFrequencies();
    } else if (const auto* f3 = dynamic_cast<const FfrBody3d*>(&body); f3 && f3->model()) {
      w = f3->model()->naturalFrequencies();
    } else {
      continue;
    }
    std::printf("beam \"%s\": natural frequencies of its model on its reference conditions (frame fixed), Hz:",
                cli::oneLine(body.name()).c_str());
    for (int k = 0; k < std::min<int>(count, static_cast<int>(w.size())); ++k) std::printf(" %.6g", w[k] / (2 * M_PI));
    std::printf("\n");
  }
}

/// The scene's JSON with the speed of driver or body `name` set to `speed`: a driver's
/// constant_speed law, or a body's initial angular velocity (spatial: along its given direction).
/// @throws InputError naming the driver, body or key.
nlohmann::json withSpeed(nlohmann::json j, const std::string& name, double speed) {
  const bool spatial = j.contains("dimension") && j["dimension"] == 3;
  if (j.contains("drivers") && j["drivers"].is_array()) {
    for (auto& d : j["drivers"]) {
      if (!d.is_object() || !d.contains("name") || d["name"] != name) continue;
      if (!d.contains("law") || !d["law"].is_object() || d["law"].value("type", "") != "constant_speed") {
        throw InputError("--sweep: driver \"" + name + "\" needs a law of type \"constant_speed\" (key \"law\") to sweep its speed");
      }
      d["law"]["speed"] = speed;
      return j;
    }
  }
  if (j.contains("bodies") && j["bodies"].is_array()) {
    for (auto& b : j["bodies"]) {
      if (!b.is_object() || !b.contains("name") || b["name"] != name) continue;
      if (!spatial) {
        b["angular_velocity"] = speed;
        return j;
      }
      if (!b.contains("angular_velocity") || !b["angular_velocity"].is_array() || b["angular_velocity"].size() != 3) {
        throw InputError("--sweep: body \"" + name + "\" needs an \"angular_velocity\" [wx, wy, wz] giving the spin axis");
      }
      Vec3 w;
      for (int k = 0; k < 3; ++k) w[k] = b["angular_velocity"][k].get<double>();
      if (w.norm() == 0.0) throw InputError("--sweep: body \"" + name + "\": key \"angular_velocity\" is zero, it must give the spin axis");
      w *= speed / w.norm();
      b["angular_velocity"] = {w[0], w[1], w[2]};
      return j;
    }
  }
  throw InputError("--sweep: the scene has no driver or body named \"" + name +
                   "\" (give a driver with a constant_speed law or a body with an initial spin)");
}

int runSweep(const ModesCommandOptions& o, const nlohmann::json& base, const fs::path& out) {
  const Sweep& sw = *o.sweep;
  std::ofstream csv(out / "campbell.csv");
  csv << "speed";
  for (int k = 1; k <= o.count; ++k) csv << ",f" << k << "_hz";
  for (int k = 1; k <= o.count; ++k) csv << ",zeta" << k;
  csv << '\n';
  // The columns are branches followed by shape (followBranches: modal assurance with the
  // previous speed's modes), not ranks: where modes cross, a line stays on its mode. Two
  // more modes than shown are followed, so that one coming down from above is caught.
  ModesOptions mo;
  mo.count = o.count + 2;
  mo.solver = o.solver;
  std::printf("Campbell sweep of \"%s\": %d speeds from %g to %g rad/s (modes followed by shape)\n",
              cli::oneLine(sw.name).c_str(), sw.points, sw.from, sw.to);
  std::vector<Mode> previous;
  for (int i = 0; i < sw.points; ++i) {
    const double speed = sw.points == 1 ? sw.from : sw.from + (sw.to - sw.from) * i / (sw.points - 1);
    cli::stopIfSignalledInStep(0.0);  // between the speeds of the sweep
    const Scene scene = parseSceneText(withSpeed(base, sw.name, speed).dump(), o.scenePath);
    const System& sys = scene.system;
    const std::vector<Mode> found = modesAbout(sys, initialReference(scene, o.steady), mo, basisFor(sys, o.solver));
    std::vector<Mode> modes;
    for (int j : followBranches(previous, found)) modes.push_back(found[j]);
    previous = modes;
    csv << number(speed);
    for (int k = 0; k < o.count; ++k) csv << ',' << (k < static_cast<int>(modes.size()) ? number(modes[k].frequencyHz) : "");
    for (int k = 0; k < o.count; ++k) csv << ',' << (k < static_cast<int>(modes.size()) ? number(modes[k].dampingRatio) : "");
    csv << '\n';
    std::printf("  speed %10.6g rad/s:", speed);
    const size_t shown = std::min<size_t>(modes.size(), static_cast<size_t>(o.count));
    for (size_t k = 0; k < std::min<size_t>(shown, 6); ++k) std::printf(" %.5g", modes[k].frequencyHz);
    std::printf(" Hz%s\n", shown > 6 ? " ..." : "");
  }
  csv.close();
  if (!csv) throw writeFailure(out / "campbell.csv");
  std::printf("Campbell diagram: %s\n", (out / "campbell.csv").string().c_str());
  ::setenv("FLEXMBD_PLOT_FROM_CLI", "1", 1);
  return runPythonScript("plot_campbell.py", {(out / "campbell.csv").string(), "--out", (out / "campbell.png").string(),
                                              "--title", "Campbell diagram: " + sw.name});
}

/// The simulation of --at reports an interrupt as its failure: exit 128 + signal.
int interrupted(int sig) {
  cli::printError("modes: interrupted by " + cli::signalName(sig) + " (the modes were not written)");
  return 128 + sig;
}

}  // namespace

int runModesCommand(const std::vector<std::string>& args) {
  ModesCommandOptions o;
  nlohmann::json base;
  std::optional<Scene> scene;
  std::optional<SensitivityScenes> sensitivities;  // --sensitivity: the scenes at p +- h, p +- 2 h
  try {
    o = parseOptions(args);
    const std::string text = readText(o.scenePath);
    scene.emplace(parseSceneText(text, o.scenePath));
    base = nlohmann::json::parse(text);
    if (!o.sensitivities.empty()) {
      sensitivities.emplace(buildSensitivityScenes(text, o.scenePath, *scene, o.sensitivities));
      const DaeSystem dae(scene->system, Formulation::Ggl);
      for (std::size_t i = 0; i < sensitivities->parameters.size(); ++i) {
        for (const auto& perturbed : sensitivities->perturbed[i]) {
          requireSameStructure(dae, DaeSystem(perturbed->system, Formulation::Ggl), sensitivities->parameters[i].name);
        }
      }
    }
  } catch (const std::exception& e) {
    cli::printError(e.what());
    return kExitInputError;
  }
  const fs::path out(o.outDir);
  std::optional<OutputLock> lock;  // one run at a time in DIR; a folder it cannot write is refused here
  try {
    lock.emplace(out);
  } catch (const std::exception& e) {
    cli::printError(e.what());
    return kExitInputError;
  }
  try {
    const cli::StopOnSignals stop;  // SIGINT, SIGTERM: as `run` (the simulation of --at within its step)
    if (o.sweep) {
      printBeamFrequencies(scene->system, o.count);
      return runSweep(o, base, out);
    }
    const System& sys = scene->system;
    const ReferenceState ref = findReference(*scene, o.at, o.steady, o.quiet);
    cli::stopIfSignalledInStep(ref.t);
    const LinearizedSystem lin = linearize(sys, ref);
    const ReducedSystem red = reduce(lin, basisFor(sys, o.solver));
    ModesOptions mo;
    // with sensitivities one mode more, so that a repeated eigenvalue at the last is seen
    mo.count = sensitivities ? o.count + 1 : o.count;
    mo.solver = o.solver;
    std::vector<Mode> modes = computeModes(red, mo);
    std::vector<ParameterModeDerivatives> derivatives;
    if (sensitivities) derivatives = modeSensitivities(*sensitivities, o.steady, lin, red, modes);
    if (static_cast<int>(modes.size()) > o.count) modes.resize(static_cast<std::size_t>(o.count));
    for (ParameterModeDerivatives& d : derivatives) d.modes.resize(modes.size());
    writeModesCsv(out / "modes.csv", modes, derivatives);
    writeShapesCsv(out / "mode_shapes.csv", modes, lin.velocityNames);
    writeShapeStates(out, *scene, ref, modes);
    writeModesJson(out, o.scenePath, ref.t);
    const double aMax = ref.a.size() ? ref.a.lpNorm<Eigen::Infinity>() : 0.0;
    std::printf("flexmbd: modes of %s about t = %g (%s; max |a| = %.3g): %d velocities, %d independent\n",
                o.scenePath.c_str(), ref.t, ref.v.lpNorm<Eigen::Infinity>() == 0.0 ? "at rest" : o.steady ? "steady motion" : "in motion", aMax,
                sys.numVelocities(), static_cast<int>(red.N.cols()));
    printTable(modes);
    printDerivatives(derivatives);
    printBeamFrequencies(sys, o.count);
    std::printf("results: %s, %s, %s, %s (flexmbd view %s draws them)\n", (out / "modes.csv").string().c_str(),
                (out / "mode_shapes.csv").string().c_str(), (out / "mode_states.csv").string().c_str(),
                (out / "vtk").string().c_str(), out.string().c_str());
    return kExitOk;
  } catch (const RunInterrupted& e) {
    cli::printError(std::string("modes: ") + e.what() + " (the modes were not written)");
    return 128 + e.signal;
  } catch (const InputError& e) {  // ModelError included: no equilibrium, no degree of freedom
    cli::printError(o.scenePath + ": " + e.what());
    return kExitInputError;
  } catch (const SolverError& e) {  // the simulation to --at failed, an eigensolver did not converge
    if (const int sig = cli::gStopSignal) return interrupted(sig);
    cli::printError(o.scenePath + ": " + e.what());
    return kExitFailure;
  } catch (const std::exception& e) {
    if (const int sig = cli::gStopSignal) return interrupted(sig);
    cli::printError(e.what());
    return kExitFailure;
  }
}

}  // namespace flexmbd
