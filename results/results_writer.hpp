/// @file
/// Results of a run: DIR/results.csv, or DIR/results.h5 with --format hdf5 (one row per
/// output time, written as the run goes) and DIR/summary.json (status and statistics,
/// written at the end).
#pragma once

#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "simulation/simulation.hpp"
#include "scene/scene.hpp"
#include "joints/joint_outputs.hpp"

namespace flexmbd {

class Hdf5RowFile;

/// The file format of the results table: results.csv (the default) or results.h5
/// (results/hdf5_results.hpp: /columns, the same names as the CSV header, and /results).
enum class ResultsFormat { Csv, Hdf5 };

/// "csv" or "hdf5". @throws std::invalid_argument naming the value and the known ones.
ResultsFormat parseResultsFormat(const std::string& name);
/// The file name of the results table of `format`: "results.csv" or "results.h5".
const char* resultsFileName(ResultsFormat format);

/// The columns of a scene's results table, in order: t; every coordinate
/// "<body>.<coord>"; every velocity "<body>.<coord>_dot"; every acceleration
/// "<body>.<coord>_ddot"; the reaction outputs (reactionOutputNames); the scene's
/// requested outputs; the spatial joints' outputs (SpatialJointOutputs: "<joint>.angle", ...).
std::vector<std::string> resultColumns(const Scene& scene);
/// The values of one row (resultColumns' order) for a sample, into `values` (cleared);
/// `joints` (made for scene.system) unwraps the joint angles over the rows of a run.
/// @throws NonFiniteResult for a value that is inf or NaN (naming the column and the
///         time), std::runtime_error if the sample has the wrong sizes.
void resultRow(const Scene& scene, const std::vector<std::string>& columns, const OutputSample& sample,
               std::vector<double>& values, SpatialJointOutputs& joints);
/// The same for a single row: joint angles in (-pi, pi], not unwrapped.
void resultRow(const Scene& scene, const std::vector<std::string>& columns, const OutputSample& sample,
               std::vector<double>& values);
/// The run summary as JSON (the keys of writeSummary, in the same order).
std::string summaryJson(const SimulationSummary& summary, const Scene& scene);

/// Writes DIR/results.csv (or DIR/results.h5, see ResultsFormat): a header row, then one
/// row per OutputSample, each flushed so that the rows written survive a failure later in
/// the run. Columns: t; every
/// coordinate "<body>.<coord>" (System::coordinateNames()); every velocity
/// "<body>.<coord>_dot"; every acceleration "<body>.<coord>_ddot" (OutputSample::a, from
/// the state at the output time); the reaction outputs (reactionOutputNames: "<joint>.fx",
/// ".fy", ".m" in world axes, "<driver>.effort"); the scene's requested outputs; the
/// spatial joints' outputs (SpatialJointOutputs, angles unwrapped over the rows written).
/// Numbers are written with 17 significant digits (they read back exactly).
/// The file is created at the first sample, so a run that fails before its first
/// output leaves no results file behind. In HDF5 the numbers are the doubles themselves.
class ResultsWriter {
 public:
  /// Creates `dir` (and parents) and deletes a stale results.csv, results.h5 and
  /// summary.json. `scene` must outlive the writer. @throws std::runtime_error if dir
  /// cannot be made.
  ResultsWriter(const std::filesystem::path& dir, const Scene& scene, ResultsFormat format = ResultsFormat::Csv);
  ~ResultsWriter();
  ResultsWriter(const ResultsWriter&) = delete;
  ResultsWriter& operator=(const ResultsWriter&) = delete;

  /// Appends one row, whole or not at all: a failed write (disk full) is cut back to the
  /// end of the last complete row. @throws NonFiniteResult for a row with inf or NaN,
  /// OutputWriteError (naming the file, the time and the system's reason) if the file
  /// cannot be written, std::runtime_error if the sample has the wrong sizes.
  void write(const OutputSample& sample);
  /// The same with the values of the columns added by addColumns() (in their order).
  /// @throws NonFiniteResult for an added value that is inf or NaN, std::invalid_argument
  /// if `added` does not match the added columns.
  void write(const OutputSample& sample, const std::vector<double>& added);
  /// Adds columns after those of the scene (a sensitivity run's d\<column\>/d\<parameter\>),
  /// before the first row. @throws std::logic_error after it.
  void addColumns(const std::vector<std::string>& names);
  /// The values of the last row written (all columns).
  const std::vector<double>& lastRow() const { return row_; }

  const std::vector<std::string>& columns() const { return columns_; }
  const std::filesystem::path& resultsPath() const { return path_; }
  long rowsWritten() const { return rows_; }
  /// Time of the last row written (NaN if none).
  double lastTime() const { return lastTime_; }

 private:
  void open();

  const Scene& scene_;
  ResultsFormat format_;
  std::filesystem::path path_;
  std::unique_ptr<Hdf5RowFile> h5_;  ///< results.h5, opened at the first row
  std::vector<std::string> columns_;
  std::vector<std::string> sceneColumns_;  ///< resultColumns(scene): the first columns
  std::vector<double> row_;                ///< the last row
  std::unique_ptr<SpatialJointOutputs> joints_;  ///< unwraps the joint angles over the rows
  int fd_ = -1;                ///< results.csv, opened at the first row
  long long bytes_ = 0;        ///< size of results.csv up to its last complete row
  long rows_ = 0;
  double lastTime_;
};

/// A CSV file written row by row, each row whole or not at all: a failed write (disk
/// full, file size limit) is cut back to the end of the last complete row and throws
/// OutputWriteError naming the file, the time and the reason.
class RowFile {
 public:
  RowFile() = default;
  ~RowFile();
  RowFile(const RowFile&) = delete;
  RowFile& operator=(const RowFile&) = delete;
  /// Creates (truncates) `path` and writes `header` (one line, with its newline).
  void open(const std::filesystem::path& path, const std::string& header);
  bool isOpen() const { return fd_ >= 0; }
  /// Appends `row` (with its newline); `t` is the time (or the `variable`) named in an error.
  void append(const std::string& row, double t, const char* variable = "t");
  long rows() const { return rows_; }

 private:
  std::filesystem::path path_;
  int fd_ = -1;
  long long bytes_ = 0;
  long rows_ = 0;
};

/// Deletes DIR/results.csv, DIR/results.h5, DIR/summary.json (and its temporary file) and the frames of
/// DIR/vtk (bodies_NNNNNN.vtu, bodies.pvd) if they exist, stale from an earlier run (which
/// may have been of another model); the directories and any other file are kept.
void removeStaleResults(const std::filesystem::path& dir);

/// Writes DIR/summary.json with status "running", padded to kSummaryReserve bytes: the
/// final summary then overwrites space already held, and is written even if the disk fills
/// during the run. A run killed outright leaves this summary (status "running").
void reserveSummary(const std::filesystem::path& dir);
constexpr std::size_t kSummaryReserve = 4096;  // a summary is about 1 KB

/// Writes `text` as DIR/summary.json: to a temporary file renamed over it (atomic); if that
/// fails (disk full), over the reserved summary in place. Never leaves the temporary file.
/// @throws OutputWriteError naming the file and the reason.
void writeSummaryText(const std::filesystem::path& dir, const std::string& text);

/// Writes DIR/summary.json: status ("ok"/"failed"), message, t_reached, steps,
/// residual_evals, jacobian_evals, nonlinear_iterations, nonlinear_conv_failures,
/// error_test_failures, linear_setups, last_step_size, initial_position_iterations,
/// cpu_seconds, max_position_violation, max_velocity_violation, energy_start and
/// energy_end (null when absent), formulation, linear_solver ("dense"/"klu"), rtol,
/// atol, atol_velocity (the one used), tolerances (per class and the model scales of
/// their defaults, SimulationSummary::tolerances and SimulationSummary::scales; null if the run failed
/// before it started), t_start, t_end, output_step, scene (the scene name), and
/// scene_file (the absolute path of the scene file, when `sceneFile` is given: `flexmbd
/// view` reads the scene from it).
/// Creates `dir` if needed; the file is replaced atomically (written beside, renamed).
/// `sensitivities` (a sensitivity run, results/sensitivity_results.hpp): written as the key
/// "sensitivities" after the others.
void writeSummary(const std::filesystem::path& dir, const SimulationSummary& summary, const Scene& scene,
                  const std::string& sceneFile = "", const nlohmann::json* sensitivities = nullptr);

/// Writes DIR/summary.json for a run that stopped on an input or model error before
/// integrating: {"status": "failed", "message": ..., "error": "input"}.
void writeInputErrorSummary(const std::filesystem::path& dir, const std::string& message);

}  // namespace flexmbd
