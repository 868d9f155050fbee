// flexmbd summary DIR: DIR/summary.json (written by `flexmbd run` or `flexmbd kinematics`)
// printed as a short report: status and message, time reached, steps, CPU time,
// constraint violations, energy drift, singular crossings, warnings; the keys it does not
// know (tensegrity and kinematics statistics) follow as "key: value" lines.
#include "app/summary_command.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <set>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "app/command_line.hpp"

namespace flexmbd {

namespace {

namespace fs = std::filesystem;
using nlohmann::ordered_json;

using cli::kExitOk;
using cli::kExitInputError;

std::string number(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

/// A JSON value on one line: numbers with 6 digits, strings unquoted, null as "-".
std::string text(const ordered_json& v) {
  if (v.is_null()) return "-";
  if (v.is_string()) return cli::oneLine(v.get<std::string>());
  if (v.is_number_float()) return number(v.get<double>());
  if (v.is_number()) return v.dump();
  if (v.is_boolean()) return v.get<bool>() ? "yes" : "no";
  if (v.is_array()) return v.empty() ? "none" : std::to_string(v.size()) + " entries";
  return cli::oneLine(v.dump());
}

bool isNumber(const ordered_json& j, const char* key) { return j.contains(key) && j[key].is_number(); }

double num(const ordered_json& j, const char* key) { return j[key].get<double>(); }

class Report {
 public:
  explicit Report(const ordered_json& j) : j_(j) {}

  /// One line "  label  value"; marks the keys as shown.
  void line(const std::string& label, const std::string& value) {
    std::cout << "  " << label << std::string(label.size() < 22 ? 22 - label.size() : 1, ' ') << value << "\n";
  }
  void more(const std::string& value) { std::cout << std::string(24, ' ') << value << "\n"; }
  bool has(const char* key) const { return j_.contains(key) && !j_[key].is_null(); }
  const ordered_json& operator[](const char* key) {
    shown_.insert(key);
    return j_[key];
  }
  void shown(std::initializer_list<const char*> keys) { shown_.insert(keys.begin(), keys.end()); }
  /// "key value" of every key not shown yet (scalars; lists by their size).
  void rest() {
    bool first = true;
    for (auto it = j_.begin(); it != j_.end(); ++it) {
      if (shown_.count(it.key())) continue;
      if (first) std::cout << "  other:\n";
      first = false;
      std::cout << "    " << it.key() << std::string(it.key().size() < 28 ? 28 - it.key().size() : 1, ' ')
                << text(it.value()) << "\n";
    }
  }

 private:
  const ordered_json& j_;
  std::set<std::string> shown_;
};

/// The header, scene, model, status and message; the time (or the kinematics' input) reached.
void printStatusAndTime(Report& r, const ordered_json& j, const std::string& path) {
  const std::string status = r["status"].get<std::string>();
  std::cout << "summary of " << cli::oneLine(path) << "\n";
  if (r.has("scene")) r.line("scene", text(r["scene"]));
  if (r.has("model")) r.line("model", text(r["model"]));
  std::string statusText = status;
  if (status == "running") {
    statusText += " (the run has not finished, or was killed before writing its summary)";
  } else if (j.contains("error") && j["error"] == "input") {
    statusText += " (input error: nothing was integrated)";
    r.shown({"error"});
  }
  r.line("status", statusText);
  if (r.has("message") && text(r["message"]) != "") {
    r.line("message", text(r["message"]));
  } else {
    r.shown({"message"});
  }

  // ----- time -----
  if (isNumber(j, "t_reached")) {
    std::string t = number(num(j, "t_reached")) + " s";
    if (isNumber(j, "t_end")) t += " of t_end " + number(num(j, "t_end")) + " s";
    if (isNumber(j, "t_start") && num(j, "t_start") != 0.0) t += " (from " + number(num(j, "t_start")) + " s)";
    r.line("time reached", t);
    r.shown({"t_reached", "t_end", "t_start"});
  }
  if (isNumber(j, "t_failure")) r.line("solver stopped at t", text(r["t_failure"]));
  else r.shown({"t_failure"});
  if (isNumber(j, "alpha_reached")) {  // kinematics
    std::string a = number(num(j, "alpha_reached"));
    if (isNumber(j, "alpha_end")) a += " of end " + number(num(j, "alpha_end"));
    if (isNumber(j, "alpha_start")) a += " (from " + number(num(j, "alpha_start")) + ")";
    r.line("input reached", a);
    r.shown({"alpha_reached", "alpha_end", "alpha_start"});
  }
}

/// Steps, evaluations and CPU time; the integrator and its settings.
void printCostAndMethod(Report& r, const ordered_json& j) {
  // ----- cost -----
  if (r.has("steps")) {
    std::string s = text(r["steps"]);
    std::string detail;
    const auto add = [&](const char* key, const char* label) {
      if (isNumber(j, key)) detail += std::string(detail.empty() ? "" : ", ") + label + " " + text(r[key]);
    };
    add("steps_completed", "completed");
    add("residual_evals", "residual evals");
    add("rhs_evals", "rhs evals");
    add("jacobian_evals", "Jacobian evals");
    add("nonlinear_iterations", "Newton iterations");
    add("error_test_failures", "error test failures");
    add("nonlinear_conv_failures", "convergence failures");
    r.line("steps", detail.empty() ? s : s + " (" + detail + ")");
  }
  if (isNumber(j, "cpu_seconds")) r.line("CPU time", text(r["cpu_seconds"]) + " s");
  if (isNumber(j, "wall_seconds")) r.line("wall time", text(r["wall_seconds"]) + " s");

  // ----- method -----
  {
    std::string m;
    const auto add = [&](const char* key, const char* label) {
      if (r.has(key)) m += std::string(m.empty() ? "" : ", ") + label + text(r[key]);
    };
    add("integrator", "");
    add("method", "");
    add("formulation", "formulation ");
    add("linear_solver", "linear solver ");
    add("max_order", "max order ");
    add("rtol", "rtol ");
    add("atol", "atol ");
    add("atol_velocity", "atol velocity ");
    if (!m.empty()) r.line("method", m);
    if (r.has("order_limit")) r.line("order limit", text(r["order_limit"]));
    else r.shown({"order_limit"});
    if (r.has("integrator_reason")) {
      const std::string requested = r.has("integrator_requested") ? text(r["integrator_requested"]) : "";
      r.line("integrator choice", (requested.empty() ? "" : requested + ": ") + text(r["integrator_reason"]));
    } else {
      r.shown({"integrator_reason", "integrator_requested"});
    }
    if (r.has("elastic_start")) r.line("elastic start", text(r["elastic_start"]));
    else r.shown({"elastic_start"});
  }
}

/// Constraint violation and energy; singular crossings, initial corrections, warnings.
void printAccuracyAndEvents(Report& r, const ordered_json& j) {
  // ----- accuracy -----
  if (isNumber(j, "max_position_violation") || isNumber(j, "max_velocity_violation")) {
    std::string v;
    if (isNumber(j, "max_position_violation")) v += "position " + text(r["max_position_violation"]);
    if (isNumber(j, "max_velocity_violation")) {
      v += std::string(v.empty() ? "" : ", ") + "velocity " + text(r["max_velocity_violation"]);
    }
    if (isNumber(j, "model_size")) v += " (model size " + text(r["model_size"]) + ")";
    r.line("constraint violation", v);
  }
  if (isNumber(j, "energy_start") && isNumber(j, "energy_end")) {
    const double e0 = num(j, "energy_start"), e1 = num(j, "energy_end");
    std::string e = "start " + number(e0) + ", end " + number(e1) + ", drift " + number(e1 - e0);
    if (e0 != 0.0) e += " (" + number((e1 - e0) / std::fabs(e0)) + " relative)";
    r.line("energy", e);
    r.shown({"energy_start", "energy_end"});
  } else if (j.contains("energy_start") || j.contains("energy_end")) {
    r.line("energy", "not reported (the model is not conservative)");
    r.shown({"energy_start", "energy_end"});
  }

  // ----- events -----
  if (j.contains("singular_crossings") && j["singular_crossings"].is_array()) {
    const ordered_json& c = r["singular_crossings"];
    r.line("singular crossings", std::to_string(c.size()));
    for (const auto& e : c) {
      if (!e.is_object()) continue;
      const auto field = [&](const char* k) { return e.contains(k) ? text(e[k]) : std::string("-"); };
      r.more("t " + field("t_start") + " -> " + field("t_end") + " (integrator stopped at " + field("t_failure") +
             ", " + field("steps") + " steps)");
    }
  }
  if (j.contains("singular") && !j["singular"].is_null()) {  // kinematics
    const ordered_json& s = r["singular"];
    if (s.is_object()) {
      r.line("singular position", (s.contains("kind") ? text(s["kind"]) : std::string("?")) + " at alpha " +
                                      (s.contains("alpha") ? text(s["alpha"]) : std::string("?")));
    } else {
      r.line("singular position", text(s));
    }
  } else {
    r.shown({"singular"});
  }
  if (j.contains("initial_corrections") && j["initial_corrections"].is_array()) {
    std::string largest;
    double worst = 0.0;
    for (const auto& c : r["initial_corrections"]) {
      if (!c.is_object() || !c.contains("position") || !c["position"].is_number()) continue;
      const double p = c["position"].get<double>();
      const double a = c.contains("angle") && c["angle"].is_number() ? c["angle"].get<double>() : 0.0;
      if (std::max(p, a) > worst) {
        worst = std::max(p, a);
        largest = (c.contains("body") ? text(c["body"]) : std::string("?")) + " (position " + number(p) +
                  ", angle " + number(a) + ")";
      }
    }
    r.line("initial corrections", largest.empty() ? "none" : "largest: " + largest);
  }
  if (j.contains("warnings") && j["warnings"].is_array()) {
    const ordered_json& w = r["warnings"];
    r.line("warnings", w.empty() ? "none" : std::to_string(w.size()));
    for (const auto& m : w) r.more("- " + text(m));
  }
}

void printSummary(const ordered_json& j, const std::string& path) {
  Report r(j);
  printStatusAndTime(r, j, path);
  printCostAndMethod(r, j);
  printAccuracyAndEvents(r, j);
  r.shown({"last_step_size", "linear_setups", "initial_position_iterations", "output_step", "steps_completed",
           "residual_evals", "rhs_evals", "jacobian_evals", "nonlinear_iterations", "error_test_failures",
           "nonlinear_conv_failures", "model_size"});
  r.rest();
}

}  // namespace

int runSummaryCommand(const std::vector<std::string>& args) {
  std::vector<std::string> positional;
  try {
    const cli::SplitArguments split = cli::splitArguments(args, {}, cli::kCommonFlags, "summary: ");
    positional = split.positional;
    if (positional.empty()) throw cli::UsageError("summary: missing the output directory (flexmbd summary DIR)");
    if (positional.size() > 1) {
      throw cli::UsageError("summary: expected one directory, got " + std::to_string(positional.size()) +
                            " arguments ('" + positional[0] + "', '" + positional[1] + "', ...)");
    }
  } catch (const std::exception& e) {
    cli::printError(e.what());
    return kExitInputError;
  }
  fs::path path(positional[0]);
  std::error_code ec;
  if (!fs::exists(path, ec)) {
    cli::printError("summary: '" + path.string() + "' does not exist (give the --out DIR of flexmbd run or kinematics)");
    return kExitInputError;
  }
  if (fs::is_directory(path, ec)) path /= "summary.json";
  if (!fs::is_regular_file(path, ec)) {
    cli::printError("summary: no " + path.string() + " (give the --out DIR of flexmbd run or kinematics)");
    return kExitInputError;
  }
  ordered_json j;
  try {
    std::ifstream in(path);
    if (!in) throw std::runtime_error("cannot be opened");
    j = ordered_json::parse(in);
  } catch (const std::exception& e) {
    cli::printError("summary: " + path.string() + " is not valid JSON (" + e.what() + ")");
    return kExitInputError;
  }
  if (!j.is_object() || !j.contains("status") || !j["status"].is_string()) {
    cli::printError("summary: " + path.string() + " is not a flexmbd summary (expected an object with a \"status\")");
    return kExitInputError;
  }
  try {
    printSummary(j, path.string());
  } catch (const std::exception& e) {  // a key of an unexpected type
    std::cout.flush();
    cli::printError("summary: " + path.string() + " is malformed (" + e.what() + ")");
    return kExitInputError;
  }
  std::cout.flush();
  return kExitOk;
}

}  // namespace flexmbd
