#include "results/adjoint_results.hpp"

#include <cmath>
#include <cstdlib>
#include <ctime>

#include <nlohmann/json.hpp>

#include "core/errors.hpp"
#include "results/results_writer.hpp"

namespace flexmbd {
namespace {

/// Where a column's value comes from: a coordinate, a velocity or a column of one of the
/// scene's requested outputs.
struct ColumnSource {
  enum class Kind { Coordinate, Velocity, Requested } kind = Kind::Coordinate;
  int index = 0;   ///< the coordinate or velocity, or the requested output
  int column = 0;  ///< Requested: the column within that output's columns
};

ColumnSource columnSource(const Scene& scene, const std::string& column, const std::string& spec) {
  const System& sys = scene.system;
  const auto coords = sys.coordinateNames(), velocities = sys.velocityNames();
  for (std::size_t k = 0; k < coords.size(); ++k) {
    if (coords[k] == column) return {ColumnSource::Kind::Coordinate, static_cast<int>(k), 0};
  }
  for (std::size_t k = 0; k < velocities.size(); ++k) {
    if (velocities[k] == column) return {ColumnSource::Kind::Velocity, static_cast<int>(k), 0};
  }
  for (std::size_t r = 0; r < scene.outputs.size(); ++r) {
    const auto names = scene.outputs[r].columnNames();
    for (std::size_t c = 0; c < names.size(); ++c) {
      if (names[c] == column) return {ColumnSource::Kind::Requested, static_cast<int>(r), static_cast<int>(c)};
    }
  }
  const auto all = resultColumns(scene);
  const bool exists = std::find(all.begin(), all.end(), column) != all.end();
  throw InputError("adjoint output '" + spec + "': " +
                   (exists ? "column \"" + column +
                                 "\" needs the accelerations or multipliers (an acceleration, reaction or joint output)"
                           : "no results column \"" + column + "\"") +
                   ": expected a coordinate, a velocity (\"<body>.<coord>_dot\") or a column of the scene's outputs");
}

double columnValue(const Scene& scene, const ColumnSource& c, const VecX& q, const VecX& v) {
  switch (c.kind) {
    case ColumnSource::Kind::Coordinate: return q[c.index];
    case ColumnSource::Kind::Velocity: return v[c.index];
    case ColumnSource::Kind::Requested:
      return scene.outputs[static_cast<std::size_t>(c.index)].evaluate(scene.system, q, v)[static_cast<std::size_t>(c.column)];
  }
  return 0.0;
}

}  // namespace

IntegralOutput integralOutput(const std::string& spec, const Scene& base, const SensitivityScenes& scenes) {
  const auto colon = spec.find(':');
  const std::string kind = colon == std::string::npos ? "" : spec.substr(0, colon);
  std::string column = colon == std::string::npos ? "" : spec.substr(colon + 1);
  double rho = 0.0;
  if (kind == "ks") {  // ks:COLUMN:RHO
    const auto last = column.rfind(':');
    char* end = nullptr;
    const std::string text = last == std::string::npos ? "" : column.substr(last + 1);
    rho = std::strtod(text.c_str(), &end);
    if (text.empty() || *end != '\0' || !(rho > 0.0) || !std::isfinite(rho)) {
      throw InputError("adjoint output '" + spec + "': expected ks:COLUMN:RHO with RHO a positive number (the "
                       "aggregate's sharpness, 1 / the column's unit)");
    }
    column = column.substr(0, last);
  } else if (kind != "integral" && kind != "integral_square" && kind != "final") {
    throw InputError("adjoint output '" + spec +
                     "': expected KIND:COLUMN with KIND \"integral\" (int c dt), \"integral_square\" (int c^2 dt) or "
                     "\"ks\" (ks:COLUMN:RHO, the aggregate ln(int exp(RHO c) dt / T) / RHO) or \"final\" (c(T))");
  }
  const ColumnSource source = columnSource(base, column, spec);
  // the scene of each system the integrand can be given (the base and the perturbed ones)
  std::vector<std::pair<const System*, const Scene*>> sceneOf{{&base.system, &base}};
  for (const auto& points : scenes.perturbed) {
    for (const auto& s : points) sceneOf.emplace_back(&s->system, s.get());
  }
  const auto value = [sceneOf, source](const System& sys, const VecX& q, const VecX& v) {
    for (const auto& [system, scene] : sceneOf) {
      if (system == &sys) return columnValue(*scene, source, q, v);
    }
    throw std::logic_error("integral output: a system of no scene of the run");
  };
  IntegralOutput out{spec, nullptr, nullptr};
  if (kind == "integral" || kind == "final") {
    out.terminal = kind == "final";
    out.integrand = [value](const System& sys, double, const VecX& q, const VecX& v) { return value(sys, q, v); };
  } else if (kind == "integral_square") {
    out.integrand = [value](const System& sys, double, const VecX& q, const VecX& v) {
      const double c = value(sys, q, v);
      return c * c;
    };
  } else {
    // Kreisselmeier-Steinhauser aggregate, a smooth maximum of c(t) over the run:
    // KS = ln(int exp(rho c) dt / T) / rho, dKS/dp = dG/dp / (rho G) with G = int exp(rho c) dt
    // (KreisselmeierSteinhauser1979; its continuous form, e.g. PoonMartins2007)
    out.integrand = [value, rho](const System& sys, double, const VecX& q, const VecX& v) {
      return std::exp(rho * value(sys, q, v));
    };
    out.report = [rho](double span, double& G, VecX& gradient) {
      gradient /= rho * G;
      G = std::log(G / span) / rho;
    };
  }
  return out;
}

AdjointSummary runAdjointScene(const Scene& scene, const SensitivityScenes& scenes, const std::vector<std::string>& specs,
                               const OutputCallback& onOutput) {
  std::vector<IntegralOutput> outputs;
  for (const std::string& spec : specs) outputs.push_back(integralOutput(spec, scene, scenes));
  return simulateWithAdjoint(scene.system, scenes.parameters, outputs, scene.solver, onOutput);
}

nlohmann::json adjointJson(const AdjointSummary& summary, const SensitivityScenes& scenes) {
  nlohmann::json out;
  out["method"] = "adjoint";
  out["parameters"] = nlohmann::json::array();
  for (const SensitivityParameter& p : scenes.parameters) {
    out["parameters"].push_back({{"path", p.name}, {"value", p.value}, {"step", p.step}});
  }
  nlohmann::json integrals = nlohmann::json::object();
  for (const IntegralGradient& g : summary.outputs) {
    nlohmann::json gradient = nlohmann::json::object();
    for (std::size_t i = 0; i < scenes.parameters.size(); ++i) {
      gradient[scenes.parameters[i].name] = g.gradient[static_cast<Eigen::Index>(i)];
    }
    integrals[g.name] = {{"value", g.value}, {"gradient", gradient}};
  }
  out["integrals"] = integrals;
  out["backward_ok"] = summary.backwardOk;
  out["backward_message"] = summary.backwardMessage;
  out["backward_steps"] = summary.backwardSteps;
  out["recorded_again"] = summary.recordedAgain;
  out["backward_cpu_seconds"] = summary.backwardCpuSeconds;
  return out;
}

}  // namespace flexmbd
