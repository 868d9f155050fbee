#include "results/results_table.hpp"

#include <cstdlib>
#include <fstream>
#include <sstream>

#include "core/errors.hpp"
#include "results/hdf5_results.hpp"

namespace flexmbd {

int ResultsTable::column(const std::string& name) const {
  for (std::size_t k = 0; k < columns.size(); ++k) {
    if (columns[k] == name) return static_cast<int>(k);
  }
  return -1;
}

ResultsTable readCsvTable(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError("cannot read '" + path.string() + "'");
  ResultsTable t;
  std::string line;
  if (!std::getline(in, line)) throw InputError("'" + path.string() + "' is empty (no header line)");
  std::stringstream header(line);
  for (std::string c; std::getline(header, c, ',');) t.columns.push_back(c);
  for (long number = 2; std::getline(in, line); ++number) {
    if (line.empty()) continue;
    std::vector<double> row;
    const char* p = line.c_str();
    while (true) {
      char* end = nullptr;
      row.push_back(std::strtod(p, &end));  // "nan", "inf" included
      if (end == p) {
        throw InputError("'" + path.string() + "' line " + std::to_string(number) + ", column " +
                         std::to_string(row.size()) + ": not a number");
      }
      p = end;
      if (*p == '\0') break;
      if (*p != ',') {
        throw InputError("'" + path.string() + "' line " + std::to_string(number) + ": expected ',' after column " +
                         std::to_string(row.size()));
      }
      ++p;
    }
    if (row.size() != t.columns.size()) {
      // a run killed while writing leaves a cut last line: the rows before it are kept
      if (in.peek() == std::char_traits<char>::eof()) break;
      throw InputError("'" + path.string() + "' line " + std::to_string(number) + ": " +
                       std::to_string(row.size()) + " values, the header names " + std::to_string(t.columns.size()));
    }
    t.rows.push_back(std::move(row));
  }
  return t;
}

ResultsTable readResults(const std::filesystem::path& dir) {
  std::error_code ec;
  if (std::filesystem::exists(dir / "results.csv", ec)) return readCsvTable(dir / "results.csv");
  if (std::filesystem::exists(dir / "results.h5", ec)) return readHdf5Results(dir / "results.h5");
  throw InputError("'" + dir.string() + "' holds no results.csv or results.h5 (the folder of a flexmbd run)");
}

}  // namespace flexmbd
