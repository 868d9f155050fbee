#include "io/results_writer.hpp"

#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <system_error>

#include <nlohmann/json.hpp>

#include "core/system_evaluation.hpp"

namespace flexmbd {
namespace {

/// A header field, quoted as RFC 4180 asks if it holds a separator, quote or newline.
std::string csvField(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

/// 17 significant digits: every double reads back exactly (-0 is written as 0).
void appendNumber(std::string& line, double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", x == 0.0 ? 0.0 : x);
  line += buf;
}

std::string sizeMismatch(const char* what, long got, long expected, double t) {
  char tbuf[32];
  std::snprintf(tbuf, sizeof tbuf, "%.17g", t);
  return std::string("results writer: output sample at t = ") + tbuf + " has " + what + " of size " +
         std::to_string(got) + ", expected " + std::to_string(expected);
}

/// Writes `j` to DIR/summary.json via a temporary file and a rename.
void writeJsonFile(const std::filesystem::path& dir, const nlohmann::ordered_json& j) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw std::runtime_error("cannot create output directory '" + dir.string() + "': " + ec.message());
  const auto target = dir / "summary.json";
  const auto tmp = dir / "summary.json.tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    if (!out) throw std::runtime_error("cannot write '" + tmp.string() + "'");
    out << j.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) << '\n';
    out.flush();
    if (!out) throw std::runtime_error("cannot write '" + tmp.string() + "'");
  }
  std::filesystem::rename(tmp, target, ec);
  if (ec) throw std::runtime_error("cannot write '" + target.string() + "': " + ec.message());
}

nlohmann::ordered_json numberOrNull(double x) {
  return std::isfinite(x) ? nlohmann::ordered_json(x) : nlohmann::ordered_json(nullptr);
}

}  // namespace

ResultsWriter::ResultsWriter(const std::filesystem::path& dir, const Scene& scene)
    : scene_(scene), path_(dir / "results.csv"), lastTime_(std::numeric_limits<double>::quiet_NaN()) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw std::runtime_error("cannot create output directory '" + dir.string() + "': " + ec.message());
  removeStaleResults(dir);

  const System& sys = scene.system;
  columns_.push_back("t");
  const auto coords = sys.coordinateNames();
  columns_.insert(columns_.end(), coords.begin(), coords.end());
  for (const auto& c : coords) columns_.push_back(c + "_dot");
  const auto reactions = reactionOutputNames(sys);
  columns_.insert(columns_.end(), reactions.begin(), reactions.end());
  for (const auto& o : scene.outputs) {
    const auto names = o.columnNames();
    columns_.insert(columns_.end(), names.begin(), names.end());
  }
}

void ResultsWriter::open() {
  out_.open(path_, std::ios::trunc);
  if (!out_) throw std::runtime_error("cannot create '" + path_.string() + "'");
  std::string header;
  for (std::size_t k = 0; k < columns_.size(); ++k) header += (k ? "," : "") + csvField(columns_[k]);
  out_ << header << '\n';
}

void ResultsWriter::write(const OutputSample& s) {
  const System& sys = scene_.system;
  const long nq = sys.numCoordinates();
  const long m = sys.numConstraintEquations();
  if (s.q.size() != nq) throw std::runtime_error(sizeMismatch("q", s.q.size(), nq, s.t));
  if (s.v.size() != nq) throw std::runtime_error(sizeMismatch("v", s.v.size(), nq, s.t));
  if (s.lambda.size() != m) throw std::runtime_error(sizeMismatch("lambda", s.lambda.size(), m, s.t));
  // The whole row first: a row with a non-finite value is not written (the run stops).
  std::vector<double> values;
  values.reserve(columns_.size());
  values.push_back(s.t);
  for (long k = 0; k < nq; ++k) values.push_back(s.q[k]);
  for (long k = 0; k < nq; ++k) values.push_back(s.v[k]);
  const VecX reactions = reactionOutputs(sys, s.q, s.lambda);
  for (Eigen::Index k = 0; k < reactions.size(); ++k) values.push_back(reactions[k]);
  for (const auto& o : scene_.outputs) {
    for (double x : o.evaluate(sys, s.q, s.v)) values.push_back(x);
  }
  if (values.size() != columns_.size()) {
    throw std::runtime_error(sizeMismatch("a row", static_cast<long>(values.size()),
                                          static_cast<long>(columns_.size()), s.t));
  }
  for (std::size_t k = 0; k < values.size(); ++k) {
    if (!std::isfinite(values[k])) {
      char tbuf[32];
      std::snprintf(tbuf, sizeof tbuf, "%.10g", s.t);
      throw NonFiniteResult("non-finite value " + std::string(std::isnan(values[k]) ? "nan" : "inf") +
                            " in column \"" + columns_[k] + "\" at t = " + tbuf);
    }
  }
  if (!out_.is_open()) open();
  std::string line;
  line.reserve(24 * columns_.size());
  for (std::size_t k = 0; k < values.size(); ++k) {
    if (k) line += ',';
    appendNumber(line, values[k]);
  }
  line += '\n';
  out_ << line;
  out_.flush();
  if (!out_) throw std::runtime_error("cannot write '" + path_.string() + "' (disk full?)");
  ++rows_;
  lastTime_ = s.t;
}

void removeStaleResults(const std::filesystem::path& dir) {
  std::error_code ec;
  for (const char* name : {"results.csv", "summary.json", "summary.json.tmp"}) {
    std::filesystem::remove(dir / name, ec);
    if (ec) {
      throw std::runtime_error("cannot delete stale '" + (dir / name).string() + "': " + ec.message());
    }
  }
}

void writeSummary(const std::filesystem::path& dir, const SimulationSummary& summary, const Scene& scene) {
  const SolverSettings& s = scene.solver;
  const IntegratorStats& st = summary.stats;
  nlohmann::ordered_json j;  // keys in this order in the file
  j["status"] = summary.ok ? "ok" : "failed";
  j["message"] = summary.message;
  j["scene"] = scene.name;
  j["t_reached"] = numberOrNull(summary.tReached);
  j["t_failure"] = summary.ok ? nlohmann::ordered_json(nullptr) : numberOrNull(summary.failureTime);
  j["steps"] = st.steps;
  j["residual_evals"] = st.residualEvals;
  j["jacobian_evals"] = st.jacobianEvals;
  j["nonlinear_iterations"] = st.nonlinearIterations;
  j["nonlinear_conv_failures"] = st.nonlinearConvFailures;
  j["error_test_failures"] = st.errorTestFailures;
  j["linear_setups"] = st.linearSetups;
  j["last_step_size"] = numberOrNull(st.lastStepSize);
  j["initial_position_iterations"] = summary.initialPositionIterations;
  j["cpu_seconds"] = numberOrNull(summary.cpuSeconds);
  j["max_position_violation"] = numberOrNull(summary.maxPositionViolation);
  j["max_velocity_violation"] = numberOrNull(summary.maxVelocityViolation);
  j["energy_start"] = summary.energyStart ? numberOrNull(*summary.energyStart) : nlohmann::ordered_json(nullptr);
  j["energy_end"] = summary.energyEnd ? numberOrNull(*summary.energyEnd) : nlohmann::ordered_json(nullptr);
  j["formulation"] = toString(s.formulation);
  j["linear_solver"] = summary.usedKlu ? "klu" : "dense";
  j["rtol"] = s.rtol;
  j["atol"] = s.atol;
  j["atol_velocity"] = s.atolVelocity ? *s.atolVelocity : s.atol;
  j["t_start"] = s.tStart;
  j["t_end"] = s.tEnd;
  j["output_step"] = s.outputStep;
  writeJsonFile(dir, j);
}

void writeInputErrorSummary(const std::filesystem::path& dir, const std::string& message) {
  nlohmann::ordered_json j;
  j["status"] = "failed";
  j["error"] = "input";
  j["message"] = message;
  writeJsonFile(dir, j);
}

}  // namespace flexmbd
