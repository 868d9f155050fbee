#include "core/linear_algebra.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace flexmbd {

std::vector<int> dependentRows(const MatX& A, double rankTolerance) {
  std::vector<int> dependent;
  std::vector<VecX> basis;
  for (int i = 0; i < A.rows(); ++i) {
    VecX r = A.row(i).transpose();
    const double norm0 = r.norm();
    for (const VecX& b : basis) r -= b.dot(r) * b;
    const double rn = r.norm();
    if (norm0 == 0.0 || rn <= rankTolerance * norm0) {
      dependent.push_back(i);
    } else {
      basis.push_back(r / rn);
    }
  }
  return dependent;
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
  // minimum-norm solution of G^T l = b by a complete orthogonal decomposition (Golub & Van Loan, 4th ed., 5.5.4)
  Eigen::CompleteOrthogonalDecomposition<MatX> cod;
  cod.setThreshold(rankTolerance);
  cod.compute(G.transpose());
  return cod.solve(G.transpose() * lambda);
}

namespace {

/// C = [C_d C_i] split at the r pivot columns d of a full-pivoting LU, and the
/// eliminated coordinates q_d = X q_i, X = -C_d^{-1} C_i.
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
