/// @file
/// The scene side of a sensitivity run (docs/sensitivities.md): the parameters named by
/// scene paths, the scenes rebuilt with each parameter one and two steps up and down, the results
/// columns d\<column\>/d\<parameter\> and the gradients of the summary's scalars.
#pragma once

#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "sensitivity/sensitivity_run.hpp"
#include "scene/scene.hpp"

namespace flexmbd {

/// The parameters of a run and, per parameter, the scenes read with p + kStencilOffsets[j] h
/// (p +- h, p +- 2 h) by the same reader as the scene itself (every numeric scene key can
/// be a parameter).
struct SensitivityScenes {
  std::vector<std::array<std::unique_ptr<Scene>, kStencilPoints>> perturbed;  ///< [parameter][point]
  std::vector<SensitivityParameter> parameters;  ///< their systems are those of `perturbed`
};

/// Reads the parameters `paths` (dotted scene paths, scene/scene_path.hpp) from the scene
/// text (already read by parseSceneText: valid) and builds the perturbed scenes.
/// @throws InputError naming the parameter: a path that does not exist or is not a number,
/// given twice, a perturbed scene that is not valid (a key that must be an integer, a
/// value at a bound), or one with other results columns.
SensitivityScenes buildSensitivityScenes(const std::string& sceneText, const std::string& source, const Scene& base,
                                         const std::vector<std::string>& paths);

/// "d\<column\>/d\<parameter\>" for every column but t, parameter by parameter.
std::vector<std::string> sensitivityColumns(const std::vector<std::string>& columns,
                                            const std::vector<SensitivityParameter>& parameters);

/// The derivatives of one row (sensitivityColumns' order): for each parameter and column,
/// sum_j w_j c(at[j]) / h (stencilDerivative), c evaluated by resultRow on the perturbed scenes.
void sensitivityRow(const SensitivityScenes& scenes, const std::vector<std::string>& columns,
                    const SensitivitySample& sample, std::vector<double>& values);

/// One output of a sensitivity run: the sample and the derivatives of its row
/// (sensitivityColumns' order).
using SensitivityRowCallback = std::function<void(const OutputSample&, const std::vector<double>&)>;

/// The run of `scene` with forward sensitivities (simulateWithSensitivities), each output's
/// derivative row made by sensitivityRow; a failure after the input was accepted (IDAS
/// could not start, ...) returns a failed summary, its rows kept, as
/// simulateKeepingFailures does. The command line and Python both run this.
/// @throws InputError (ModelError included): nothing was integrated.
SimulationSummary runSensitivityScene(const Scene& scene, const SensitivityScenes& sensitivities, bool errorControl,
                                      const SensitivityRowCallback& onRow);

/// The gradients of the scalar summaries of the results columns: the final value and the
/// largest magnitude max_k |c(t_k)| (derivative sign(c) dc/dp at the output where it is
/// reached; not differentiable where two outputs tie, the first one is taken).
class SensitivitySummary {
 public:
  SensitivitySummary(std::vector<std::string> columns, const std::vector<SensitivityParameter>& parameters);
  /// One row of results (columns) and its derivatives (sensitivityColumns' order).
  void add(const std::vector<double>& row, const std::vector<double>& derivatives);
  /// {"parameters": [{"path", "value", "step"}], "error_control", "final": {column:
  /// {parameter: d}}, "max_abs": {column: {"value", "t", "gradient": {parameter: d}}}}.
  nlohmann::json toJson(bool errorControl) const;

 private:
  std::vector<std::string> columns_;
  std::vector<std::string> names_;
  std::vector<double> values_, steps_;
  std::vector<double> finalValues_, finalDerivatives_, maxAbs_, maxTime_, maxDerivatives_;
  bool any_ = false;
};

}  // namespace flexmbd
