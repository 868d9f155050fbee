/// @file
/// Small dense linear-algebra helpers shared by the model set-up and the integrators.
#pragma once

#include <vector>

#include "core/types.hpp"

namespace flexmbd {

/// out[k] = x[cols[k]]: the entries of a global vector a component uses (resizes out;
/// allocates only when it grows).
inline void gather(const std::vector<int>& cols, const double* x, VecX& out) {
  out.resize(static_cast<Eigen::Index>(cols.size()));
  for (std::size_t k = 0; k < cols.size(); ++k) out[k] = x[cols[k]];
}

/// Indices of the rows of A that are linearly dependent on earlier rows (orthogonalisation in
/// row order by a sparse QR of A^T; a row whose remainder is below rankTolerance times its
/// own norm is dependent). Reports the later of two conflicting rows, so errors can
/// name the constraint the user added last.
std::vector<int> dependentRows(const MatX& A, double rankTolerance = 1e-9);

/// Rows up to which singularValueRatio takes the dense SVD (exact, O(m^2 n)): 300 rows
/// (150 revolute joints) factor in about 0.1 s; the 800-link chain (1,600 rows) took 60 s.
constexpr Eigen::Index kDenseSingularValueRows = 300;
/// Power and inverse iterations of singularValueRatio above kDenseSingularValueRows.
constexpr int kSingularValueIterations = 100;

/// Smallest over largest singular value of A (m x n, m <= n; 1 for m = 0, 0 if rank-deficient):
/// the dense SVD up to kDenseSingularValueRows rows, above it the square roots of the extreme
/// eigenvalues of A A^T (sparse Cholesky; inverse and power iteration, to about 1 %).
double singularValueRatio(const MatX& A);

/// A without the rows listed in `rows` (ascending): the independent rows of a constraint
/// Jacobian whose dependent rows are released.
MatX withoutRows(const MatX& A, const std::vector<int>& rows);

/// The minimum-norm multipliers of the full set G (m x n) with the same resultant as
/// lambda: argmin |l| subject to G^T l = G^T lambda (a redundant set's reactions are not
/// unique; this choice spreads the load evenly over the dependent rows). Rows of G whose
/// pivots fall below rankTolerance times the largest count as dependent, as in dependentRows.
/// Solved by a complete orthogonal decomposition (GolubVanLoan2013, sec. 5.5.4).
VecX minimumNormMultipliers(const MatX& G, const VecX& lambda, double rankTolerance = 1e-9);

/// Basis B of the null space of the full-row-rank matrix C (r x n), chosen so that
/// B keeps as many unit columns as possible: C = [C_d C_i] (d: r pivot columns of
/// a full-pivoting LU), q_d = -C_d^{-1} C_i q_i, B = P [-C_d^{-1} C_i; I] (coordinate
/// partitioning, Haug1989).
/// `independent` receives the kept coordinates (the columns of B are unit vectors there).
MatX nullSpaceBasis(const MatX& C, std::vector<int>* independent = nullptr);
/// The same basis, sparse, built without the dense n x (n - r) matrix (cost O(r^2 n)):
/// n - r unit columns and the r eliminated rows, entries below 1e-14 max |C_d^{-1} C_i|
/// dropped (the beam models' B2, bodies/ffr_beam_model.cpp).
SpMat sparseNullSpaceBasis(const MatX& C);

}  // namespace flexmbd
