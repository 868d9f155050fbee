#include "integrators/klu_ordering.hpp"

#include <camd.h>

#include <algorithm>

namespace flexmbd {
namespace {

/// KLU ordering callback: constrained AMD on A + A^T with the groups of
/// DaeSystem::eliminationGroups() (elastic unknowns first; frame coordinates and
/// multipliers, which couple to a whole body or have no diagonal, last).
int64_t camdOrdering(int64_t n, int64_t* Ap, int64_t* Ai, int64_t* perm, klu_l_common* common) {
  const auto* groups = static_cast<const std::vector<int64_t>*>(common->user_data);
  double control[CAMD_CONTROL], info[CAMD_INFO];
  camd_l_defaults(control);
  if (camd_l_order(n, Ap, Ai, perm, control, info, const_cast<int64_t*>(groups->data())) < CAMD_OK) return 0;
  return std::max<int64_t>(1, static_cast<int64_t>(info[CAMD_LNZ]));
}

/// With KLU's default (AMD after a block-triangular permutation, partial pivoting
/// with threshold 1e-3) the factors of a large flexible body filled in quadratically:
/// the zero diagonals of the multipliers, and entries beside the cj diagonals of the
/// elastic coordinates, made KLU pick pivots off the fill-reducing order. The elastic
/// 2 x 2 blocks [cj, -1; K, cj M] have positive Schur complements cj M + K / cj, so
/// their diagonal pivots are safe; a threshold of 1e-6 still rejects the (near-)zero
/// diagonals of the small last group (a threshold of 1e-12 let the rigid slider-crank
/// tests fail to converge). bench_micro compares both orderings: elastic slider-crank,
/// 256 elements, nnz(L + U) 311,373 with KLU's defaults and 28,658 with this one.
constexpr double kKluPivotTolerance = 1e-6;

}  // namespace

void configureKluOrdering(klu_l_common& common, const std::vector<int64_t>& groups) {
  if (std::find(groups.begin(), groups.end(), 0) == groups.end()) return;
  common.btf = 0;  // one block: the groups index the whole matrix
  common.ordering = 3;
  common.user_order = &camdOrdering;
  common.user_data = const_cast<std::vector<int64_t>*>(&groups);
  common.tol = kKluPivotTolerance;
}


}  // namespace flexmbd
