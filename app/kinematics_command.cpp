#include "app/kinematics_command.hpp"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "app/command_line.hpp"
#include "core/errors.hpp"
#include "core/number_text.hpp"
#include "results/output_lock.hpp"
#include "results/results_writer.hpp"
#include "linkage/kinematic_analysis.hpp"
#include "linkage/kinematics_scene.hpp"

namespace flexmbd {

namespace {

namespace fs = std::filesystem;

using cli::kExitOk;
constexpr int kExitStopped = cli::kExitFailure;
using cli::kExitInputError;

using cli::UsageError;

struct Options {
  std::string scenePath, outDir;
  std::optional<long> steps;
  std::optional<double> tolerance;
  std::optional<std::string> corrector;
};

using cli::oneLine;
using cli::printError;

Options parseOptions(const std::vector<std::string>& args) {
  Options o;
  const cli::SplitArguments split =
      cli::splitArguments(args, cli::withCommon(cli::kCommonValueOptions, {"--steps", "--tolerance", "--corrector"}),
                          cli::kCommonFlags, "kinematics: ");
  for (const auto& [name, value] : split.values) {
    if (name == "--out") {
      if (value.empty()) throw UsageError("option --out needs a directory");
      o.outDir = value;
    } else if (name == "--corrector") {
      if (value != "newton" && value != "modified_newton") {
        throw UsageError("option --corrector expects 'newton' or 'modified_newton', got '" + value + "'");
      }
      o.corrector = value;
    } else if (name == "--steps") {
      const double x = cli::parseNumberOption(name, value);
      if (x != std::floor(x) || x < 1 || x > static_cast<double>(kMaxKinematicSteps)) {
        throw UsageError("option --steps expects an integer from 1 to " + std::to_string(kMaxKinematicSteps) + ", got '" +
                         value + "'");
      }
      o.steps = static_cast<long>(x);
    } else {
      o.tolerance = cli::parsePositiveOption(name, value);
    }
  }
  const std::vector<std::string>& positional = split.positional;
  if (positional.empty()) throw UsageError("kinematics: missing the scene file (flexmbd kinematics SCENE.json --out DIR)");
  if (positional.size() > 1) {
    throw UsageError("kinematics: expected one scene file, got " + std::to_string(positional.size()) + " arguments ('" +
                     positional[0] + "', '" + positional[1] + "', ...)");
  }
  o.scenePath = positional[0];
  if (o.outDir.empty()) throw UsageError("kinematics: missing --out DIR (the output directory)");
  return o;
}

/// DIR/kinematics.csv, one row per input step, flushed row by row (kept on a stop).
class KinematicsWriter {
 public:
  KinematicsWriter(const fs::path& path, const Linkage2d& linkage) : linkage_(linkage) {
    std::string header;
    for (const std::string& c : kinematicsColumns(linkage)) header += (header.empty() ? "" : ",") + c;
    file_.open(path, header + "\n");
  }

  /// One row, written whole or not at all (RowFile).
  void write(const KinematicState& s) {
    kinematicsRow(linkage_, s, values_);
    std::ostringstream out_;
    out_.precision(17);
    for (std::size_t k = 0; k < values_.size(); ++k) {
      if (k) out_ << ',';
      if (k == 0 || k == 2) {
        out_ << static_cast<long>(values_[k]);  // step, iterations: integers
      } else {
        out_ << values_[k];
      }
    }
    out_ << '\n';
    file_.append(out_.str(), s.alpha, "alpha");
    lastAlpha_ = s.alpha;
  }
  long rows() const { return file_.rows(); }
  /// The input of the last row written (NaN if none).
  double lastAlpha() const { return lastAlpha_; }

 private:
  const Linkage2d& linkage_;
  RowFile file_;
  std::vector<double> values_;
  double lastAlpha_ = NAN;
};

void writeJson(const fs::path& dir, const nlohmann::json& j) {
  writeSummaryText(dir, j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + '\n');
}

void removeStale(const fs::path& dir) {
  std::error_code ec;
  fs::remove(dir / "kinematics.csv", ec);
  fs::remove(dir / "summary.json", ec);
}

int reportInputError(const fs::path& outDir, const std::string& message) {
  try {
    fs::create_directories(outDir);
    removeStale(outDir);
    writeJson(outDir, {{"status", "failed"}, {"error", "input"}, {"message", oneLine(message)}});
  } catch (...) {
  }
  printError(message);
  return kExitInputError;
}

}  // namespace

int runKinematicsCommand(const std::vector<std::string>& args) {
  Options o;
  try {
    o = parseOptions(args);
  } catch (const std::exception& e) {
    printError(e.what());
    return kExitInputError;
  }
  const fs::path outDir(o.outDir);
  std::optional<OutputLock> lock;  // one run at a time in DIR (results/output_lock.hpp)
  try {
    lock.emplace(outDir);
  } catch (const std::exception& e) {
    printError(e.what());
    return kExitInputError;
  }

  std::optional<KinematicsScene> scene;
  std::optional<KinematicAnalysis> analysis;
  try {
    scene.emplace(loadKinematicsScene(o.scenePath));
    if (o.steps) scene->settings.steps = static_cast<int>(*o.steps);
    if (o.tolerance) scene->settings.tolerance = *o.tolerance;
    if (o.corrector) {
      scene->settings.corrector = *o.corrector == "newton" ? CorrectorKind::Newton : CorrectorKind::ModifiedNewton;
    }
    analysis.emplace(scene->linkage, scene->settings);  // assembly at alpha = start
  } catch (const InputError& e) {
    const std::string m = e.what();
    return reportInputError(outDir, m.find(o.scenePath) != std::string::npos ? m : o.scenePath + ": " + m);
  }

  std::optional<KinematicsWriter> writer;
  try {
    fs::create_directories(outDir);
    removeStale(outDir);
    reserveSummary(outDir);
    writer.emplace(outDir / "kinematics.csv", scene->linkage);
  } catch (const OutputWriteError& e) {  // a full disk (exit 1, README)
    printError(e.what());
    return kExitStopped;
  } catch (const std::exception& e) {
    printError(e.what());
    return kExitInputError;
  }

  KinematicSummary summary;
  int minIt = 0, maxIt = 0, interruptedBy = 0;
  // A run stopped by a signal or a full disk: the rows written are whole, the summary
  // says where they end.
  auto stoppedAt = [&](const std::string& message) {
    summary.ok = false;
    summary.message = message;
    summary.stepsCompleted = static_cast<int>(writer->rows());
    summary.alphaReached = writer->rows() > 0 ? writer->lastAlpha() : scene->settings.start;
  };
  try {
    const cli::StopOnSignals stop;  // SIGINT, SIGTERM: stop within the step (as `run`)
    summary = analysis->run([&](const KinematicState& s) { writer->write(s); });
  } catch (const OutputWriteError& e) {
    stoppedAt(e.what());
  } catch (const RunInterrupted& e) {
    stoppedAt(std::string(e.what()) + " (the rows up to alpha = " + fmt(writer->lastAlpha()) + " are kept)");
    interruptedBy = e.signal;
  }
  minIt = summary.minIterations;
  maxIt = summary.maxIterations;

  const KinematicSettings& st = scene->settings;
  nlohmann::json j;
  j["status"] = summary.ok ? "ok" : interruptedBy ? "interrupted" : "failed";
  j["message"] = summary.message;
  j["scene"] = scene->name;
  j["mobility"] = scene->linkage.mobility();
  j["coordinates"] = scene->linkage.numCoordinates();
  j["steps"] = st.steps;
  j["steps_completed"] = std::max(0, summary.stepsCompleted - 1);
  j["alpha_start"] = st.start;
  j["alpha_end"] = st.end;
  j["alpha_reached"] = summary.alphaReached;
  j["speed"] = st.speed;
  j["acceleration"] = st.acceleration;
  j["tolerance"] = st.tolerance;
  j["corrector"] = st.corrector == CorrectorKind::Newton ? "newton" : "modified_newton";
  j["assembly_iterations"] = summary.assemblyIterations;
  j["iterations_min"] = minIt;
  j["iterations_max"] = maxIt;
  j["iterations_mean"] = summary.meanIterations;
  j["max_residual"] = summary.maxResidual;
  j["wall_seconds"] = summary.wallSeconds;
  j["seconds_per_step"] = summary.stepsCompleted > 0 ? summary.wallSeconds / summary.stepsCompleted : 0.0;
  if (summary.singular) {
    const SingularPosition& s = *summary.singular;
    j["singular"] = {{"kind", s.kind},       {"alpha", s.alpha}, {"alpha_regular", s.alphaRegular},
                     {"alpha_beyond", s.alphaBeyond}, {"nodes", s.nodes}, {"links", s.links}};
  } else {
    j["singular"] = nullptr;
  }
  try {
    writeJson(outDir, j);
  } catch (const std::exception& e) {
    printError(std::string("cannot write the summary: ") + e.what());
    return interruptedBy ? 128 + interruptedBy : kExitStopped;
  }
  const fs::path csv = outDir / "kinematics.csv";
  if (interruptedBy) {
    printError(summary.message + " (" + csv.string() + ")");
    return 128 + interruptedBy;
  }
  if (!summary.ok) {
    printError(o.scenePath + ": " + summary.message + " (" + csv.string() + ")");
    return kExitStopped;
  }
  std::cout << "flexmbd: ok: alpha = " << summary.alphaReached << " reached in " << st.steps << " steps, iterations "
            << minIt << "-" << maxIt << " per step, max residual " << summary.maxResidual << "; results in "
            << csv.string() << std::endl;
  return kExitOk;
}

}  // namespace flexmbd
