/// @file
/// The rows of a beam model's nodal basis (nodal displacements = basis * q_f) that belong
/// to one element, restricted to the elastic coordinates they depend on, so that element
/// loops stay O(elements) for nodal and reduced bodies alike. Planar (N = 6) and spatial
/// (N = 12) beam models.
#pragma once

#include <Eigen/Sparse>
#include <algorithm>
#include <array>
#include <vector>

namespace flexmbd {

template <int N>
struct ElementBasis {
  std::vector<int> cols;                      ///< elastic coordinates used, ascending
  Eigen::Matrix<double, N, Eigen::Dynamic> B;  ///< rows of the element's nodal coordinates, over cols
};

/// The element basis of the nodal rows `rows` of `basis` (row-major, nodes x q_f).
template <int N>
ElementBasis<N> makeElementBasis(const Eigen::SparseMatrix<double, Eigen::RowMajor>& basis,
                                 const std::array<int, N>& rows) {
  using Basis = Eigen::SparseMatrix<double, Eigen::RowMajor>;
  ElementBasis<N> eb;
  for (int r : rows) {
    for (typename Basis::InnerIterator it(basis, r); it; ++it) eb.cols.push_back(static_cast<int>(it.col()));
  }
  std::sort(eb.cols.begin(), eb.cols.end());
  eb.cols.erase(std::unique(eb.cols.begin(), eb.cols.end()), eb.cols.end());
  eb.B = Eigen::Matrix<double, N, Eigen::Dynamic>::Zero(N, static_cast<Eigen::Index>(eb.cols.size()));
  for (int r = 0; r < N; ++r) {
    for (typename Basis::InnerIterator it(basis, rows[r]); it; ++it) {
      const auto k = std::lower_bound(eb.cols.begin(), eb.cols.end(), static_cast<int>(it.col())) - eb.cols.begin();
      eb.B(r, k) = it.value();
    }
  }
  return eb;
}

}  // namespace flexmbd
