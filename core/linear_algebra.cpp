#include "core/linear_algebra.hpp"

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseQR>
#include <cmath>
#include <stdexcept>
#include <algorithm>
#include <cmath>

namespace flexmbd {

namespace {

/// A^T with unit columns (the rows of A scaled to norm 1; zero rows stay zero), sparse.
SpMat unitRowsTransposed(const MatX& A) {
  std::vector<Eigen::Triplet<double>> t;
  for (Eigen::Index i = 0; i < A.rows(); ++i) {
    const double norm = A.row(i).norm();
    if (norm == 0.0) continue;
    for (Eigen::Index j = 0; j < A.cols(); ++j) {
      if (A(i, j) != 0.0) t.emplace_back(j, i, A(i, j) / norm);
    }
  }
  SpMat At(A.cols(), A.rows());
  At.setFromTriplets(t.begin(), t.end());
  return At;
}

}  // namespace

std::vector<int> dependentRows(const MatX& A, double rankTolerance) {
  std::vector<int> dependent;
  if (A.rows() == 0) return dependent;
  // Householder QR of A^T column by column in natural order (Eigen's SparseQR moves a column
  // whose remainder is below the pivot threshold to the end): with unit columns, a row is
  // dependent when its remainder after the earlier rows is below rankTolerance of its norm.
  // Sparse: O(nnz) for a chain, where the dense Gram-Schmidt was O(m^2 n).
  const SpMat At = unitRowsTransposed(A);
  Eigen::SparseQR<SpMat, Eigen::NaturalOrdering<int>> qr;
  qr.setPivotThreshold(rankTolerance);
  qr.compute(At);
  if (qr.info() != Eigen::Success) throw std::runtime_error("dependentRows: the sparse QR factorisation failed");
  const auto& perm = qr.colsPermutation().indices();
  for (Eigen::Index k = qr.rank(); k < perm.size(); ++k) dependent.push_back(perm[k]);
  std::sort(dependent.begin(), dependent.end());
  return dependent;
}

double singularValueRatio(const MatX& A) {
  if (A.rows() == 0) return 1.0;
  if (A.rows() <= kDenseSingularValueRows) {
    const VecX sv = Eigen::JacobiSVD<MatX>(A).singularValues();
    return sv.size() > 0 && sv[0] > 0 ? sv[sv.size() - 1] / sv[0] : 0.0;
  }
  // large: extreme eigenvalues of A A^T (sparse) by power and inverse iteration; the ratio
  // is a diagnosis (thresholds 0.1 and 0.5 of the start's): about 1 % suffices
  SpMat As = A.sparseView();
  const SpMat S = As * As.transpose();
  Eigen::SimplicialLDLT<SpMat> ldlt(S);
  if (ldlt.info() != Eigen::Success) return 0.0;
  const Eigen::Index m = S.rows();
  VecX x = VecX::Ones(m).normalized(), y = x;
  double lambdaMax = 0.0, lambdaMin = 0.0;
  for (int it = 0; it < kSingularValueIterations; ++it) {
    x = (S * x).normalized();
    y = ldlt.solve(y);
    if (!y.allFinite() || y.norm() == 0.0) return 0.0;
    y.normalize();
  }
  lambdaMax = x.dot(S * x);  // Rayleigh quotients
  lambdaMin = y.dot(S * y);
  return lambdaMax > 0.0 && lambdaMin > 0.0 ? std::sqrt(lambdaMin / lambdaMax) : 0.0;
}

MatX withoutRows(const MatX& A, const std::vector<int>& rows) {
  MatX B(A.rows() - static_cast<Eigen::Index>(rows.size()), A.cols());
  size_t k = 0;
  Eigen::Index out = 0;
  for (Eigen::Index i = 0; i < A.rows(); ++i) {
    if (k < rows.size() && rows[k] == i) {
      ++k;
    } else {
      B.row(out++) = A.row(i);
    }
  }
  return B;
}

VecX minimumNormMultipliers(const MatX& G, const VecX& lambda, double rankTolerance) {
  // minimum-norm solution of G^T l = b by a complete orthogonal decomposition (GolubVanLoan2013, sec. 5.5.4)
  Eigen::CompleteOrthogonalDecomposition<MatX> cod;
  cod.setThreshold(rankTolerance);
  cod.compute(G.transpose());
  return cod.solve(G.transpose() * lambda);
}

namespace {

/// C = [C_d C_i] split at the r pivot columns d of a full-pivoting LU, and the
/// eliminated coordinates q_d = X q_i, X = -C_d^{-1} C_i (coordinate partitioning, Haug1989).
struct NullSpaceSplit {
  std::vector<int> pivots, free;
  MatX X;
};

NullSpaceSplit splitAtPivots(const MatX& C) {
  const int r = static_cast<int>(C.rows()), n = static_cast<int>(C.cols());
  const Eigen::FullPivLU<MatX> lu(C);
  NullSpaceSplit s;
  s.pivots.resize(r);
  for (int k = 0; k < r; ++k) s.pivots[k] = lu.permutationQ().indices()[k];
  std::vector<bool> isPivot(n, false);
  for (int p : s.pivots) isPivot[p] = true;
  for (int j = 0; j < n; ++j) {
    if (!isPivot[j]) s.free.push_back(j);
  }
  MatX Cd(r, r), Ci(r, s.free.size());
  for (int k = 0; k < r; ++k) Cd.col(k) = C.col(s.pivots[k]);
  for (size_t k = 0; k < s.free.size(); ++k) Ci.col(k) = C.col(s.free[k]);
  s.X = -Cd.fullPivLu().solve(Ci);  // q_d = X q_i
  return s;
}

}  // namespace

MatX nullSpaceBasis(const MatX& C, std::vector<int>* independent) {
  const NullSpaceSplit s = splitAtPivots(C);
  MatX B = MatX::Zero(C.cols(), s.free.size());
  for (size_t k = 0; k < s.free.size(); ++k) B(s.free[k], k) = 1.0;
  for (size_t k = 0; k < s.pivots.size(); ++k) B.row(s.pivots[k]) = s.X.row(k);
  if (independent) *independent = s.free;
  return B;
}

SpMat sparseNullSpaceBasis(const MatX& C) {
  const NullSpaceSplit s = splitAtPivots(C);
  const MatX& X = s.X;
  const double drop = 1e-14 * (X.size() > 0 ? X.cwiseAbs().maxCoeff() : 0.0);
  std::vector<Eigen::Triplet<double>> t;
  for (size_t k = 0; k < s.free.size(); ++k) t.emplace_back(s.free[k], static_cast<int>(k), 1.0);
  for (size_t k = 0; k < s.pivots.size(); ++k) {
    for (int j = 0; j < X.cols(); ++j) {
      if (std::abs(X(k, j)) > drop) t.emplace_back(s.pivots[k], j, X(k, j));
    }
  }
  SpMat B(C.cols(), static_cast<Eigen::Index>(s.free.size()));
  B.setFromTriplets(t.begin(), t.end());
  return B;
}

}  // namespace flexmbd
