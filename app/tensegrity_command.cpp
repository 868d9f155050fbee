#include "app/tensegrity_command.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "app/command_line.hpp"
#include "core/errors.hpp"
#include "results/output_lock.hpp"
#include "results/results_writer.hpp"
#include "results/vtk_writer.hpp"
#include "tensegrity/tensegrity_scene.hpp"

namespace flexmbd {

namespace {

using cli::kExitOk;
constexpr int kExitSolverFailure = cli::kExitFailure;
using cli::kExitInputError;

using cli::oneLine;
using cli::printError;

std::string num(double x) {
  std::ostringstream os;
  os.precision(17);
  os << x;
  return os.str();
}

/// Writes results.csv and events.csv as the run goes (each row flushed).
class TensegrityResults {
 public:
  TensegrityResults(const std::filesystem::path& dir, const TensegrityStructure& s) : s_(s) {
    std::string header;
    for (const std::string& c : tensegrityColumns(s)) header += (header.empty() ? "" : ",") + c;
    results_.open(dir / "results.csv", header + "\n");
    events_.open(dir / "events.csv", "t,step,type,member,other,impulse,elongation_rate,energy_change,x,y,z\n");
  }
  void sample(const TensegritySample& smp) {
    tensegrityRow(s_, smp, values_);  // throws NonFiniteResult: the run stops before this row
    std::ostringstream row;
    for (std::size_t k = 0; k < values_.size(); ++k) {
      if (k) row << ",";
      row << num(values_[k]);  // 17 digits; the 0/1 of the slack columns print as 0 and 1
    }
    row << "\n";
    results_.append(row.str(), smp.t);
    ++rows_;
    lastTime_ = smp.t;
    lastSteps_ = smp.steps;
  }
  void event(const TensegrityEvent& e) {
    std::ostringstream row;
    row << num(e.t) << "," << e.step << "," << toString(e.type) << "," << e.member << "," << e.other << ","
        << num(e.impulse) << "," << num(e.elongationRate) << "," << num(e.energyChange) << "," << num(e.point[0])
        << "," << num(e.point[1]) << "," << num(e.point[2]) << "\n";
    events_.append(row.str(), e.t);
  }
  long rows() const { return rows_; }
  double lastTime() const { return lastTime_; }
  /// Steps taken up to the last row written.
  long lastSteps() const { return lastSteps_; }

 private:
  const TensegrityStructure& s_;
  RowFile results_, events_;
  std::vector<double> values_;
  long rows_ = 0;
  double lastTime_ = NAN;
  long lastSteps_ = 0;
};

void writeTensegritySummary(const std::filesystem::path& dir, const TensegrityRunSummary& s,
                            const TensegrityScene& scene, int interruptedBy) {
  nlohmann::json j;
  j["status"] = s.ok ? "ok" : interruptedBy ? "interrupted" : "failed";
  j["message"] = s.message;
  j["model"] = "tensegrity";
  j["scene"] = scene.name;
  j["method"] = s.method;
  j["t_reached"] = s.tReached;
  j["steps"] = s.steps;
  j["cpu_seconds"] = s.cpuSeconds;
  j["snaps"] = s.snaps;
  j["taut_transitions"] = s.tautTransitions;
  j["slack_transitions"] = s.slackTransitions;
  j["contacts"] = s.contacts;
  j["energy_start"] = s.energyStart;
  j["energy_end"] = s.energyEnd;
  if (s.method == "time_stepping") {
    j["lcp_solver"] = s.lcpSolver;
    j["max_lcp_residual"] = s.maxLcpResidual;
    j["max_lcp_size"] = s.maxLcpSize;
    j["lcp_iterations"] = s.lcpIterations;
    j["lcp_solves"] = s.lcpSolves;
    j["contact_impulse_sum"] = s.contactImpulseSum;
    j["max_drift_before_projection"] = s.maxDriftBeforeProjection;
    j["max_drift_after_projection"] = s.maxDriftAfterProjection;
    j["projection_iterations"] = s.projectionIterations;
    j["max_energy_increase_at_snap"] = s.snaps > 0 ? nlohmann::json(s.maxEnergyIncreaseAtSnap) : nlohmann::json();
    j["time_step"] = scene.timeStepping.timeStep;
  } else {
    j["rhs_evals"] = s.rhsEvals;
    j["root_evals"] = s.rootEvals;
    j["error_test_failures"] = s.errorTestFailures;
    j["nonlinear_conv_failures"] = s.nonlinearConvFailures;
    j["rtol"] = scene.massless.cvode.rtol;
    j["atol"] = scene.massless.cvode.atol;
  }
  writeSummaryText(dir, j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
}

int reportInputError(const std::filesystem::path& outDir, const std::string& message) {
  try {
    removeStaleResults(outDir);
    std::filesystem::remove(outDir / "events.csv");
    writeInputErrorSummary(outDir, oneLine(message));
  } catch (...) {
  }
  printError(message);
  return kExitInputError;
}

}  // namespace

bool isTensegrityScene(const std::string& scenePath) { return isTensegritySceneFile(scenePath); }

int runTensegrityCommand(const TensegrityRunOptions& o) {
  const std::filesystem::path outDir(o.outDir);
  std::optional<OutputLock> lock;  // one run at a time in DIR (results/output_lock.hpp)
  try {
    lock.emplace(outDir);
  } catch (const std::exception& e) {
    printError(e.what());
    return kExitInputError;
  }
  TensegrityScene scene;
  try {
    scene = loadTensegrityScene(o.scenePath);
    if (scene.method == TensegrityScene::Method::TimeStepping) {
      if (o.rtol || o.atol) throw InputError("options --rtol and --atol apply to method \"massless_cables\" only");
      if (o.tEnd) {
        if (!(*o.tEnd > scene.timeStepping.tStart)) throw InputError("option --t-end must be > t_start");
        scene.timeStepping.tEnd = *o.tEnd;
      }
    } else {
      if (o.tEnd) {
        if (!(*o.tEnd > scene.massless.tStart)) throw InputError("option --t-end must be > t_start");
        scene.massless.tEnd = *o.tEnd;
      }
      // --rtol alone scales atol by the same factor, as for multibody scenes (overrideTolerances)
      if (o.rtol && !o.atol) scene.massless.cvode.atol *= *o.rtol / scene.massless.cvode.rtol;
      if (o.rtol) scene.massless.cvode.rtol = *o.rtol;
      if (o.atol) scene.massless.cvode.atol = *o.atol;
    }
    checkTensegrityTimes(scene);  // after --t-end
  } catch (const std::exception& e) {
    return reportInputError(outDir, e.what());
  }

  std::optional<TensegrityResults> results;
  std::optional<TensegrityVtkWriter> vtk;
  try {
    std::filesystem::create_directories(outDir);
    removeStaleResults(outDir);
    reserveSummary(outDir);
    results.emplace(outDir, *scene.structure);
    if (o.vtk) vtk.emplace(outDir / "vtk", *scene.structure, scene.name);
  } catch (const OutputWriteError& e) {  // a full disk (exit 1, README)
    printError(e.what());
    return kExitSolverFailure;
  } catch (const std::exception& e) {  // --vtk where DIR/vtk is a file, ...
    return reportInputError(outDir, e.what());
  }
  const TensegrityObserver observer{[&](const TensegritySample& s) {
                                      results->sample(s);
                                      if (vtk) vtk->write(s);
                                      cli::stopIfSignalled(s.t);
                                    },
                                    [&](const TensegrityEvent& e) { results->event(e); }};
  TensegrityRunSummary summary;
  int interruptedBy = 0;
  bool outputFailed = false;
  try {
    const cli::StopOnSignals stop;  // a signal stops the run within its step
    if (scene.method == TensegrityScene::Method::TimeStepping) {
      summary = TensegrityTimeStepper(*scene.structure, scene.timeStepping).run(observer);
    } else {
      summary = MasslessCableIntegrator(*scene.structure, scene.massless).run(observer);
    }
  } catch (const InputError& e) {
    return reportInputError(outDir, o.scenePath + ": " + e.what());
  } catch (const RunInterrupted& e) {
    summary.ok = false;
    summary.message = e.what();
    summary.tReached = results->lastTime();
    summary.steps = results->lastSteps();
    interruptedBy = e.signal;
  } catch (const OutputWriteError& e) {
    summary.ok = false;
    summary.message = e.what();
    summary.tReached = results->lastTime();
    summary.steps = results->lastSteps();
    outputFailed = true;
  } catch (const NonFiniteResult& e) {
    if (results->rows() == 0) {  // at the start: the scene's own values overflow (exit 2)
      return reportInputError(outDir, o.scenePath + ": the initial state has " + e.what() +
                                          ": values of the scene overflow (check masses, velocities, stiffnesses)");
    }
    summary.ok = false;
    summary.message = std::string(e.what()) + ": the run stops before this output (the rows before it are kept)";
    summary.tReached = results->lastTime();
    summary.steps = results->lastSteps();
  } catch (const std::exception& e) {
    summary.ok = false;
    summary.message = e.what();
    summary.tReached = results->lastTime();
    summary.steps = results->lastSteps();
  }
  try {
    writeTensegritySummary(outDir, summary, scene, interruptedBy);
  } catch (const std::exception& e) {
    printError((summary.ok ? std::string() : summary.message + "; ") + "cannot write the summary: " + e.what());
    return interruptedBy ? 128 + interruptedBy : kExitSolverFailure;
  }
  const std::string kept = results->rows() > 0 ? "results up to t = " + num(results->lastTime()) + " kept in " +
                                                     (outDir / "results.csv").string()
                                               : std::string("no results were written");
  if (interruptedBy) {
    printError(summary.message + " (" + kept + ")");
    return 128 + interruptedBy;
  }
  if (outputFailed) {
    printError(summary.message + " (" + kept + ")");
    return kExitSolverFailure;
  }
  if (!summary.ok) {
    printError("solver failure: " + summary.message + " (" +
               (results->rows() > 0 ? "results up to t = " + num(results->lastTime()) + " kept in " +
                                          (outDir / "results.csv").string()
                                    : std::string("no results were written")) +
               ")");
    return kExitSolverFailure;
  }
  {  // the one-line report of `run` (--quiet only silences progress, as for `run`)
    std::cout << "flexmbd: ok: t = " << summary.tReached << " reached, " << summary.steps << " steps, "
              << summary.snaps << " snaps, " << summary.slackTransitions << " slack, " << summary.contacts
              << " contacts, " << summary.cpuSeconds << " s CPU; results in " << (outDir / "results.csv").string()
              << std::endl;
  }
  return kExitOk;
}

}  // namespace flexmbd
