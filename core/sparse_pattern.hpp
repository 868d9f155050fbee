/// @file
/// Compressed-sparse-column pattern of the DAE Jacobian, built once after finalize,
/// and the sink the assembly writes entries into (dense or sparse storage).
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

/// Where each entry an assembly writes goes in a sparse pattern's value array, in the
/// order the entries are written, each with its (row, col) to check against: kept in an
/// evaluator's scratch (DaeScratch), filled by its first assembly into a pattern and
/// replayed by the next ones (JacobianSink::withPositions), so that an assembly into a
/// fixed pattern searches the pattern once per run instead of once per entry.
class JacobianPositions {
 public:
  /// Forgets the recorded order (the next assembly records it again).
  void clear() {
    pattern_ = nullptr;
    key_.clear();
    position_.clear();
  }

 private:
  friend class JacobianSink;
  static int64_t key(int row, int col) { return (static_cast<int64_t>(col) << 32) | static_cast<uint32_t>(row); }
  const SparsePattern* pattern_ = nullptr;  ///< the pattern the positions index
  std::vector<int64_t> key_;                ///< (col, row) of the k-th entry written
  std::vector<int64_t> position_;           ///< its position in the value array
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
  /// The pattern of a sparse sink (null otherwise).
  const SparsePattern* pattern() const { return entries_ ? nullptr : pattern_; }
  /// The same sink, which for a sparse pattern takes the positions of the entries from
  /// `positions` in the order they were written by the previous assembly with it, and
  /// records them where they are not known yet or the order differs (every entry's (row,
  /// col) is checked: a different order costs searches, never a wrong entry). Dense sinks
  /// and recorders are returned as they are.
  JacobianSink withPositions(JacobianPositions& positions) const {
    JacobianSink s = *this;
    if (!pattern_ || entries_) return s;
    if (positions.pattern_ != pattern_) {
      positions.clear();
      positions.pattern_ = pattern_;
    }
    s.positions_ = &positions;
    s.next_ = 0;
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
    if (positions_) {
      data_[position(row, col)] += value;
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
    if (positions_) {
      for (int k = 0; k < n; ++k) data_[position(row0 + k, col)] += s * value(k);
      return;
    }
    const auto& ri = pattern_->rowIndex();
    const int64_t end = pattern_->colStart()[col + 1];
    int64_t p = firstAtOrBelow(col, row0, end);
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
    if (positions_) {
      // the recorded positions, read through local pointers (which the stores into data_
      // cannot alias) while the entries are the ones recorded; from a difference on, searched
      const JacobianPositions& P = *positions_;
      int k = 0;
      if (next_ + static_cast<size_t>(n) <= P.key_.size()) {
        const int64_t* key = P.key_.data() + next_;
        const int64_t* pos = P.position_.data() + next_;
        while (k < n && key[k] == JacobianPositions::key(rowOf(k), col)) {
          data_[pos[k]] += s * values[k];
          ++k;
        }
        next_ += static_cast<size_t>(k);
      }
      for (; k < n; ++k) data_[position(rowOf(k), col)] += s * values[k];
      return;
    }
    const auto& ri = pattern_->rowIndex();
    const int64_t end = pattern_->colStart()[col + 1];
    int64_t p = n > 0 ? firstAtOrBelow(col, rowOf(0), end) : end;
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
  /// Position of the first row >= `row` in column `col` (end: its end): where a merge walk
  /// down the column starts. A binary search, so that a block far down a long column (the
  /// constraint rows of a coordinate's column) costs no walk over the rows above it.
  int64_t firstAtOrBelow(int col, int row, int64_t end) const {
    const auto& ri = pattern_->rowIndex();
    return std::lower_bound(ri.begin() + pattern_->colStart()[col], ri.begin() + end, static_cast<int64_t>(row)) -
           ri.begin();
  }
  /// The position of the next entry written, (row, col): replayed if it is the entry
  /// written at this point last time, else searched and recorded from here on.
  int64_t position(int row, int col) {
    JacobianPositions& P = *positions_;
    const int64_t key = JacobianPositions::key(row, col);
    if (next_ < P.key_.size() && P.key_[next_] == key) return P.position_[next_++];
    const int64_t k = pattern_->find(row, col);
    if (k < 0) throwOutsidePattern(row, col);
    P.key_.resize(next_);  // a different order: what was recorded after this point is stale
    P.position_.resize(next_);
    P.key_.push_back(key);
    P.position_.push_back(k);
    ++next_;
    return k;
  }
  double* data_;
  int n_;
  const SparsePattern* pattern_;
  std::vector<Eigen::Triplet<double>>* entries_ = nullptr;
  JacobianPositions* positions_ = nullptr;  ///< see withPositions
  size_t next_ = 0;                         ///< the next entry's index in *positions_
};

}  // namespace flexmbd
