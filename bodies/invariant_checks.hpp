/// @file
/// The checks FfrInvariants::validate and FfrInvariants3d::validate share: sizes,
/// finiteness, symmetry and positive definiteness of an invariant, each failure an
/// InputError "<owner>: invariant <what> ...".
#pragma once

#include <string>

#include "core/types.hpp"

namespace flexmbd::invariantchecks {

void requireSize(bool ok, const std::string& owner, const std::string& what, const std::string& expected);
/// Largest |entry| of A (0 for an empty matrix).
double maxAbs(const SpMat& A);
/// |A - A^T| <= 1e-10 max |A|.
void requireSymmetric(const SpMat& A, const std::string& owner, const std::string& what);
void requireFiniteAll(const SpMat& A, const std::string& owner, const std::string& what);
void requireFiniteAll(const MatX& A, const std::string& owner, const std::string& what);
/// Sparse LDL^T succeeds with positive pivots: A is positive definite (a dense
/// factorisation would cost O(n^3) for a large nodal mesh).
bool isPositiveDefinite(const SpMat& A);

}  // namespace flexmbd::invariantchecks
