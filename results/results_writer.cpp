#include "results/results_writer.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <system_error>

#include <nlohmann/json.hpp>

#include "core/system_evaluation.hpp"
#include "results/hdf5_results.hpp"

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

/// Writes all of `data` to `fd` at its current offset: 0, or the errno of the failure
/// (ENOSPC: disk full, EFBIG: file size limit).
int writeAll(int fd, const char* data, std::size_t size) {
  while (size > 0) {
    const ssize_t n = ::write(fd, data, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    if (n == 0) return EIO;
    data += n;
    size -= static_cast<std::size_t>(n);
  }
  return 0;
}

/// Writes `text` as the whole content of `path` (created or truncated): 0 or an errno.
int writeWholeFile(const std::filesystem::path& path, const std::string& text) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return errno;
  int err = writeAll(fd, text.data(), text.size());
  if (::close(fd) != 0 && err == 0) err = errno;
  return err;
}

/// Overwrites the existing `path` in place with `text` (no new blocks needed when the file
/// was at least as long) and cuts it to the length of `text`: 0 or an errno.
int overwriteInPlace(const std::filesystem::path& path, const std::string& text) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0) return errno;
  int err = writeAll(fd, text.data(), text.size());
  if (err == 0 && ::ftruncate(fd, static_cast<off_t>(text.size())) != 0) err = errno;
  if (::close(fd) != 0 && err == 0) err = errno;
  return err;
}

std::string timeText(double t) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", t);
  return buf;
}

void writeJsonFile(const std::filesystem::path& dir, const nlohmann::ordered_json& j) {
  writeSummaryText(dir, j.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) + '\n');
}

nlohmann::ordered_json numberOrNull(double x) {
  return std::isfinite(x) ? nlohmann::ordered_json(x) : nlohmann::ordered_json(nullptr);
}

}  // namespace

ResultsFormat parseResultsFormat(const std::string& name) {
  if (name == "csv") return ResultsFormat::Csv;
  if (name == "hdf5") return ResultsFormat::Hdf5;
  throw std::invalid_argument("unknown results format '" + name + "' (known formats: csv, hdf5)");
}

const char* resultsFileName(ResultsFormat format) {
  return format == ResultsFormat::Hdf5 ? "results.h5" : "results.csv";
}

ResultsWriter::ResultsWriter(const std::filesystem::path& dir, const Scene& scene, ResultsFormat format)
    : scene_(scene),
      format_(format),
      path_(dir / resultsFileName(format)),
      lastTime_(std::numeric_limits<double>::quiet_NaN()) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw std::runtime_error("cannot create output directory '" + dir.string() + "': " + ec.message());
  removeStaleResults(dir);
  reserveSummary(dir);

  columns_ = resultColumns(scene);
  sceneColumns_ = columns_;
  joints_ = std::make_unique<SpatialJointOutputs>(scene.system);
}

std::vector<std::string> resultColumns(const Scene& scene) {
  const System& sys = scene.system;
  std::vector<std::string> columns = {"t"};
  const auto coords = sys.coordinateNames(), velocities = sys.velocityNames(), accelerations = sys.accelerationNames();
  columns.insert(columns.end(), coords.begin(), coords.end());
  columns.insert(columns.end(), velocities.begin(), velocities.end());
  columns.insert(columns.end(), accelerations.begin(), accelerations.end());
  const auto reactions = reactionOutputNames(sys);
  columns.insert(columns.end(), reactions.begin(), reactions.end());
  for (const auto& o : scene.outputs) {
    const auto names = o.columnNames();
    columns.insert(columns.end(), names.begin(), names.end());
  }
  const auto joints = SpatialJointOutputs(sys).columnNames();
  columns.insert(columns.end(), joints.begin(), joints.end());
  return columns;
}

void resultRow(const Scene& scene, const std::vector<std::string>& columns, const OutputSample& s,
               std::vector<double>& values) {
  SpatialJointOutputs joints(scene.system);
  resultRow(scene, columns, s, values, joints);
}

void resultRow(const Scene& scene, const std::vector<std::string>& columns, const OutputSample& s,
               std::vector<double>& values, SpatialJointOutputs& joints) {
  const System& sys = scene.system;
  const long nq = sys.numCoordinates(), nv = sys.numVelocities();
  const long m = sys.numConstraintEquations();
  if (s.q.size() != nq) throw std::runtime_error(sizeMismatch("q", s.q.size(), nq, s.t));
  if (s.v.size() != nv) throw std::runtime_error(sizeMismatch("v", s.v.size(), nv, s.t));
  if (s.a.size() != nv) throw std::runtime_error(sizeMismatch("a", s.a.size(), nv, s.t));
  if (s.lambda.size() != m) throw std::runtime_error(sizeMismatch("lambda", s.lambda.size(), m, s.t));
  values.clear();
  values.reserve(columns.size());
  values.push_back(s.t);
  for (long k = 0; k < nq; ++k) values.push_back(s.q[k]);
  for (long k = 0; k < nv; ++k) values.push_back(s.v[k]);
  for (long k = 0; k < nv; ++k) values.push_back(s.a[k]);
  const VecX reactions = reactionOutputs(sys, s.q, s.lambda);
  for (Eigen::Index k = 0; k < reactions.size(); ++k) values.push_back(reactions[k]);
  for (const auto& o : scene.outputs) {
    for (double x : o.evaluate(sys, s.q, s.v)) values.push_back(x);
  }
  joints.append(s.q, s.v, values);
  if (values.size() != columns.size()) {
    throw std::runtime_error(sizeMismatch("a row", static_cast<long>(values.size()),
                                          static_cast<long>(columns.size()), s.t));
  }
  for (std::size_t k = 0; k < values.size(); ++k) {
    if (!std::isfinite(values[k])) {
      char tbuf[32];
      std::snprintf(tbuf, sizeof tbuf, "%.10g", s.t);
      throw NonFiniteResult("non-finite value " + std::string(std::isnan(values[k]) ? "nan" : "inf") +
                            " in column \"" + columns[k] + "\" at t = " + tbuf);
    }
  }
}

RowFile::~RowFile() {
  if (fd_ >= 0) ::close(fd_);
}

void RowFile::open(const std::filesystem::path& path, const std::string& header) {
  path_ = path;
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) throw OutputWriteError("cannot create '" + path.string() + "': " + std::strerror(errno));
  if (const int err = writeAll(fd_, header.data(), header.size())) {
    if (::ftruncate(fd_, 0) == 0) ::lseek(fd_, 0, SEEK_SET);
    throw OutputWriteError("cannot write the header of '" + path.string() + "': " + std::strerror(err));
  }
  bytes_ = static_cast<long long>(header.size());
}

void RowFile::append(const std::string& row, double t, const char* variable) {
  if (const int err = writeAll(fd_, row.data(), row.size())) {
    if (::ftruncate(fd_, static_cast<off_t>(bytes_)) == 0) ::lseek(fd_, static_cast<off_t>(bytes_), SEEK_SET);
    throw OutputWriteError("cannot write '" + path_.string() + "' at " + variable + " = " + timeText(t) + ": " +
                           std::strerror(err) +
                           " (" + std::to_string(rows_) + " complete rows kept)");
  }
  bytes_ += static_cast<long long>(row.size());
  ++rows_;
}

ResultsWriter::~ResultsWriter() {
  if (fd_ >= 0) ::close(fd_);
}  // h5_ closes results.h5

void ResultsWriter::open() {
  fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) throw OutputWriteError("cannot create '" + path_.string() + "': " + std::strerror(errno));
  std::string header;
  for (std::size_t k = 0; k < columns_.size(); ++k) header += (k ? "," : "") + csvField(columns_[k]);
  header += '\n';
  if (const int err = writeAll(fd_, header.data(), header.size())) {
    if (::ftruncate(fd_, 0) == 0) ::lseek(fd_, 0, SEEK_SET);
    throw OutputWriteError("cannot write the header of '" + path_.string() + "': " + std::strerror(err));
  }
  bytes_ = static_cast<long long>(header.size());
}

void ResultsWriter::addColumns(const std::vector<std::string>& names) {
  if (rows_ > 0 || fd_ >= 0 || h5_) throw std::logic_error("ResultsWriter::addColumns after the first row");
  columns_.insert(columns_.end(), names.begin(), names.end());
}

void ResultsWriter::write(const OutputSample& s) { write(s, {}); }

void ResultsWriter::write(const OutputSample& s, const std::vector<double>& added) {
  if (added.size() != columns_.size() - sceneColumns_.size()) {
    throw std::invalid_argument("ResultsWriter::write: " + std::to_string(added.size()) + " added values for " +
                                std::to_string(columns_.size() - sceneColumns_.size()) + " added columns");
  }
  // The whole row first: a row with a non-finite value is not written (the run stops).
  std::vector<double>& values = row_;
  resultRow(scene_, sceneColumns_, s, values, *joints_);
  for (std::size_t k = 0; k < added.size(); ++k) {
    if (!std::isfinite(added[k])) {
      throw NonFiniteResult("non-finite value " + std::string(std::isnan(added[k]) ? "nan" : "inf") + " in column \"" +
                            columns_[sceneColumns_.size() + k] + "\" at t = " + timeText(s.t));
    }
    values.push_back(added[k]);
  }
  if (format_ == ResultsFormat::Hdf5) {
    if (!h5_) {
      auto file = std::make_unique<Hdf5RowFile>();
      file->open(path_, columns_);
      h5_ = std::move(file);
    }
    h5_->append(values, s.t);
    ++rows_;
    lastTime_ = s.t;
    return;
  }
  if (fd_ < 0) open();
  std::string line;
  line.reserve(24 * columns_.size());
  for (std::size_t k = 0; k < values.size(); ++k) {
    if (k) line += ',';
    appendNumber(line, values[k]);
  }
  line += '\n';
  if (const int err = writeAll(fd_, line.data(), line.size())) {
    // Cut a partly written row (never a half row in the file), ready for no more rows.
    if (::ftruncate(fd_, static_cast<off_t>(bytes_)) == 0) ::lseek(fd_, static_cast<off_t>(bytes_), SEEK_SET);
    throw OutputWriteError("cannot write '" + path_.string() + "' at t = " + timeText(s.t) + ": " +
                           std::strerror(err) + " (" + std::to_string(rows_) + " complete rows kept)");
  }
  bytes_ += static_cast<long long>(line.size());
  ++rows_;
  lastTime_ = s.t;
}

void removeStaleResults(const std::filesystem::path& dir) {
  std::error_code ec;
  std::vector<std::filesystem::path> stale;
  for (const char* name : {"results.csv", "results.h5", "summary.json", "summary.json.tmp"}) stale.push_back(dir / name);
  // Frames of an earlier run with --vtk (VtkWriter: bodies_NNNNNN.vtu, bodies.pvd): left
  // there, they would be read as frames of this run's model.
  const std::filesystem::path vtk = dir / "vtk";
  if (std::filesystem::is_directory(vtk, ec)) {
    for (const auto& entry : std::filesystem::directory_iterator(vtk, ec)) {
      const std::string name = entry.path().filename().string();
      const bool frame = name.rfind("bodies_", 0) == 0 && name.size() > 11 &&
                         name.compare(name.size() - 4, 4, ".vtu") == 0;
      if (frame || name == "bodies.pvd") stale.push_back(entry.path());
    }
  }
  for (const auto& path : stale) {
    std::filesystem::remove(path, ec);
    if (ec) throw std::runtime_error("cannot delete stale '" + path.string() + "': " + ec.message());
  }
}

void reserveSummary(const std::filesystem::path& dir) {
  nlohmann::ordered_json j;
  j["status"] = "running";
  j["message"] = "the run has not finished, or was killed before it could write its summary";
  std::string text = j.dump(2) + '\n';
  text.append(kSummaryReserve > text.size() ? kSummaryReserve - text.size() : 0, ' ');
  const std::filesystem::path target = dir / "summary.json";
  if (const int err = writeWholeFile(target, text)) {
    std::error_code ec;
    std::filesystem::remove(target, ec);  // not an empty summary.json (a full disk)
    throw OutputWriteError("cannot write '" + target.string() + "': " + std::strerror(err) +
                           " (nothing was run)");
  }
}

void writeSummaryText(const std::filesystem::path& dir, const std::string& text) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw OutputWriteError("cannot create output directory '" + dir.string() + "': " + ec.message());
  const auto target = dir / "summary.json";
  const auto tmp = dir / "summary.json.tmp";
  int err = writeWholeFile(tmp, text);
  if (err == 0) {
    std::filesystem::rename(tmp, target, ec);
    if (!ec) return;
    err = ec.value();
  }
  std::filesystem::remove(tmp, ec);
  // Disk full: the summary reserved at the start of the run (reserveSummary) holds the space.
  if (text.size() <= kSummaryReserve && overwriteInPlace(target, text) == 0) return;
  throw OutputWriteError("cannot write '" + target.string() + "': " + std::strerror(err));
}

namespace {

/// The tolerances the run used per coordinate class and the model scales their defaults
/// follow (null before the run computed them: a failed initialisation).
nlohmann::ordered_json tolerancesObject(const SimulationSummary& summary) {
  const ClassTolerances& t = summary.tolerances;
  if (!(t.position > 0.0)) return nullptr;
  const ModelScales& m = summary.scales;
  nlohmann::ordered_json j;
  j["rtol"] = t.rtol;
  j["position"] = t.position;
  j["angle"] = t.angle;
  j["elastic"] = t.elastic;
  j["velocity"] = t.velocity;
  j["angular_velocity"] = t.angularVelocity;
  j["elastic_velocity"] = t.elasticVelocity;
  j["length_scale"] = m.length;
  j["time_scale"] = m.timeScale;
  j["elastic_size"] = m.elasticSize;
  j["elastic_body"] = m.elasticBody.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(m.elasticBody);
  j["lowest_elastic_frequency"] = m.lowestFrequency;
  return j;
}

namespace {

/// The units of the columns whose unit the name cannot tell: a driver's effort is a
/// torque (N m) when it drives an angle (body_theta, joint_angle), else a force (N).
nlohmann::ordered_json modelUnits(const System& sys) {
  nlohmann::ordered_json units = nlohmann::ordered_json::object();
  for (int c = 0; c < sys.numConstraints(); ++c) {
    const Constraint& con = sys.constraint(ConstraintIndex(c));
    if (!con.isDriver()) continue;
    const std::string type = con.typeName();
    const bool angle = type == "body_theta" || type == "joint_angle";
    units[con.name() + ".effort"] = angle ? "N m" : "N";
  }
  return units;
}

}  // namespace

nlohmann::ordered_json summaryObject(const SimulationSummary& summary, const Scene& scene) {
  const SolverSettings& s = scene.solver;
  const IntegratorStats& st = summary.stats;
  nlohmann::ordered_json j;  // keys in this order in the file
  j["status"] = summary.ok ? "ok" : summary.interruptedBySignal ? "interrupted" : "failed";
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
  j["model_size"] = summary.modelSize;
  nlohmann::ordered_json corrections = nlohmann::ordered_json::array();
  for (const InitialCorrection& c : summary.initialCorrections) {
    nlohmann::ordered_json e;
    e["body"] = c.body;
    e["position"] = c.position;
    e["angle"] = c.angle;
    e["coordinate"] = c.coordinate;
    e["given"] = c.given;
    e["corrected"] = c.corrected;
    e["constraint"] = c.constraint.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(c.constraint);
    e["residual"] = c.residual;
    corrections.push_back(e);
  }
  j["initial_corrections"] = corrections;
  j["warnings"] = summary.warnings;
  j["redundant_constraints"] = summary.redundantConstraints;
  j["energy_start"] = summary.energyStart ? numberOrNull(*summary.energyStart) : nlohmann::ordered_json(nullptr);
  j["energy_end"] = summary.energyEnd ? numberOrNull(*summary.energyEnd) : nlohmann::ordered_json(nullptr);
  nlohmann::ordered_json crossings = nlohmann::ordered_json::array();
  for (const SingularCrossing& c : summary.singularCrossings) {
    crossings.push_back({{"t_failure", c.tFailure}, {"t_start", c.tStart}, {"t_end", c.tEnd}, {"steps", c.steps}});
  }
  j["singular_crossings"] = crossings;
  nlohmann::ordered_json participation = nlohmann::ordered_json::array();
  for (const BodyParticipation& b : summary.modalParticipation) {
    nlohmann::ordered_json modes = nlohmann::ordered_json::array();
    for (const ModeParticipation& m : b.modes) {
      modes.push_back({{"omega", m.omega}, {"max_amplitude", m.maxAmplitude}, {"max_energy", m.maxEnergy}});
    }
    participation.push_back({{"body", b.body}, {"nodal", b.nodal}, {"carrying", b.carrying}, {"modes", modes}});
  }
  j["modal_participation"] = participation;
  j["formulation"] = toString(s.formulation);
  j["integrator"] = toString(summary.integrator);
  j["integrator_requested"] = toString(s.integrator);
  j["integrator_reason"] = summary.integratorReason;
  j["elastic_start"] = summary.elasticStart.empty() ? nlohmann::ordered_json(nullptr)
                                                    : nlohmann::ordered_json(summary.elasticStart);
  j["integrator_switch"] = summary.integratorSwitch.empty() ? nlohmann::ordered_json(nullptr)
                                                            : nlohmann::ordered_json(summary.integratorSwitch);
  j["linear_solver"] = summary.usedKlu ? "klu" : "dense";
  j["max_order"] = summary.maxOrder;
  j["order_limit"] = summary.orderLimit.empty() ? nlohmann::json() : nlohmann::json(summary.orderLimit);
  j["rtol"] = s.rtol;
  j["atol"] = s.atol;
  j["atol_velocity"] = summary.tolerances.position > 0.0 ? summary.tolerances.velocity
                                                          : s.atolVelocity.value_or(s.atol);
  j["tolerances"] = tolerancesObject(summary);
  j["t_start"] = s.tStart;
  j["t_end"] = s.tEnd;
  j["output_step"] = s.outputStep;
  j["units"] = modelUnits(scene.system);
  return j;
}

}  // namespace

std::string summaryJson(const SimulationSummary& summary, const Scene& scene) {
  return summaryObject(summary, scene).dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
}

void writeSummary(const std::filesystem::path& dir, const SimulationSummary& summary, const Scene& scene,
                  const std::string& sceneFile, const nlohmann::json* sensitivities) {
  nlohmann::ordered_json j = summaryObject(summary, scene);
  if (!sceneFile.empty()) {
    std::error_code ec;
    const std::filesystem::path absolute = std::filesystem::absolute(sceneFile, ec);
    j["scene_file"] = ec ? sceneFile : absolute.lexically_normal().string();
  }
  if (sensitivities) j["sensitivities"] = nlohmann::ordered_json::parse(sensitivities->dump());
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
