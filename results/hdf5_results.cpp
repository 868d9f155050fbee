#include "results/hdf5_results.hpp"

#include <fcntl.h>
#include <hdf5.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <type_traits>

#include "core/errors.hpp"

#include "simulation/simulation.hpp"

namespace flexmbd {

static_assert(std::is_same_v<hid_t, std::int64_t>, "Hdf5RowFile stores hid_t as std::int64_t");

namespace {

/// HDF5 prints its error stack to stderr by default; the writer reports errors itself.
/// Turned off while an HDF5 call of the writer runs, restored after (RAII).
class QuietHdf5Errors {
 public:
  QuietHdf5Errors() {
    H5Eget_auto2(H5E_DEFAULT, &func_, &data_);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  ~QuietHdf5Errors() { H5Eset_auto2(H5E_DEFAULT, func_, data_); }
  QuietHdf5Errors(const QuietHdf5Errors&) = delete;
  QuietHdf5Errors& operator=(const QuietHdf5Errors&) = delete;

 private:
  H5E_auto2_t func_ = nullptr;
  void* data_ = nullptr;
};

/// The message of HDF5's current error stack that carries the system's reason ("...
/// errno = 28, error message = 'No space left on device'"), else the innermost non-empty
/// one (where the failure was detected), or "HDF5 error" if there is none.
std::string hdf5Reason() {
  std::vector<std::string> messages;  // innermost first
  H5Ewalk2(
      H5E_DEFAULT, H5E_WALK_UPWARD,
      [](unsigned, const H5E_error2_t* e, void* out) -> herr_t {
        if (e->desc && *e->desc) static_cast<std::vector<std::string>*>(out)->push_back(e->desc);
        return 0;
      },
      &messages);
  H5Eclear2(H5E_DEFAULT);
  for (const auto& m : messages) {
    if (m.find("errno") != std::string::npos) return m;
  }
  return messages.empty() ? "HDF5 error" : messages.front();
}

/// Reserves the bytes [from, from + bytes) of the file open as `fd` (a no-op where the file
/// already has them): 0, or the error (ENOSPC: disk full, EFBIG: file size limit). A file
/// system that cannot reserve counts as success.
int reserve(int fd, long long from, long long bytes) {
  const int err = ::posix_fallocate(fd, static_cast<off_t>(from), static_cast<off_t>(bytes));
  return err == EOPNOTSUPP || err == EINVAL ? 0 : err;
}

std::string timeText(double t) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", t);
  return buf;
}

/// Closes an identifier when it goes out of scope (datatypes, dataspaces, property lists).
struct Id {
  hid_t id;
  herr_t (*closer)(hid_t);
  ~Id() {
    if (id >= 0) closer(id);
  }
};

}  // namespace

Hdf5RowFile::~Hdf5RowFile() {
  try {
    close();
  } catch (...) {
  }
}

void Hdf5RowFile::close() {
  QuietHdf5Errors quiet;
  bool ok = true;
  haddr_t end = 0;  // HDF5's end of allocated space, once all is written
  if (dataset_ >= 0) ok = H5Dclose(dataset_) >= 0 && ok;
  if (file_ >= 0) {
    ok = H5Fflush(file_, H5F_SCOPE_LOCAL) >= 0 && H5Fget_eoa(file_, &end) >= 0 && ok;
    ok = H5Fclose(file_) >= 0 && ok;
  }
  dataset_ = file_ = -1;
  // The space reserved past the end (append) is given back.
  if (reserveFd_ >= 0) {
    struct stat st {};
    if (ok && end > 0 && ::fstat(reserveFd_, &st) == 0 && static_cast<haddr_t>(st.st_size) > end) {
      if (::ftruncate(reserveFd_, static_cast<off_t>(end)) != 0) ok = false;
    }
    ::close(reserveFd_);
    reserveFd_ = -1;
  }
  if (!ok) throw OutputWriteError("cannot close '" + path_.string() + "': " + hdf5Reason());
}

void Hdf5RowFile::open(const std::filesystem::path& path, const std::vector<std::string>& columns) {
  QuietHdf5Errors quiet;
  path_ = path;
  columns_ = columns.size();
  rows_ = 0;
  // Chunks of about 64 KiB (at least a row); the space reserved before each row: room for
  // a new chunk and the metadata HDF5 may grow with it (index nodes, object header).
  const hsize_t chunkRows = std::clamp<hsize_t>(65536 / (8 * std::max<std::size_t>(columns_, 1)), 1, 1024);
  reserveBytes_ = 2 * static_cast<long long>(chunkRows * 8 * std::max<std::size_t>(columns_, 1)) + 256 * 1024;
  // The space for the empty file, checked before HDF5 writes it (HDF5 truncates it again).
  reserveFd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (reserveFd_ < 0) throw OutputWriteError("cannot create '" + path.string() + "': " + std::strerror(errno));
  if (const int err = reserve(reserveFd_, 0, reserveBytes_)) {
    ::close(reserveFd_);
    reserveFd_ = -1;
    std::filesystem::remove(path);
    throw OutputWriteError("cannot create '" + path.string() + "': " + std::strerror(err));
  }
  const auto fail = [&](const std::string& what) {
    const std::string reason = hdf5Reason();
    ::close(reserveFd_);
    reserveFd_ = -1;
    if (dataset_ >= 0) H5Dclose(dataset_);
    if (file_ >= 0) H5Fclose(file_);
    dataset_ = file_ = -1;
    std::error_code ec;
    std::filesystem::remove(path_, ec);  // no results file rather than a damaged one
    throw OutputWriteError("cannot " + what + " '" + path_.string() + "': " + reason);
  };
  file_ = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (file_ < 0) fail("create");

  // /columns: the names, variable-length UTF-8 strings.
  {
    std::vector<const char*> names;
    for (const auto& c : columns) names.push_back(c.c_str());
    const Id type{H5Tcopy(H5T_C_S1), H5Tclose};
    const hsize_t n = columns.size();
    const Id space{H5Screate_simple(1, &n, nullptr), H5Sclose};
    if (type.id < 0 || H5Tset_size(type.id, H5T_VARIABLE) < 0 || H5Tset_cset(type.id, H5T_CSET_UTF8) < 0 ||
        space.id < 0) {
      fail("write the column names of");
    }
    const Id names_ds{H5Dcreate2(file_, "columns", type.id, space.id, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                      H5Dclose};
    if (names_ds.id < 0 || H5Dwrite(names_ds.id, type.id, H5S_ALL, H5S_ALL, H5P_DEFAULT, names.data()) < 0) {
      fail("write the column names of");
    }
  }

  // /results: rows x columns, extendible in rows, chunks of about 64 KiB (at least a row).
  const hsize_t dims[2] = {0, static_cast<hsize_t>(columns_)};
  const hsize_t maxDims[2] = {H5S_UNLIMITED, static_cast<hsize_t>(columns_)};
  const hsize_t chunk[2] = {chunkRows, std::max<hsize_t>(columns_, 1)};
  const Id space{H5Screate_simple(2, dims, maxDims), H5Sclose};
  const Id props{H5Pcreate(H5P_DATASET_CREATE), H5Pclose};
  if (space.id < 0 || props.id < 0 || H5Pset_chunk(props.id, 2, chunk) < 0) fail("create the results table of");
  dataset_ = H5Dcreate2(file_, "results", H5T_IEEE_F64LE, space.id, H5P_DEFAULT, props.id, H5P_DEFAULT);
  if (dataset_ < 0) fail("create the results table of");
  if (H5Fflush(file_, H5F_SCOPE_LOCAL) < 0) fail("write");
}

void Hdf5RowFile::append(const std::vector<double>& row, double t) {
  if (row.size() != columns_) {
    throw std::runtime_error("results writer: a row of " + std::to_string(row.size()) + " values for " +
                             std::to_string(columns_) + " columns of '" + path_.string() + "'");
  }
  QuietHdf5Errors quiet;
  // Past the end of the space HDF5 has allocated (its end of address space; HDF5 cuts the
  // file back to it when it closes the file).
  haddr_t end = 0;
  if (H5Fget_eoa(file_, &end) < 0) end = 0;
  if (const int err = reserve(reserveFd_, static_cast<long long>(end), reserveBytes_)) {
    throw OutputWriteError("cannot write '" + path_.string() + "' at t = " + timeText(t) + ": " +
                           std::strerror(err) + " (" + std::to_string(rows_) + " complete rows kept)");
  }
  const hsize_t grown[2] = {static_cast<hsize_t>(rows_) + 1, static_cast<hsize_t>(columns_)};
  const hsize_t start[2] = {static_cast<hsize_t>(rows_), 0};
  const hsize_t count[2] = {1, static_cast<hsize_t>(columns_)};
  bool ok = H5Dset_extent(dataset_, grown) >= 0;
  if (ok) {
    const Id fileSpace{H5Dget_space(dataset_), H5Sclose};
    const Id memSpace{H5Screate_simple(2, count, nullptr), H5Sclose};
    ok = fileSpace.id >= 0 && memSpace.id >= 0 &&
         H5Sselect_hyperslab(fileSpace.id, H5S_SELECT_SET, start, nullptr, count, nullptr) >= 0 &&
         H5Dwrite(dataset_, H5T_NATIVE_DOUBLE, memSpace.id, fileSpace.id, H5P_DEFAULT, row.data()) >= 0 &&
         H5Fflush(file_, H5F_SCOPE_LOCAL) >= 0;
  }
  if (!ok) {
    const std::string reason = hdf5Reason();
    // Back to the complete rows (best effort: the disk may refuse this too).
    const hsize_t kept[2] = {static_cast<hsize_t>(rows_), static_cast<hsize_t>(columns_)};
    if (H5Dset_extent(dataset_, kept) >= 0) H5Fflush(file_, H5F_SCOPE_LOCAL);
    H5Eclear2(H5E_DEFAULT);
    throw OutputWriteError("cannot write '" + path_.string() + "' at t = " + timeText(t) + ": " + reason + " (" +
                           std::to_string(rows_) + " complete rows kept)");
  }
  ++rows_;
}

// ----- reading results back ----------------------------------------------------------------

ResultsTable readHdf5Results(const std::filesystem::path& path) {
  QuietHdf5Errors quiet;
  const std::string where = "'" + path.string() + "'";
  const Id file{H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose};
  if (file.id < 0) throw InputError(where + ": not an HDF5 file that can be read (" + hdf5Reason() + ")");
  ResultsTable t;
  {
    const Id ds{H5Dopen2(file.id, "columns", H5P_DEFAULT), H5Dclose};
    const Id space{ds.id >= 0 ? H5Dget_space(ds.id) : -1, H5Sclose};
    if (ds.id < 0 || space.id < 0 || H5Sget_simple_extent_ndims(space.id) != 1) {
      throw InputError(where + ": no 1-D dataset /columns (the column names flexmbd run --format hdf5 writes)");
    }
    hsize_t n = 0;
    H5Sget_simple_extent_dims(space.id, &n, nullptr);
    const Id type{H5Tcopy(H5T_C_S1), H5Tclose};
    H5Tset_size(type.id, H5T_VARIABLE);
    H5Tset_cset(type.id, H5T_CSET_UTF8);
    std::vector<char*> names(n, nullptr);
    if (n > 0 && H5Dread(ds.id, type.id, H5S_ALL, H5S_ALL, H5P_DEFAULT, names.data()) < 0) {
      throw InputError(where + ": /columns is not a dataset of strings");
    }
    for (char* c : names) t.columns.push_back(c ? c : "");
    if (n > 0) H5Dvlen_reclaim(type.id, space.id, H5P_DEFAULT, names.data());
  }
  const Id ds{H5Dopen2(file.id, "results", H5P_DEFAULT), H5Dclose};
  const Id space{ds.id >= 0 ? H5Dget_space(ds.id) : -1, H5Sclose};
  if (ds.id < 0 || space.id < 0 || H5Sget_simple_extent_ndims(space.id) != 2) {
    throw InputError(where + ": no 2-D dataset /results (rows x columns)");
  }
  hsize_t dims[2] = {0, 0};
  H5Sget_simple_extent_dims(space.id, dims, nullptr);
  if (dims[1] != t.columns.size()) {
    throw InputError(where + ": /results has " + std::to_string(dims[1]) + " columns, /columns names " +
                     std::to_string(t.columns.size()));
  }
  std::vector<double> all(dims[0] * dims[1]);
  if (!all.empty() && H5Dread(ds.id, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, all.data()) < 0) {
    throw InputError(where + ": /results cannot be read (" + hdf5Reason() + ")");
  }
  for (hsize_t r = 0; r < dims[0]; ++r) t.rows.emplace_back(all.begin() + r * dims[1], all.begin() + (r + 1) * dims[1]);
  return t;
}

}  // namespace flexmbd
