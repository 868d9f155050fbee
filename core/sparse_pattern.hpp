// Compressed-sparse-column pattern of the DAE Jacobian, built once after finalize,
// and the sink the assembly writes entries into (dense or sparse storage).
#pragma once

#include <Eigen/SparseCore>
#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

namespace flexmbd {

/// Square CSC pattern: column c holds rows rowIndex[colStart[c] .. colStart[c+1]).
class SparsePattern {
 public:
  SparsePattern() = default;
  /// From (row, col) pairs; duplicates are merged.
  SparsePattern(int n, std::vector<std::pair<int, int>> entries);
  int size() const { return n_; }
  int64_t nonZeros() const { return static_cast<int64_t>(rowIndex_.size()); }
  const std::vector<int64_t>& colStart() const { return colStart_; }
  const std::vector<int64_t>& rowIndex() const { return rowIndex_; }
  /// Position of (row, col) in the value array, or -1 if it is not in the pattern.
  int64_t find(int row, int col) const {
    const auto b = rowIndex_.begin() + colStart_[col], e = rowIndex_.begin() + colStart_[col + 1];
    const auto it = std::lower_bound(b, e, static_cast<int64_t>(row));
    return (it != e && *it == row) ? static_cast<int64_t>(it - rowIndex_.begin()) : -1;
  }

 private:
  int n_ = 0;
  std::vector<int64_t> colStart_, rowIndex_;
};

/// Where Jacobian entries go: accumulated into a column-major dense array (leading
/// dimension n), or into the value array of a SparsePattern.
class JacobianSink {
 public:
  static JacobianSink dense(double* data, int n) { return JacobianSink(data, n, nullptr); }
  static JacobianSink sparse(double* values, const SparsePattern& p) {
    return JacobianSink(values, p.size(), &p);
  }
  /// Records the entries written with their values (duplicates kept): to build the
  /// pattern, or a sparse matrix by setFromTriplets (which sums duplicates).
  static JacobianSink recorder(std::vector<Eigen::Triplet<double>>* entries) {
    JacobianSink s(nullptr, 0, nullptr);
    s.entries_ = entries;
    return s;
  }
  /// J(row, col) += value. @throws std::logic_error if (row, col) is outside a sparse
  /// pattern (an assembly bug, never a user error).
  void add(int row, int col, double value) {
    if (entries_) {
      entries_->emplace_back(row, col, value);
      return;
    }
    if (!pattern_) {
      data_[static_cast<int64_t>(col) * n_ + row] += value;
      return;
    }
    const int64_t k = pattern_->find(row, col);
    if (k < 0) throwOutsidePattern(row, col);
    data_[k] += value;
  }
  /// J(row0 + k, col) += s * value(k) for k < n: a column segment computed on the fly
  /// (one merge walk down the column in a sparse pattern).
  template <class Fn>
  void addColumnSegment(int col, int row0, int n, Fn&& value, double s) {
    if (entries_ || !pattern_) {
      for (int k = 0; k < n; ++k) add(row0 + k, col, s * value(k));
      return;
    }
    const auto& ri = pattern_->rowIndex();
    int64_t p = pattern_->colStart()[col];
    const int64_t end = pattern_->colStart()[col + 1];
    for (int k = 0; k < n; ++k) {
      const int r = row0 + k;
      while (p < end && ri[p] < r) ++p;
      if (p == end || ri[p] != r) throwOutsidePattern(r, col);
      data_[p] += s * value(k);
    }
  }
  /// J(row0 + rows[k], col) += s * values[k], k < n, rows ascending (rows null: rows
  /// 0..n-1). In a sparse pattern one merge walk down the column replaces n searches.
  void addColumn(int col, int row0, const int* rows, const double* values, int n, double s) {
    auto rowOf = [&](int k) { return row0 + (rows ? rows[k] : k); };
    if (entries_ || !pattern_) {
      for (int k = 0; k < n; ++k) add(rowOf(k), col, s * values[k]);
      return;
    }
    const auto& ri = pattern_->rowIndex();
    int64_t p = pattern_->colStart()[col];
    const int64_t end = pattern_->colStart()[col + 1];
    for (int k = 0; k < n; ++k) {
      const int r = rowOf(k);
      while (p < end && ri[p] < r) ++p;
      if (p == end || ri[p] != r) throwOutsidePattern(r, col);
      data_[p] += s * values[k];
    }
  }

 private:
  JacobianSink(double* d, int n, const SparsePattern* p) : data_(d), n_(n), pattern_(p) {}
  [[noreturn]] static void throwOutsidePattern(int row, int col);
  double* data_;
  int n_;
  const SparsePattern* pattern_;
  std::vector<Eigen::Triplet<double>>* entries_ = nullptr;
};

}  // namespace flexmbd
