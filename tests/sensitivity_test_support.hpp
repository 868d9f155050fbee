// Helpers of the sensitivity tests (tests/test_sensitivities.cpp,
// tests/test_sensitivities_elastic.cpp): a run with forward sensitivities of a scene given
// as JSON, plain runs with one number changed, and the comparison of the two.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "sensitivity/sensitivity_run.hpp"
#include "results/results_writer.hpp"
#include "scene/scene_path.hpp"
#include "results/sensitivity_results.hpp"

namespace {

using namespace flexmbd;
using nlohmann::json;

/// The rows of a run with sensitivities: results columns, and per row the derivatives
/// (sensitivityColumns' order: parameter by parameter, every column but t).
struct SensitivityRun {
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows, derivatives;
  SimulationSummary summary;
  int column(const std::string& name) const {
    for (std::size_t k = 0; k < columns.size(); ++k) {
      if (columns[k] == name) return static_cast<int>(k);
    }
    ADD_FAILURE() << "no column " << name;
    return 0;
  }
  /// d column / d parameter i at row r.
  double d(std::size_t r, const std::string& name, std::size_t i) const {
    return derivatives[r][i * (columns.size() - 1) + static_cast<std::size_t>(column(name)) - 1];
  }
  double value(std::size_t r, const std::string& name) const { return rows[r][static_cast<std::size_t>(column(name))]; }
};

SensitivityRun runWithSensitivities(const json& scene, const std::vector<std::string>& paths, bool errorControl = true) {
  const std::string text = scene.dump();
  Scene base = parseSceneText(text);
  base.solver.progress = false;
  const SensitivityScenes perturbed = buildSensitivityScenes(text, "<scene>", base, paths);
  SensitivityRun run;
  run.columns = resultColumns(base);
  std::vector<double> row, d;
  run.summary = simulateWithSensitivities(base.system, perturbed.parameters, base.solver, {errorControl},
                                          [&](const OutputSample& s, const SensitivitySample& sens) {
                                            resultRow(base, run.columns, s, row);
                                            sensitivityRow(perturbed, run.columns, sens, d);
                                            run.rows.push_back(row);
                                            run.derivatives.push_back(d);
                                          });
  return run;
}

/// The rows of a plain run of the scene with the number at `path` set to `value`.
std::vector<std::vector<double>> plainRun(json scene, const std::string& path, double value) {
  setSceneNumber(scene, path, value);
  Scene s = parseSceneText(scene.dump());
  s.solver.progress = false;
  const std::vector<std::string> columns = resultColumns(s);
  std::vector<std::vector<double>> rows;
  std::vector<double> row;
  const SimulationSummary summary = simulate(s.system, s.solver, [&](const OutputSample& o) {
    resultRow(s, columns, o, row);
    rows.push_back(row);
  });
  EXPECT_TRUE(summary.ok) << summary.message;
  return rows;
}

/// The central difference of whole runs, (c(p + dp) - c(p - dp)) / (2 dp) for every row
/// and column (t included, as 0), dp = relStep |p|.
std::vector<std::vector<double>> wholeRunDifference(const json& scene, const std::string& path, double relStep) {
  const double p = sceneNumber(scene, path), dp = relStep * std::fabs(p);
  const auto plus = plainRun(scene, path, p + dp), minus = plainRun(scene, path, p - dp);
  EXPECT_EQ(plus.size(), minus.size());
  std::vector<std::vector<double>> fd(std::min(plus.size(), minus.size()));
  for (std::size_t r = 0; r < fd.size(); ++r) {
    for (std::size_t k = 0; k < plus[r].size(); ++k) fd[r].push_back((plus[r][k] - minus[r][k]) / (2.0 * dp));
  }
  return fd;
}

/// Largest |sensitivity - fd| over the rows and the largest |fd|, for `column` and
/// parameter `parameter` of the run; fd from wholeRunDifference.
std::pair<double, double> compareWithDifference(const SensitivityRun& run, std::size_t parameter,
                                                const std::vector<std::vector<double>>& fd, const std::string& column) {
  EXPECT_EQ(fd.size(), run.rows.size());
  const auto k = static_cast<std::size_t>(run.column(column));
  double worst = 0.0, largest = 0.0;
  for (std::size_t r = 0; r < std::min(fd.size(), run.rows.size()); ++r) {
    worst = std::max(worst, std::fabs(run.d(r, column, parameter) - fd[r][k]));
    largest = std::max(largest, std::fabs(fd[r][k]));
  }
  return {worst, largest};
}

/// Largest |sensitivity - central difference of whole runs| over the rows and the largest
/// |derivative|, for `column` with respect to `path` (relative step `relStep`).
std::pair<double, double> againstWholeRuns(const json& scene, const SensitivityRun& run, std::size_t parameter,
                                           const std::string& path, const std::string& column, double relStep) {
  return compareWithDifference(run, parameter, wholeRunDifference(scene, path, relStep), column);
}

/// A rigid body of mass m on a spring k (free length 1 m) and damper c to the ground along
/// x, released at rest 0.1 m from equilibrium: m u'' + c u' + k u = 0, u = x - 1.
json springMassDamper() {
  return json::parse(R"({
    "name": "spring-mass-damper", "gravity": [0.0, 0.0],
    "bodies": [{"name": "mass", "type": "rigid", "mass": 2.0, "inertia": 0.1, "com": [0.0, 0.0],
                "position": [1.1, 0.0], "angle": 0.0}],
    "forces": [{"name": "spring", "type": "spring_damper", "bodies": ["ground", "mass"],
                "points": [[0.0, 0.0], [0.0, 0.0]], "stiffness": 50.0, "damping": 0.8, "free_length": 1.0}],
    "solver": {"rtol": 1e-10, "atol": 1e-12, "t_end": 3.0, "output_step": 0.05}
  })");
}

/// A bob of 1 kg (small inertia) on a massless length L = 0.8 m from a pivot at the origin,
/// released at 0.3 rad: joints[0].points[1][1] is L (the pivot in the bob's frame).
json pendulum() {
  const double L = 0.8, th = 0.3;
  json j = json::parse(R"({
    "name": "pendulum", "gravity": [0.0, -9.81],
    "bodies": [{"name": "bob", "type": "rigid", "mass": 1.0, "inertia": 1e-3, "com": [0.0, 0.0],
                "position": [0.0, 0.0], "angle": 0.3}],
    "joints": [{"name": "pivot", "type": "revolute", "bodies": ["ground", "bob"], "points": [[0.0, 0.0], [0.0, 0.8]]}],
    "solver": {"rtol": 1e-11, "atol": 1e-13, "t_end": 2.0, "output_step": 0.05}
  })");
  j["bodies"][0]["position"] = {L * std::sin(th), -L * std::cos(th)};
  return j;
}

}  // namespace
