#include "core/sparse_pattern.hpp"

#include <stdexcept>
#include <string>

namespace flexmbd {

SparsePattern::SparsePattern(int n, std::vector<std::pair<int, int>> entries) : n_(n) {
  // sort by (col, row) and merge duplicates
  std::sort(entries.begin(), entries.end(), [](const auto& a, const auto& b) {
    return a.second != b.second ? a.second < b.second : a.first < b.first;
  });
  entries.erase(std::unique(entries.begin(), entries.end()), entries.end());
  colStart_.assign(n + 1, 0);
  rowIndex_.reserve(entries.size());
  for (const auto& [r, c] : entries) {
    if (r < 0 || r >= n || c < 0 || c >= n) throw std::logic_error("SparsePattern: entry out of range");
    ++colStart_[c + 1];
    rowIndex_.push_back(r);
  }
  for (int c = 0; c < n; ++c) colStart_[c + 1] += colStart_[c];
}

void JacobianSink::throwOutsidePattern(int row, int col) {
  throw std::logic_error("Jacobian entry (" + std::to_string(row) + ", " + std::to_string(col) +
                         ") is outside the sparse pattern built at finalize");
}

}  // namespace flexmbd
