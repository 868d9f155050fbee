#include "core/linear_algebra.hpp"

#include <Eigen/Dense>
#include <algorithm>

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

MatX nullSpaceBasis(const MatX& C, std::vector<int>* independent) {
  const int r = static_cast<int>(C.rows()), n = static_cast<int>(C.cols());
  const Eigen::FullPivLU<MatX> lu(C);
  std::vector<int> pivots(r), free;
  for (int k = 0; k < r; ++k) pivots[k] = lu.permutationQ().indices()[k];
  std::vector<bool> isPivot(n, false);
  for (int p : pivots) isPivot[p] = true;
  for (int j = 0; j < n; ++j) {
    if (!isPivot[j]) free.push_back(j);
  }
  MatX Cd(r, r), Ci(r, free.size());
  for (int k = 0; k < r; ++k) Cd.col(k) = C.col(pivots[k]);
  for (size_t k = 0; k < free.size(); ++k) Ci.col(k) = C.col(free[k]);
  const MatX X = -Cd.fullPivLu().solve(Ci);  // q_d = X q_i
  MatX B = MatX::Zero(n, free.size());
  for (size_t k = 0; k < free.size(); ++k) B(free[k], k) = 1.0;
  for (int k = 0; k < r; ++k) B.row(pivots[k]) = X.row(k);
  if (independent) *independent = free;
  return B;
}

}  // namespace flexmbd
