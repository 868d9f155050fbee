/// @file
/// A run's results read back (results.csv or results.h5 of `flexmbd run`): the viewer and
/// other commands that work on a finished run.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace flexmbd {

/// A results file read back whole: its column names and rows.
struct ResultsTable {
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;
  /// The index of a column, or -1.
  int column(const std::string& name) const;
};

/// Reads a CSV file of a header line and rows of numbers ("nan", "inf" included).
/// @throws InputError naming the file, the line and what was wrong.
ResultsTable readCsvTable(const std::filesystem::path& path);

/// Reads DIR/results.csv (or DIR/results.h5, results/hdf5_results.hpp, when there is no
/// results.csv). A cut last line (a run killed while writing) is left out.
/// @throws InputError naming the file, the line and what was wrong.
ResultsTable readResults(const std::filesystem::path& dir);

}  // namespace flexmbd
