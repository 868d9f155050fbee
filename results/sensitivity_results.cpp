#include "results/sensitivity_results.hpp"

#include <cmath>
#include <ctime>
#include <limits>
#include <set>

#include <nlohmann/json.hpp>

#include "core/errors.hpp"
#include "core/number_text.hpp"
#include "results/results_writer.hpp"
#include "scene/scene_path.hpp"

namespace flexmbd {
namespace {

using nlohmann::json;

/// The scene with the parameter at `value`, read by the scene reader.
std::unique_ptr<Scene> sceneAt(const json& base, const std::string& source, const std::string& path, double value) {
  json j = base;
  setSceneNumber(j, path, value);
  try {
    // dump() writes the shortest text that reads back the same double (nlohmann: Grisu2)
    return std::make_unique<Scene>(parseSceneText(j.dump(), source));
  } catch (const InputError& e) {
    throw InputError("sensitivity parameter '" + path + "': the scene with " + path + " = " + fmt(value) +
                     " (a step of the central difference) is not valid: " + e.what());
  }
}

}  // namespace

SensitivityScenes buildSensitivityScenes(const std::string& sceneText, const std::string& source, const Scene& base,
                                         const std::vector<std::string>& paths) {
  const json j = json::parse(sceneText);
  const std::vector<std::string> columns = resultColumns(base);
  SensitivityScenes out;
  std::set<std::string> seen;
  for (const std::string& path : paths) {
    if (!seen.insert(path).second) {
      throw InputError("sensitivity parameter '" + path + "': given twice (expected each parameter once)");
    }
    double p = 0.0;
    try {
      p = sceneNumber(j, path);
    } catch (const InputError& e) {
      throw InputError("sensitivity parameter: " + std::string(e.what()));
    }
    const double h = parameterStep(p);
    SensitivityParameter parameter{path, p, h, {}};
    std::array<std::unique_ptr<Scene>, kStencilPoints> scenes;
    for (std::size_t k = 0; k < kStencilPoints; ++k) {
      scenes[k] = sceneAt(j, source, path, p + kStencilOffsets[k] * h);
      if (resultColumns(*scenes[k]) != columns) {
        throw InputError("sensitivity parameter '" + path +
                         "': changing it changes the results columns: expected a parameter that keeps the model's "
                         "structure");
      }
      parameter.systems[k] = &scenes[k]->system;
    }
    out.perturbed.push_back(std::move(scenes));
    out.parameters.push_back(parameter);
  }
  return out;
}

std::vector<std::string> sensitivityColumns(const std::vector<std::string>& columns,
                                            const std::vector<SensitivityParameter>& parameters) {
  std::vector<std::string> names;
  for (const SensitivityParameter& p : parameters) {
    for (std::size_t c = 1; c < columns.size(); ++c) names.push_back("d" + columns[c] + "/d" + p.name);
  }
  return names;
}

void sensitivityRow(const SensitivityScenes& scenes, const std::vector<std::string>& columns,
                    const SensitivitySample& sample, std::vector<double>& values) {
  values.clear();
  std::array<std::vector<double>, kStencilPoints> rows;
  for (std::size_t i = 0; i < scenes.parameters.size(); ++i) {
    for (std::size_t j = 0; j < kStencilPoints; ++j) {
      resultRow(*scenes.perturbed[i][j], columns, sample.perturbed[i].at[j], rows[j]);
    }
    const double h = scenes.parameters[i].step;
    // dc/dp = sum_j w_j c(p + o_j h, y + o_j h s) / h + O(h^4) (AbramowitzStegun1964, eq. 25.3.6;
    // docs/sensitivities.md, "Output derivatives")
    for (std::size_t c = 1; c < columns.size(); ++c) {
      values.push_back(stencilDerivative<double>(h, [&](int j) { return rows[static_cast<std::size_t>(j)][c]; }));
    }
  }
}

SimulationSummary runSensitivityScene(const Scene& scene, const SensitivityScenes& sensitivities, bool errorControl,
                                      const SensitivityRowCallback& onRow) {
  const std::clock_t start = std::clock();
  double lastDone = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> derivatives;
  const std::vector<std::string> columns = resultColumns(scene);
  try {
    return simulateWithSensitivities(
        scene.system, sensitivities.parameters, scene.solver, SensitivitySettings{errorControl},
        [&](const OutputSample& sample, const SensitivitySample& sensitivity) {
          sensitivityRow(sensitivities, columns, sensitivity, derivatives);
          onRow(sample, derivatives);
          lastDone = sample.t;
        });
  } catch (const InputError&) {  // includes ModelError: nothing was integrated
    throw;
  } catch (const std::exception& e) {  // IDAS could not start, ...: a failed run
    SimulationSummary summary;
    summary.ok = false;
    summary.message = e.what();
    const auto* solver = dynamic_cast<const SolverError*>(&e);
    summary.tReached = solver ? solver->time() : lastDone;
    summary.cpuSeconds = static_cast<double>(std::clock() - start) / CLOCKS_PER_SEC;
    return summary;
  }
}

SensitivitySummary::SensitivitySummary(std::vector<std::string> columns,
                                       const std::vector<SensitivityParameter>& parameters)
    : columns_(std::move(columns)) {
  for (const SensitivityParameter& p : parameters) {
    names_.push_back(p.name);
    values_.push_back(p.value);
    steps_.push_back(p.step);
  }
  const std::size_t nc = columns_.size() - 1, np = names_.size();
  finalValues_.assign(nc, 0.0);
  maxAbs_.assign(nc, -1.0);
  maxTime_.assign(nc, 0.0);
  finalDerivatives_.assign(nc * np, 0.0);
  maxDerivatives_.assign(nc * np, 0.0);
}

void SensitivitySummary::add(const std::vector<double>& row, const std::vector<double>& d) {
  const std::size_t nc = columns_.size() - 1, np = names_.size();
  any_ = true;
  for (std::size_t c = 0; c < nc; ++c) {
    const double v = row[c + 1];
    finalValues_[c] = v;
    const bool larger = std::fabs(v) > maxAbs_[c];
    if (larger) {
      maxAbs_[c] = std::fabs(v);
      maxTime_[c] = row[0];
    }
    for (std::size_t i = 0; i < np; ++i) {
      const double dv = d[i * nc + c];
      finalDerivatives_[c * np + i] = dv;
      // d max|c| / dp = sign(c) dc/dp at the output of the maximum
      if (larger) maxDerivatives_[c * np + i] = (v < 0.0 ? -dv : dv);
    }
  }
}

json SensitivitySummary::toJson(bool errorControl) const {
  json out;
  out["method"] = "forward";
  out["parameters"] = json::array();
  for (std::size_t i = 0; i < names_.size(); ++i) {
    out["parameters"].push_back({{"path", names_[i]}, {"value", values_[i]}, {"step", steps_[i]}});
  }
  out["error_control"] = errorControl;
  json finals = json::object(), maxima = json::object();
  const std::size_t nc = columns_.size() - 1, np = names_.size();
  for (std::size_t c = 0; any_ && c < nc; ++c) {
    json f = json::object(), g = json::object();
    for (std::size_t i = 0; i < np; ++i) {
      f[names_[i]] = finalDerivatives_[c * np + i];
      g[names_[i]] = maxDerivatives_[c * np + i];
    }
    finals[columns_[c + 1]] = {{"value", finalValues_[c]}, {"gradient", f}};
    maxima[columns_[c + 1]] = {{"value", maxAbs_[c]}, {"t", maxTime_[c]}, {"gradient", g}};
  }
  out["final"] = finals;
  out["max_abs"] = maxima;
  return out;
}

}  // namespace flexmbd
