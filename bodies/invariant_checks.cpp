#include "bodies/invariant_checks.hpp"

#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>

#include "core/errors.hpp"

namespace flexmbd::invariantchecks {

void requireSize(bool ok, const std::string& owner, const std::string& what, const std::string& expected) {
  if (!ok) throw InputError(owner + ": invariant " + what + " has the wrong size; expected " + expected);
}

double maxAbs(const SpMat& A) {
  double m = 0.0;
  for (int j = 0; j < A.outerSize(); ++j) {
    for (SpMat::InnerIterator it(A, j); it; ++it) m = std::max(m, std::abs(it.value()));
  }
  return m;
}

void requireSymmetric(const SpMat& A, const std::string& owner, const std::string& what) {
  const double scale = maxAbs(A) + 1e-300;
  if (maxAbs(SpMat(A - SpMat(A.transpose()))) > 1e-10 * scale) {
    throw InputError(owner + ": invariant " + what + " is not symmetric; expected a symmetric matrix");
  }
}

void requireFiniteAll(const SpMat& A, const std::string& owner, const std::string& what) {
  for (int j = 0; j < A.outerSize(); ++j) {
    for (SpMat::InnerIterator it(A, j); it; ++it) {
      if (!std::isfinite(it.value())) throw InputError(owner + ": invariant " + what + " has non-finite entries");
    }
  }
}

void requireFiniteAll(const MatX& A, const std::string& owner, const std::string& what) {
  if (!A.allFinite()) throw InputError(owner + ": invariant " + what + " has non-finite entries");
}

bool isPositiveDefinite(const SpMat& A) {
  const Eigen::SimplicialLDLT<SpMat> ldlt(A);
  return ldlt.info() == Eigen::Success && ldlt.vectorD().minCoeff() > 0.0;
}

}  // namespace flexmbd::invariantchecks
