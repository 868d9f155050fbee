/// @file
/// Results as HDF5 (flexmbd run --format hdf5): DIR/results.h5 with
///   /columns  1-D dataset of variable-length UTF-8 strings: the column names, in order,
///             the same as the header of results.csv;
///   /results  2-D dataset of float64, rows x columns, chunked and extendible: one row per
///             output time, appended as the run goes.
/// The HDF5 C API stays in hdf5_results.cpp (a private dependency of the library).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "results/results_table.hpp"

namespace flexmbd {

/// An HDF5 table written row by row, each row whole or not at all, the file flushed after
/// every row, so a run killed or failing later keeps the rows written.
///
/// A full disk or a file size limit: HDF5 1.10 leaves a file whose write failed unreadable
/// (its metadata then points past the end of the file) and crashes at exit closing it. So
/// before each row the writer reserves the space HDF5 may need for it (posix_fallocate of
/// two chunks and 256 KiB past the end of HDF5's allocated space; the file is cut back to
/// that space when it is closed):
/// when that fails the row is not written, the file stays as it was (every complete row
/// readable) and OutputWriteError names the file, the time and the system's reason. A
/// failure HDF5 meets anyway (a file system without fallocate) is reported the same way,
/// with HDF5's reason.
class Hdf5RowFile {
 public:
  Hdf5RowFile() = default;
  ~Hdf5RowFile();
  Hdf5RowFile(const Hdf5RowFile&) = delete;
  Hdf5RowFile& operator=(const Hdf5RowFile&) = delete;

  /// Creates (truncates) `path` with /columns and an empty /results of columns.size()
  /// columns. @throws OutputWriteError naming the file and the reason.
  void open(const std::filesystem::path& path, const std::vector<std::string>& columns);
  bool isOpen() const { return file_ >= 0; }
  /// Appends one row of columns.size() values; `t` is the time named in an error.
  void append(const std::vector<double>& row, double t);
  long rows() const { return rows_; }
  /// Closes the file (also done by the destructor). @throws OutputWriteError on failure.
  void close();

 private:
  std::filesystem::path path_;
  std::int64_t file_ = -1;     ///< hid_t of the file
  std::int64_t dataset_ = -1;  ///< hid_t of /results
  std::size_t columns_ = 0;
  long rows_ = 0;
  int reserveFd_ = -1;         ///< the file again, to reserve space before each row
  long long reserveBytes_ = 0;  ///< bytes reserved past the end of the file
};

/// Reads /columns and /results of a file Hdf5RowFile wrote.
/// @throws InputError naming the file and what is missing or malformed.
ResultsTable readHdf5Results(const std::filesystem::path& path);

}  // namespace flexmbd
